// Hostile input to skyshell-weatherd's HTTP API through real sockets (issue
// 18: no input may stop the process): invalid UTF-8 in the target, a query
// value, a header, a JSON string and an author (the two crashes the issue
// names, with the author's round trip through --db across a restart); an
// oversized body, a slow body, header bloat, a thousand idle connections,
// foreign Origins and a wrong Host. After each probe the same process
// answers /healthz within 100 ms.
#include <poll.h>
#include <signal.h>
#include <sys/resource.h>
#include <sys/socket.h>
#include <netinet/in.h>
#include <arpa/inet.h>
#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <future>
#include <iostream>
#include <string>
#include <thread>
#include <vector>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "sky/core/utf8.hpp"
#include "weatherd_process.hpp"

namespace fs = std::filesystem;
using namespace std::chrono_literals;

namespace sky::test {
namespace {

// A plain TCP connection to 127.0.0.1:port; every read has a deadline.
class Raw {
 public:
  explicit Raw(unsigned port) : fd_(::socket(AF_INET, SOCK_STREAM, 0)) {
    sockaddr_in a{};
    a.sin_family = AF_INET;
    a.sin_port = htons(static_cast<std::uint16_t>(port));
    a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    connected_ = fd_ >= 0 && ::connect(fd_, reinterpret_cast<sockaddr*>(&a), sizeof a) == 0;
  }
  ~Raw() {
    if (fd_ >= 0) ::close(fd_);
  }
  Raw(const Raw&) = delete;
  Raw& operator=(const Raw&) = delete;
  bool connected() const { return connected_; }

  bool send(const std::string& bytes) {
    std::size_t sent = 0;
    while (sent < bytes.size()) {
      const ssize_t n = ::send(fd_, bytes.data() + sent, bytes.size() - sent, MSG_NOSIGNAL);
      if (n <= 0) return false;
      sent += static_cast<std::size_t>(n);
    }
    return true;
  }
  // Everything until the server closes, or until `timeout`.
  std::string readAll(std::chrono::milliseconds timeout) {
    std::string out;
    const auto deadline = std::chrono::steady_clock::now() + timeout;
    for (bool first = true;; first = false) {
      const auto left = std::chrono::ceil<std::chrono::milliseconds>(deadline - std::chrono::steady_clock::now());
      if (left.count() <= 0 && !first) break;
      pollfd p{fd_, POLLIN, 0};
      if (::poll(&p, 1, static_cast<int>(std::max<long>(left.count(), 0))) <= 0) break;
      char buf[4096];
      const ssize_t n = ::recv(fd_, buf, sizeof buf, 0);
      if (n <= 0) {
        closedByServer = true;
        break;
      }
      out.append(buf, static_cast<std::size_t>(n));
    }
    return out;
  }
  // What has arrived, without waiting.
  std::string readNow() { return readAll(1ms); }
  bool closedByServer = false;

