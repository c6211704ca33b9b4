// Issue 18, stream side: the server on a real loopback socket refuses what a
// subscriber may not send (a snapshot-sized frame from its header, a Snapshot,
// garbage), refuses connections past its subscriber cap with an Error, keeps
// running when a handler throws, and backs off when accept() fails for lack of
// file descriptors instead of spinning a core.
#include <fcntl.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <memory>
#include <sstream>
#include <stdexcept>
#include <string>
#include <thread>

#include <spdlog/sinks/ostream_sink.h>
#include <spdlog/spdlog.h>

#include "sky/server/scenario.hpp"
#include "sky/server/server.hpp"
#include "stream_test_client.hpp"

namespace sky::server {
namespace {

std::unique_ptr<Server> makeServer(std::size_t maxSubscribers = kDefaultMaxSubscribers,
                                   std::shared_ptr<spdlog::logger> log = nullptr) {
  auto scenario = loadScenario(SKY_SOURCE_DIR "/deploy/scenarios/skeleton-cumulus.toml");
  EXPECT_TRUE(scenario);
  ServerOptions options;
  options.port = 0;
  options.heartbeatInterval = 1000ms;
  options.handleSignals = false;
  options.maxSubscribers = maxSubscribers;
  options.log = std::move(log);
  auto server = Server::create(options, WeatherState(*scenario, WallClock::now()));
  EXPECT_TRUE(server);
  return std::move(*server);
}

class Running {
 public:
  explicit Running(Server& s) : server_(s), thread_([&s] { s.run(); }) {}
  ~Running() {
    server_.stop();
    thread_.join();
  }

