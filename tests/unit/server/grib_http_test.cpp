// POST /api/grib on a real HttpApi on loopback sockets: the forecast decodes
// off the io thread, so other requests are answered meanwhile; one decode at
// a time (another gets 503 with Retry-After); a client that leaves, or the
// API closing, during a decode. The decoder is the real one behind a gate (a
// script that waits for a file, then runs it), so "while it decodes" is a
// state the test holds, not a race against the machine's load.
#include <poll.h>
#include <signal.h>
#include <sys/socket.h>
#include <netinet/in.h>
#include <arpa/inet.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <filesystem>
#include <fstream>
#include <future>
#include <thread>

#include <gtest/gtest.h>
#include <boost/asio/executor_work_guard.hpp>
#include <boost/asio/post.hpp>
#include <nlohmann/json.hpp>

#include "grib_tools.hpp"
#include "sky/server/http_api.hpp"

namespace sky::server {
namespace {

namespace fs = std::filesystem;
using namespace std::chrono_literals;

const char* kToken = "grib-t0ken";

// One HTTP request on a socket of its own: sent at once, its answer read
// when asked (until the server closes).
class Client {
 public:
  Client(std::uint16_t port, const std::string& method, const std::string& target, const std::string& body) {
    fd_ = ::socket(AF_INET, SOCK_STREAM | SOCK_CLOEXEC, 0);
    sockaddr_in a{};
    a.sin_family = AF_INET;
    a.sin_port = htons(port);
    a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    if (::connect(fd_, reinterpret_cast<const sockaddr*>(&a), sizeof a) != 0) {
      ADD_FAILURE() << "connect: " << std::strerror(errno);
      return;
    }
    std::string r = method + " " + target + " HTTP/1.1\r\nHost: 127.0.0.1:" + std::to_string(port) +
                    "\r\nAuthorization: Bearer " + kToken + "\r\nContent-Length: " + std::to_string(body.size()) +
                    "\r\n\r\n" + body;
    for (std::size_t at = 0; at < r.size();) {
      const ssize_t n = ::send(fd_, r.data() + at, r.size() - at, MSG_NOSIGNAL);
      if (n <= 0) {
        ADD_FAILURE() << "send: " << std::strerror(errno);
        return;
      }
      at += static_cast<std::size_t>(n);
    }
  }
  ~Client() { leave(); }
  Client(const Client&) = delete;
  Client& operator=(const Client&) = delete;

  // Whether any of the answer has arrived (without waiting).
  bool answered() const {
    pollfd p{fd_, POLLIN, 0};
    return ::poll(&p, 1, 0) > 0;
  }
  // The whole answer, read until the server closes; false when it does not
  // within `timeout` (the answer so far is kept).
  bool read(std::chrono::seconds timeout) {
    const auto until = std::chrono::steady_clock::now() + timeout;
    char buf[65536];
    for (;;) {
      const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(until - std::chrono::steady_clock::now());
      if (left.count() <= 0) return false;
      pollfd p{fd_, POLLIN, 0};
      if (::poll(&p, 1, static_cast<int>(left.count())) <= 0) continue;
      const ssize_t n = ::recv(fd_, buf, sizeof buf, 0);
      if (n < 0 && errno == EINTR) continue;
      if (n <= 0) return true;
      answer_.append(buf, static_cast<std::size_t>(n));
    }
  }
  // The answer's status (0: none), a header's value, the body.
  int status() const { return answer_.size() > 12 ? std::atoi(answer_.c_str() + 9) : 0; }
  std::string header(const std::string& name) const {
    const auto at = answer_.find("\r\n" + name + ": ");
    if (at == std::string::npos || at > answer_.find("\r\n\r\n")) return "";
    const auto from = at + name.size() + 4;
    return answer_.substr(from, answer_.find("\r\n", from) - from);
  }
  std::string body() const {
    const auto at = answer_.find("\r\n\r\n");
    return at == std::string::npos ? "" : answer_.substr(at + 4);
  }
  nlohmann::json json() const { return nlohmann::json::parse(body(), nullptr, false); }
  // Closes the socket: the client leaves.
  void leave() {
    if (fd_ >= 0) ::close(fd_);
    fd_ = -1;
  }