 private:
  int fd_;
  bool connected_ = false;
};

int statusOf(const std::string& response) {
  if (response.rfind("HTTP/1.1 ", 0) != 0 || response.size() < 12) return 0;
  return std::stoi(response.substr(9, 3));
}
std::string bodyOf(const std::string& response) {
  const auto end = response.find("\r\n\r\n");
  return end == std::string::npos ? "" : response.substr(end + 4);
}

struct Hostile : testing::Test {
  static std::string request(const std::string& method, const std::string& target, unsigned port,
                             const std::string& headers = "", const std::string& body = "") {
    std::string r = method + " " + target + " HTTP/1.1\r\nHost: 127.0.0.1:" + std::to_string(port) + "\r\n" + headers;
    if (!body.empty()) r += "Content-Length: " + std::to_string(body.size()) + "\r\n";
    return r + "\r\n" + body;
  }
  static std::string exchange(unsigned port, const std::string& bytes, std::chrono::milliseconds timeout = 5s) {
    Raw c(port);
    EXPECT_TRUE(c.connected());
    c.send(bytes);
    return c.readAll(timeout);
  }
  // The same process still runs and answers /healthz within 100 ms. On a
  // loaded machine (builds on both cores) one request can wait tens of ms to
  // be scheduled, so the best of three tries counts, and each must answer
  // within a second: a stalled server fails all three.
  static inline std::chrono::steady_clock::duration slowestHealthz{};
  static void expectHealthy(Weatherd& w, const char* after) {
    ASSERT_FALSE(w.process->wait(0ms)) << "the process exited after: " << after << "\n" << w.process->log();
    auto best = std::chrono::steady_clock::duration::max();
    for (int i = 0; i < 3; ++i) {
      const auto start = std::chrono::steady_clock::now();
      const std::string r = exchange(w.httpPort, request("GET", "/healthz", w.httpPort), 1s);
      const auto took = std::chrono::steady_clock::now() - start;
      ASSERT_EQ(bodyOf(r), "ok\n") << "after: " << after << "\n" << r;
      if (i == 0 && took > 30ms)
        std::cout << "[ measured ] first /healthz after " << after << ": "
                  << std::chrono::duration_cast<std::chrono::milliseconds>(took).count() << " ms\n";
      best = std::min(best, took);
      if (best < 100ms) break;
    }
    EXPECT_LT(best, 100ms) << "after: " << after;
    slowestHealthz = std::max(slowestHealthz, best);
  }
};

TEST_F(Hostile, TheServerSurvivesEveryProbeAndKeepsAuthorsAcrossARestart) {
  const fs::path db = fs::path(SKY_TEST_OUTPUT_DIR) / "hostile-http.db";
  fs::remove(db);
  std::optional<Weatherd> w;
  w.emplace("hostile-http", SKY_SCENARIO_CLOUDY, false, std::vector<std::string>{"--db", db.string()});
  ASSERT_GT(w->httpPort, 0u) << w->process->log();
  const unsigned port = w->httpPort;
  const std::string token = std::string("Authorization: Bearer ") + kToken + "\r\n";

  // A slow body, started first and trickled one byte a second: the 10 s
  // deadline (whole request, not idle time) drops it while the other probes run.
  const auto slowStart = std::chrono::steady_clock::now();
  auto slow = std::async(std::launch::async, [&] {
    Raw c(port);
    c.send(request("POST", "/api/changes", port, token + "Content-Length: 1000\r\n") + "{");
    for (int i = 0; i < 20 && !c.closedByServer; ++i) {
      if (!c.send(" ")) break;
      c.readAll(1s);
    }
    return std::chrono::steady_clock::now() - slowStart;
  });

  // Issue 18, crash 1: a byte 0x80-0xFF in the target or a query value.
  for (const std::string target : {"/nowhere\xff", "/api/events?limit=\xfe", "/api/conditions?lat_deg=\xc3"}) {
    const std::string r = exchange(port, request("GET", target, port));
    EXPECT_EQ(statusOf(r), 400) << r;
    EXPECT_TRUE(utf8::valid(r)) << "echoed raw: " << r;
    expectHealthy(*w, "invalid UTF-8 in the target");
  }
  EXPECT_EQ(statusOf(exchange(port, request("GET", "/healthz", port, "X-Who: \xff\xfe\r\n"))), 400);
  expectHealthy(*w, "invalid UTF-8 in a header");
  // Not JSON: a raw 0xFF inside a JSON string.
  const std::string raw = "{\"author\": \"\xff\", \"changes\": [{\"op\": \"set_clock\", \"rate\": 1}]}";
  const std::string badJson = exchange(port, request("POST", "/api/changes", port, token, raw));
  EXPECT_EQ(statusOf(badJson), 400) << badJson;
  EXPECT_TRUE(utf8::valid(badJson));
  expectHealthy(*w, "invalid UTF-8 in a JSON string");

  // Issue 18, crash 2: 199 ASCII bytes and "é" as the author.
  const std::string author = std::string(199, 'a') + "\xc3\xa9";
  const std::string change =
      nlohmann::json{{"author", author}, {"changes", {{{"op", "set_clock"}, {"rate", 2}}}}}.dump();
  EXPECT_EQ(statusOf(exchange(port, request("POST", "/api/changes", port, token, change))), 200);
  const std::string events = exchange(port, request("GET", "/api/events", port));
  ASSERT_EQ(statusOf(events), 200) << events;
  EXPECT_EQ(nlohmann::json::parse(bodyOf(events))["events"][0]["author"], std::string(199, 'a'));
  expectHealthy(*w, "a 200-byte author cut inside a character");

  // Oversized body: 413 from the declared length, before the body is read
  // (the client has sent 64 kB of its 50 MB).
  {
    Raw c(port);
    c.send(request("POST", "/api/changes", port, token + "Content-Length: 50000000\r\n"));
    c.send(std::string(64 * 1024, ' '));
    const std::string r = c.readAll(2s);
    EXPECT_EQ(statusOf(r), 413) << r;
  }
  expectHealthy(*w, "an oversized body");
  // Header bloat: 431.
  EXPECT_EQ(statusOf(exchange(port, request("GET", "/healthz", port, "X-Bloat: " + std::string(20000, 'x') + "\r\n"))),
            431);
  expectHealthy(*w, "header bloat");

  // Browsers: a foreign page's WebSocket and POST, and DNS rebinding (a foreign Host).
  const std::string upgrade =
      "Upgrade: websocket\r\nConnection: Upgrade\r\nSec-WebSocket-Key: dGhlIHNhbXBsZSBub25jZQ==\r\n"
      "Sec-WebSocket-Version: 13\r\nOrigin: http://evil.example\r\n";
  EXPECT_EQ(statusOf(exchange(port, request("GET", "/api/ws", port, upgrade))), 403);
  EXPECT_EQ(statusOf(exchange(port, request("POST", "/api/changes", port, token + "Origin: http://evil.example\r\n",
                                            change))),
            403);
  EXPECT_EQ(statusOf(exchange(port, "GET /api/state HTTP/1.1\r\nHost: evil.example:" + std::to_string(port) +
                                        "\r\n\r\n")),
            403);
  expectHealthy(*w, "foreign Origin and Host");

  // A thousand idle connections: past the cap (256) the oldest idle ones are
  // answered 503 and closed; /healthz is still answered.
  rlimit files{};
  getrlimit(RLIMIT_NOFILE, &files);
  if (files.rlim_cur < 1200 && files.rlim_max >= 1200) {
    files.rlim_cur = 1200;
    setrlimit(RLIMIT_NOFILE, &files);
  }
  {
    std::vector<std::unique_ptr<Raw>> idle;
    for (int i = 0; i < 1000; ++i) {
      idle.push_back(std::make_unique<Raw>(port));
      ASSERT_TRUE(idle.back()->connected()) << i;
    }
    // The connects complete in the kernel's backlog; the server accepts them
    // a moment later.
    std::this_thread::sleep_for(300ms);
    expectHealthy(*w, "a thousand idle connections");
    std::this_thread::sleep_for(100ms);
    int refused = 0;
    for (auto& c : idle) refused += statusOf(c->readNow()) == 503;
    // 744 past the cap, one more for each /healthz, a few slots held by the
    // slow body and connections still lingering.
    std::cout << "[ measured ] " << refused << " of 1000 idle connections refused with 503\n";
    EXPECT_GE(refused, 1000 - 256) << "connections past the cap refused with 503";
    EXPECT_LE(refused, 1000 - 256 + 10);
  }
  expectHealthy(*w, "a thousand idle connections, closed");

  // The slow body was dropped by the deadline, without an answer.
  ASSERT_EQ(slow.wait_for(15s), std::future_status::ready);
  const auto slowFor = slow.get();
  EXPECT_GT(slowFor, 9s);
  EXPECT_LT(slowFor, 13s);
  expectHealthy(*w, "a slow body");
  std::cout << "[ measured ] slow body dropped after "
            << std::chrono::duration_cast<std::chrono::milliseconds>(slowFor).count()
            << " ms; slowest /healthz (best of up to 3) after a probe "
            << std::chrono::duration_cast<std::chrono::microseconds>(slowestHealthz).count() << " us\n";

  const std::string metrics = bodyOf(exchange(port, request("GET", "/metrics", port)));
  for (const char* reason : {"http_malformed", "http_too_large", "http_header_too_large", "http_forbidden",
                             "http_busy", "http_timeout"})
    EXPECT_NE(metrics.find(std::string("skyshell_rejected_inputs_total{reason=\"") + reason + "\"} "),
              std::string::npos);
  EXPECT_EQ(metrics.find("reason=\"http_timeout\"} 0"), std::string::npos) << metrics;
  EXPECT_EQ(metrics.find("reason=\"http_busy\"} 0"), std::string::npos);
  EXPECT_NE(metrics.find("reason=\"http_internal\"} 0\n"), std::string::npos) << "nothing failed inside";

  // Restart on the same database: the stored author reads back as valid UTF-8.
  EXPECT_EQ(w->process->stop(), 0) << w->process->log();
  w.emplace("hostile-http", SKY_SCENARIO_CLOUDY, false, std::vector<std::string>{"--db", db.string()});
  ASSERT_GT(w->httpPort, 0u) << w->process->log();
  const std::string again = exchange(w->httpPort, request("GET", "/api/events", w->httpPort));
  ASSERT_EQ(statusOf(again), 200) << again;
  EXPECT_TRUE(utf8::valid(again));
  EXPECT_EQ(nlohmann::json::parse(bodyOf(again))["events"][0]["author"], std::string(199, 'a'));
  expectHealthy(*w, "a restart");
  EXPECT_EQ(w->process->stop(), 0) << w->process->log();
}

}  // namespace
}  // namespace sky::test