 private:
  Server& server_;
  std::thread thread_;
};

// The Error a refused peer is sent, then the server's EOF.
void expectErrorThenEof(TestClient& client, const std::string& says) {
  for (;;) {
    auto m = client.read();
    ASSERT_TRUE(m) << m.error().detail;
    if (std::holds_alternative<stream::Hello>(*m) || std::holds_alternative<stream::Heartbeat>(*m)) continue;
    const auto* error = std::get_if<stream::StreamError>(&*m);
    ASSERT_NE(error, nullptr) << stream::kindName(*m);
    EXPECT_NE(error->detail.find(says), std::string::npos) << error->detail;
    break;
  }
  auto end = client.read();
  ASSERT_FALSE(end);
  EXPECT_EQ(end.error().detail, "eof");
}

void expectServes(std::uint16_t port) {
  TestClient client(port);
  ASSERT_TRUE(client.readNext<stream::Hello>());
  stream::Subscribe s;
  s.area = {47.0, 8.5, 20'000};
  s.tileLevel = 10;
  client.send(s);
  ASSERT_TRUE(client.readNext<weather::WeatherSnapshot>());
}

TEST(HostileStream, ASnapshotSizedFrameIsRefusedFromItsHeader) {
  auto server = makeServer();
  Running running(*server);
  TestClient client(server->port());
  // 4 MiB announced, nothing of it sent: the server must answer at once.
  client.sendBytes({0x00, 0x40, 0x00, 0x00});
  expectErrorThenEof(client, "cap is 4096");
  EXPECT_EQ(server->rejections().get(RejectReason::StreamMalformed), 1u);
  expectServes(server->port());
}

TEST(HostileStream, ASubscriberSendingASnapshotIsRefused) {
  auto server = makeServer();
  Running running(*server);
  TestClient client(server->port());
  weather::WeatherSnapshot snapshot;
  snapshot.tileLevel = 8;
  client.send(snapshot);
  expectErrorThenEof(client, "Snapshot is sent by servers");
  expectServes(server->port());
}

TEST(HostileStream, GarbageAndAbsurdSubscribesAreRefused) {
  auto server = makeServer();
  Running running(*server);
  {
    TestClient client(server->port());
    std::vector<std::uint8_t> garbage(600);
    for (std::size_t i = 0; i < garbage.size(); ++i) garbage[i] = static_cast<std::uint8_t>(i * 37 + 11);
    garbage[0] = garbage[1] = 0;  // a small length, so the payload is decoded and fails verification
    client.sendBytes(garbage);
    expectErrorThenEof(client, "");
  }
  {
    TestClient client(server->port());
    stream::Subscribe s;
    s.area = {47.0, 8.5, 1.0e9};  // radius beyond the Earth
    s.tileLevel = 30;
    client.send(s);
    expectErrorThenEof(client, "radius_m");
  }
  EXPECT_EQ(server->rejections().get(RejectReason::StreamMalformed), 2u);
  expectServes(server->port());
}

TEST(HostileStream, ConnectionsPastTheCapAreToldAndClosed) {
  auto server = makeServer(2);
  Running running(*server);
  TestClient a(server->port()), b(server->port());
  ASSERT_TRUE(a.readNext<stream::Hello>());
  ASSERT_TRUE(b.readNext<stream::Hello>());
  TestClient c(server->port());
  expectErrorThenEof(c, "server full: 2 subscribers, at most 2");
  EXPECT_EQ(server->rejections().get(RejectReason::SubscriberCap), 1u);
  EXPECT_EQ(onIo(server->io(), [&] { return server->subscribers(); }), 2u);
  // A slot freed is a slot taken.
  a.close();
  for (int i = 0; i < 100 && onIo(server->io(), [&] { return server->subscribers(); }) != 1; ++i)
    std::this_thread::sleep_for(10ms);
  expectServes(server->port());
}

TEST(HostileStream, AHandlerThatThrowsDoesNotEndTheServer) {
  auto server = makeServer();
  Running running(*server);
  boost::asio::post(server->io(), [] { throw std::runtime_error("a handler bug"); });
  expectServes(server->port());
  EXPECT_EQ(server->streamCounters().handlerExceptions.load(), 1u);
  EXPECT_EQ(server->rejections().get(RejectReason::HandlerFailed), 1u);
}

// In a child process, so the lowered descriptor limit touches nothing else:
// with the limit reached, accept() fails with EMFILE on every try; the server
// must retry a few times a second, not spin, and serve once a descriptor is
// free. The child's exit code says which check failed.
int acceptBackoffChild() {
  auto server = makeServer();
  if (!server) return 10;
  // The thread is running before the limit is lowered: UBSan's vptr check
  // of its first (virtual) call reads the object through a pipe, and with no
  // descriptor left it would report the thread's own state as invalid.
  std::atomic<bool> running{false};
  std::thread thread([&] {
    running = true;
    server->run();
  });
  while (!running) std::this_thread::yield();
  int code = 0;
  {
    // Connected before the limit: the kernel completes the handshake into the
    // backlog, and the server's accept() is what fails.
    TestClient client(server->port());
    // The running server may accept that one before the limit is set; a
    // second, whose socket is made now and connected after the limit, is
    // one the server cannot accept whatever the timing.
    asio::io_context lateIo;
    asio::ip::tcp::socket late(lateIo);
    late.open(asio::ip::tcp::v4());
    rlimit old{};
    getrlimit(RLIMIT_NOFILE, &old);
    // The lowest free descriptor: with the limit there, no new one can be made.
    const int probe = ::open("/dev/null", O_RDONLY);
    ::close(probe);
    rlimit low = old;
    low.rlim_cur = static_cast<rlim_t>(probe);
    setrlimit(RLIMIT_NOFILE, &low);
    boost::system::error_code connectError;
    late.connect(asio::ip::tcp::endpoint(asio::ip::make_address("127.0.0.1"), server->port()), connectError);
    if (connectError) code = 15;
    rusage before{}, after{};
    getrusage(RUSAGE_SELF, &before);
    std::this_thread::sleep_for(2s);
    getrusage(RUSAGE_SELF, &after);
    const auto failures = server->streamCounters().acceptFailures.load();
    auto cpu_s = [](const rusage& r) {
      return double(r.ru_utime.tv_sec + r.ru_stime.tv_sec) + 1e-6 * double(r.ru_utime.tv_usec + r.ru_stime.tv_usec);
    };
    const double used_s = cpu_s(after) - cpu_s(before);
    std::fprintf(stderr, "accept failures in 2 s: %llu, cpu %.3f s\n", static_cast<unsigned long long>(failures),
                 used_s);
    // 10, 20, ... 640, 1000 ms: about 8 tries in the first two seconds.
    // A spinning loop uses the whole 2 s of CPU.
    if (code == 0) code = failures < 2 ? 11 : failures > 20 ? 12 : used_s > 0.3 ? 13 : 0;
    setrlimit(RLIMIT_NOFILE, &old);
    // Within the longest back-off the waiting connection is accepted.
    if (code == 0 && !client.readNext<stream::Hello>()) code = 14;
  }
  server->stop();
  thread.join();
  return code;
}

// A peer that proposes host clock offsets far apart, for one host and for
// hundreds, changes the held offset at every proposal: counted, logged at
// info at most once a second, and the server serves a real channel the
// whole time, which gets the offset held at its own proposal.
TEST(HostileStream, HostClockProposalsFloodNeitherTheLogNorTheServer) {
  std::ostringstream logged;
  auto log = std::make_shared<spdlog::logger>("hostile", std::make_shared<spdlog::sinks::ostream_sink_mt>(logged));
  log->set_level(spdlog::level::info);
  std::unique_ptr<Server> server = makeServer(kDefaultMaxSubscribers, log);
  ASSERT_TRUE(server);
  const auto start = std::chrono::steady_clock::now();
  {
    Running running(*server);
    TestClient hostile(server->port());
    ASSERT_TRUE(hostile.readNext<stream::Hello>());
    constexpr int kProposals = 3000;
    for (int i = 0; i < kProposals; ++i) {
      const std::string host = i % 10 == 0 ? "host " + std::to_string(i) : "10.0.0.1";
      hostile.send(stream::HostClock{host, (i % 2) * 1000.0, 1.0});
    }
    expectServes(server->port());
    TestClient channel(server->port());
    ASSERT_TRUE(channel.readNext<stream::Hello>());
    channel.send(stream::HostClock{"10.0.0.1", 5000.0, 1.0});
    auto got = channel.readNext<stream::HostClock>();
    ASSERT_TRUE(got) << got.error().detail;
    EXPECT_EQ(got->offset_s, 5000.0);  // 1000 or 0 held: 5000 does not stand against either, and replaces it
    // The hostile connection's proposals may still be in the server's
    // input when the channel's answer comes: wait for them all.
    const auto until = std::chrono::steady_clock::now() + kTimeout;
    while (server->streamCounters().hostClockProposals.load() < kProposals + 1u &&
           std::chrono::steady_clock::now() < until)
      std::this_thread::sleep_for(5ms);
    EXPECT_EQ(server->streamCounters().hostClockProposals.load(), kProposals + 1u);
    // Every new host name, and every offset for 10.0.0.1 1000 s from the
    // one held, is a change: most of the proposals.
    EXPECT_GE(server->streamCounters().hostClockChanges.load(), kProposals / 2u);
    EXPECT_LE(server->streamCounters().hostClockChanges.load(), kProposals + 1u);
  }
  const double took_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  std::size_t lines = 0;
  const std::string text = logged.str();
  for (std::size_t at = text.find("event=host_clock"); at != std::string::npos; at = text.find("event=host_clock", at + 1))
    ++lines;
  std::printf("[ flood    ] %llu host clock changes in %.2f s, %zu logged at info\n",
              static_cast<unsigned long long>(server->streamCounters().hostClockChanges.load()), took_s, lines);
  EXPECT_GE(lines, 1u);
  EXPECT_LE(double(lines), took_s + 1);
}

TEST(HostileStream, AcceptBacksOffWhenOutOfDescriptors) {
  const pid_t child = ::fork();
  ASSERT_GE(child, 0);
  if (child == 0) ::_exit(acceptBackoffChild());
  int status = 0;
  ASSERT_EQ(::waitpid(child, &status, 0), child);
  ASSERT_TRUE(WIFEXITED(status));
  EXPECT_EQ(WEXITSTATUS(status), 0) << "10: no server; 11: accept not retried; 12: retried too often; "
                                       "13: the retries used the CPU; 14: not served after the limit rose; "
                                       "15: the second client could not connect";
}

}  // namespace
}  // namespace sky::server