 private:
  int fd_ = -1;
  std::string answer_;
};

fs::path emptyDir(const fs::path& dir) {
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir;
}

class GribHttp : public testing::Test {
 protected:
  GribHttp()
      : dir_(emptyDir(fs::temp_directory_path() /
                      ("sky-grib-http-" + std::to_string(::getpid()) + "-" +
                       testing::UnitTest::GetInstance()->current_test_info()->name()))),
        gate_(dir_ / "gate", SKY_GRIB_DECODER),
        weather_(scenario_, WallClock::now(), [] { return WallClock::now(); }, [] { return std::int64_t{0}; }) {
    fs::create_directories(dir_ / "grib");
    fs::copy_file(kNam, dir_ / "grib" / "nam.grib2", fs::copy_options::overwrite_existing);
    HttpApiOptions options;
    options.token = kToken;
    options.gribDir = (dir_ / "grib").string();
    options.gribDecoder.executable = gate_.executable();
    HttpApiHooks hooks;
    hooks.rejections = &rejections_;
    auto api = HttpApi::create(io_, options, weather_, hooks);
    EXPECT_TRUE(api) << api.error().detail;
    if (api) api_ = std::move(*api);
    io_thread_ = std::thread([this] { io_.run(); });
  }
  ~GribHttp() override {
    gate_.open();  // a decode still waiting ends, whatever the test left behind
    onIo([this] {
      if (api_) api_->close();
    });
    work_.reset();
    io_.stop();
    io_thread_.join();
    std::error_code ignored;
    fs::remove_all(dir_, ignored);
  }

  std::uint16_t port() const { return api_ ? api_->port() : 0; }
  // Runs `f` on the io thread, as everything of the API runs, and waits.
  void onIo(std::function<void()> f) {
    std::promise<void> done;
    boost::asio::post(io_, [&] {
      f();
      done.set_value();
    });
    done.get_future().wait();
  }
  // The decoder's pid once it has started (a decode is under way), or 0.
  pid_t waitForDecoder() { return gate_.waitUntilStarted(60s); }
  std::string get(const std::string& target) {
    Client c(port(), "GET", target, "");
    EXPECT_TRUE(c.read(60s)) << "GET " << target << " not answered";
    EXPECT_EQ(c.status(), 200) << target;
    return c.body();
  }

  fs::path dir_;
  GatedDecoder gate_;
  Scenario scenario_;
  LiveWeather weather_;
  Rejections rejections_;
  boost::asio::io_context io_;
  boost::asio::executor_work_guard<boost::asio::io_context::executor_type> work_ = boost::asio::make_work_guard(io_);
  std::unique_ptr<HttpApi> api_;
  std::thread io_thread_;
};

// The bug: the decode ran inside the HTTP handler on the io thread, so while
// a forecast decoded (seconds) the server answered nothing else.
TEST_F(GribHttp, OtherRequestsAreAnsweredWhileAForecastDecodes) {
  ASSERT_NE(port(), 0);
  Client post(port(), "POST", "/api/grib", R"({"path": "nam.grib2"})");
  ASSERT_GT(waitForDecoder(), 0) << "the decoder did not start";
  // The decoder waits at the gate: the POST cannot have been answered, and
  // these are answered before it.
  EXPECT_EQ(get("/healthz"), "ok\n");
  const auto state = nlohmann::json::parse(get("/api/state"), nullptr, false);
  EXPECT_TRUE(state.is_object() && state["forecast"].is_null()) << state.dump();
  EXPECT_FALSE(post.answered());

  gate_.open();
  ASSERT_TRUE(post.read(120s)) << "the POST was not answered";
  ASSERT_EQ(post.status(), 200) << post.body();
  auto first = post.json();
  EXPECT_EQ(first["forecast"]["name"], "nam.grib2");
  EXPECT_EQ(first["skipped_total"], 0);
  const auto loaded = nlohmann::json::parse(get("/api/state"), nullptr, false);
  EXPECT_EQ(loaded["forecast"]["name"], "nam.grib2");

  // The same file again (the gate open) answers the same, but for the
  // change's sequence and the weather clock it was placed at.
  Client again(port(), "POST", "/api/grib", R"({"path": "nam.grib2"})");
  ASSERT_TRUE(again.read(120s));
  ASSERT_EQ(again.status(), 200) << again.body();
  auto second = again.json();
  EXPECT_EQ(second["sequence"], first["sequence"].get<std::uint64_t>() + 1);
  for (auto* j : {&first, &second}) {
    j->erase("sequence");
    j->erase("clock_s");
    (*j)["forecast"].erase("anchor_clock_s");
    const std::string summary = (*j)["summary"];
    (*j)["summary"] = summary.substr(0, summary.rfind(" at clock "));
  }
  EXPECT_EQ(second, first);
}

TEST_F(GribHttp, AnotherForecastWhileOneDecodesIsRefusedBusy) {
  ASSERT_NE(port(), 0);
  Client post(port(), "POST", "/api/grib", R"({"path": "nam.grib2"})");
  ASSERT_GT(waitForDecoder(), 0) << "the decoder did not start";
  // An upload and a path: both refused at once, the first decode untouched.
  const std::string bytes = [] {
    std::ifstream in(kNam, std::ios::binary);
    return std::string(std::istreambuf_iterator<char>(in), {});
  }();
  for (const std::string& body : {bytes, std::string(R"({"path": "nam.grib2"})")}) {
    Client busy(port(), "POST", "/api/grib?name=second.grib2", body);
    ASSERT_TRUE(busy.read(60s));
    EXPECT_EQ(busy.status(), 503) << busy.body();
    EXPECT_EQ(busy.header("Retry-After"), std::to_string(kGribBusyRetryAfter_s));
    EXPECT_EQ(busy.json()["error"], "grib: another forecast is decoding (at most 1 at a time); try again once it has loaded");
  }
  // An invalid request is still told what is wrong with it.
  Client outside(port(), "POST", "/api/grib", R"({"path": "../elsewhere.grib2"})");
  ASSERT_TRUE(outside.read(60s));
  EXPECT_EQ(outside.status(), 400) << outside.body();
  EXPECT_EQ(rejections_.get(RejectReason::GribBusy), 2u);
  EXPECT_NE(get("/metrics").find("skyshell_rejected_inputs_total{reason=\"grib_busy\"} 2\n"), std::string::npos);
  EXPECT_FALSE(post.answered());

  gate_.open();
  ASSERT_TRUE(post.read(120s));
  EXPECT_EQ(post.status(), 200) << post.body();
  // The slot is free again.
  Client after(port(), "POST", "/api/grib", R"({"path": "nam.grib2"})");
  ASSERT_TRUE(after.read(120s));
  EXPECT_EQ(after.status(), 200) << after.body();
}

TEST_F(GribHttp, AClientThatLeavesDuringTheDecodeCostsNothing) {
  ASSERT_NE(port(), 0);
  {
    Client post(port(), "POST", "/api/grib", R"({"path": "nam.grib2"})");
    ASSERT_GT(waitForDecoder(), 0) << "the decoder did not start";
  }  // gone before its answer
  gate_.open();
  // The request was accepted: the forecast is loaded all the same, and its
  // connection is closed once the answer finds no one (the sanitizer build
  // reports a leak at exit).
  std::string metrics;
  const auto until = std::chrono::steady_clock::now() + 120s;
  do {
    std::this_thread::sleep_for(50ms);
    metrics = get("/metrics");
  } while (metrics.find("\nskyshell_http_connections 1\n") == std::string::npos &&
           std::chrono::steady_clock::now() < until);
  EXPECT_NE(metrics.find("\nskyshell_http_connections 1\n"), std::string::npos) << "only the /metrics request";
  EXPECT_EQ(nlohmann::json::parse(get("/api/state"), nullptr, false)["forecast"]["name"], "nam.grib2");
}

TEST_F(GribHttp, ClosingTheApiDuringADecodeKillsTheDecoder) {
  ASSERT_NE(port(), 0);
  Client post(port(), "POST", "/api/grib", R"({"path": "nam.grib2"})");
  const pid_t decoder = waitForDecoder();
  ASSERT_GT(decoder, 0) << "the decoder did not start";
  // The gate stays shut: close() returns because it kills the decoder, not
  // because the decode ended.
  onIo([this] { api_->close(); });
  EXPECT_EQ(::kill(decoder, 0), -1) << "the decoder still runs";
  EXPECT_EQ(errno, ESRCH);
  // The client is let go without an answer; nothing was loaded.
  ASSERT_TRUE(post.read(60s));
  EXPECT_EQ(post.status(), 0);
  onIo([this] { EXPECT_EQ(weather_.forecast(), nullptr); });
}

}  // namespace
}  // namespace sky::server
