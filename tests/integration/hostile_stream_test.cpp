// Issue 18: hostile input to a real skyshell-weatherd through real sockets.
// One server process takes every probe: a snapshot frame of 60 000 layers, a
// length prefix of 4 GiB, garbage, an absurd Subscribe, connections past the
// subscriber cap, and CIGI weather datagrams with bad size bytes from
// thousands of senders. After each probe /healthz answers within 100 ms and
// the process is still the one started (it never exited, so never restarted),
// and /metrics counts the refusals by reason.
#include <chrono>
#include <random>
#include <string>
#include <thread>
#include <vector>

#include <boost/asio/ip/tcp.hpp>
#include <boost/asio/ip/udp.hpp>
#include <boost/asio/read.hpp>
#include <boost/asio/write.hpp>
#include <gtest/gtest.h>

#include "sky/cigi/codec.hpp"
#include "sky/stream/framing.hpp"
#include "sky/stream/messages.hpp"
#include "weatherd_process.hpp"

namespace sky::test {
namespace {

namespace asio = boost::asio;
using asio::ip::tcp;
using asio::ip::udp;

// The subscriber cap skyshell-weatherd runs with (server.hpp kDefaultMaxSubscribers).
constexpr int kSubscriberCap = 64;

// A blocking stream client whose reads give up after a deadline.
class StreamPeer {
 public:
  explicit StreamPeer(unsigned port) : socket_(io_) {
    socket_.connect(tcp::endpoint(asio::ip::make_address("127.0.0.1"), static_cast<unsigned short>(port)));
    const timeval deadline{5, 0};
    ::setsockopt(socket_.native_handle(), SOL_SOCKET, SO_RCVTIMEO, &deadline, sizeof deadline);
  }
  void send(const std::vector<std::uint8_t>& bytes) {
    boost::system::error_code ec;  // the server may close before all is written: that is its right
    asio::write(socket_, asio::buffer(bytes), ec);
  }
  // The next message; an error at EOF or on a timeout.
  Result<stream::Message> read() {
    std::uint8_t header[4];
    boost::system::error_code ec;
    asio::read(socket_, asio::buffer(header), ec);
    if (ec) return fail(ErrorCode::Io, ec.message());
    std::vector<std::uint8_t> payload((std::size_t{header[0]} << 24) | (std::size_t{header[1]} << 16) |
                                      (std::size_t{header[2]} << 8) | header[3]);
    asio::read(socket_, asio::buffer(payload), ec);
    if (ec) return fail(ErrorCode::Io, ec.message());
    return stream::decodeMessage(payload);
  }
  // Reads past Hello and heartbeats to the Error the server refuses with,
  // then expects the server to end the connection.
  void expectRefused(const std::string& says) {
    for (;;) {
      auto m = read();
      ASSERT_TRUE(m) << "no Error before the end: " << m.error().detail;
      if (std::holds_alternative<stream::Hello>(*m) || std::holds_alternative<stream::Heartbeat>(*m)) continue;
      const auto* error = std::get_if<stream::StreamError>(&*m);
      ASSERT_NE(error, nullptr) << stream::kindName(*m);
      EXPECT_NE(error->detail.find(says), std::string::npos) << error->detail;
      break;
    }
    // The server shuts down its side; whatever we still send is discarded.
    socket_.shutdown(tcp::socket::shutdown_send);
    auto end = read();
    EXPECT_FALSE(end) << "the connection stayed open after the Error";
  }

 private:
  asio::io_context io_;
  tcp::socket socket_;
};

class HostileWeatherd : public ::testing::Test {
 protected:
  void SetUp() override {
    weatherd_.emplace("hostile-stream", SKY_SCENARIO_CLOUDY, true);
    ASSERT_GT(weatherd_->httpPort, 0u) << weatherd_->process->log();
  }

  // /healthz within 100 ms, from the process this test started.
  void expectHealthy(const char* after) {
    SCOPED_TRACE(after);
    ASSERT_FALSE(weatherd_->process->wait(0ms)) << "skyshell-weatherd exited:\n" << weatherd_->process->log();
    const auto started = std::chrono::steady_clock::now();
    auto reply = weatherd_->request("GET", "/healthz");
    const auto took = std::chrono::steady_clock::now() - started;
    EXPECT_EQ(reply.status, 200);
    EXPECT_LT(took, 100ms) << std::chrono::duration<double, std::milli>(took).count() << " ms";
  }

  // The value of the /metrics line that starts with `series` and a space;
  // all ones when there is none.
  std::uint64_t metric(const std::string& series) {
    const auto metrics = "\n" + weatherd_->request("GET", "/metrics").body;
    const auto at = metrics.find("\n" + series + " ");
    if (at == std::string::npos) return ~0ull;
    return std::stoull(metrics.substr(at + series.size() + 2));
  }
  std::uint64_t rejected(const std::string& reason) {
    return metric("skyshell_rejected_inputs_total{reason=\"" + reason + "\"}");
  }

  // Waits (up to 2 s) until the server has closed every refused connection.
  void waitForNoSubscribers() {
    for (int i = 0; i < 100; ++i) {
      if (metric("skyshell_subscribers") == 0) return;
      std::this_thread::sleep_for(20ms);
    }
    ADD_FAILURE() << "subscribers still connected";
  }

  std::optional<Weatherd> weatherd_;
};

TEST_F(HostileWeatherd, EveryProbeIsRefusedAndTheServerStaysUp) {
  const unsigned port = weatherd_->streamPort;
  expectHealthy("start");

  {  // A snapshot of 60 000 layers: refused from its 4-byte header.
    weather::WeatherSnapshot s;
    s.tileLevel = 8;
    weather::CloudLayer l;
    l.base_m = 1000;
    l.thickness_m = 500;
    for (std::uint32_t id = 1; id <= 60000; ++id) {
      l.id = id;
      s.layers.push_back(l);
    }
    const auto frame = stream::encodeFrame(stream::encodeMessage(s));
    std::printf("60 000-layer snapshot frame: %zu bytes\n", frame.size());
    StreamPeer peer(port);
    peer.send(frame);
    peer.expectRefused("cap is 4096");
  }
  expectHealthy("60 000-layer snapshot");

  {  // A length prefix of 4 GiB - 1.
    StreamPeer peer(port);
    peer.send({0xff, 0xff, 0xff, 0xff, 1, 2, 3});
    peer.expectRefused("frame announces 4294967295 bytes");
  }
  expectHealthy("huge length prefix");

  {  // Garbage: 64 KiB of random bytes (a random length prefix, then noise).
    std::mt19937 rng(18);
    std::vector<std::uint8_t> garbage(64 * 1024);
    for (auto& b : garbage) b = static_cast<std::uint8_t>(rng());
    StreamPeer peer(port);
    peer.send(garbage);
    peer.expectRefused("");
  }
  {  // Garbage inside a frame of an accepted size.
    std::vector<std::uint8_t> frame{0, 0, 0x02, 0};
    for (int i = 0; i < 512; ++i) frame.push_back(static_cast<std::uint8_t>(i * 97 + 5));
    StreamPeer peer(port);
    peer.send(frame);
    peer.expectRefused("verification");
  }
  expectHealthy("garbage");

  {  // A Subscribe with an absurd radius and level.
    stream::Subscribe s;
    s.area = {47.0, 8.5, 1.0e12};
    s.tileLevel = 200;
    StreamPeer peer(port);
    peer.send(stream::encodeFrame(stream::encodeMessage(s)));
    peer.expectRefused("radius_m");
  }
  expectHealthy("absurd Subscribe");
  EXPECT_EQ(rejected("stream_malformed"), 5u);

  waitForNoSubscribers();
  {  // Subscribers past the cap: each of the extra ones is told and closed.
    std::vector<std::unique_ptr<StreamPeer>> admitted;
    for (int i = 0; i < kSubscriberCap; ++i) {
      admitted.push_back(std::make_unique<StreamPeer>(port));
      auto hello = admitted.back()->read();  // served: its Hello came
      ASSERT_TRUE(hello && std::holds_alternative<stream::Hello>(*hello)) << "subscriber " << i;
    }
    for (int i = 0; i < 20; ++i) {
      StreamPeer extra(port);
      extra.expectRefused("server full: 64 subscribers, at most 64");
    }
    expectHealthy("subscribers past the cap, while 64 are connected");
  }
  EXPECT_EQ(rejected("subscriber_cap"), 20u);
  expectHealthy("subscribers past the cap");

  {  // CIGI weather: size bytes 0, 1 and past the end, from thousands of senders.
    cigi::DatagramWriter w(cigi::ByteOrder::Big);
    w.add(cigi::IgControl{});
    cigi::WeatherControl wc;
    wc.layerId = cigi::LayerId::CloudLayer2;
    wc.coverage_pct = 50;
    wc.baseElevation_m = 1500;
    wc.thickness_m = 800;
    w.add(wc);
    const std::vector<std::uint8_t> good = w.bytes();
    const std::size_t sizeByte = good.size() - cigi::WeatherControl::kSize + 1;
    asio::io_context io;
    const udp::endpoint to(asio::ip::make_address("127.0.0.1"), static_cast<unsigned short>(weatherd_->cigiPort));
    const int senders = 3000;
    for (int i = 0; i < senders; ++i) {
      udp::socket socket(io, udp::endpoint(udp::v4(), 0));  // a new source port: a new sender
      std::vector<std::uint8_t> bad = good;
      bad[sizeByte] = static_cast<std::uint8_t>(std::array<int, 4>{0, 1, 255, 200}[i % 4]);
      socket.send_to(asio::buffer(i % 5 == 4 ? good : bad), to);
      // Paced so loopback's socket buffer (a few hundred datagrams) does not
      // overflow while the sanitizer-built server reads.
      if (i % 100 == 99) std::this_thread::sleep_for(10ms);
    }
    // Let the server drain its socket before asking.
    std::this_thread::sleep_for(300ms);
    const auto cigiMalformed = rejected("cigi_malformed");
    const auto cigiRefused = rejected("cigi_refused");
    std::printf("CIGI: %d datagrams from %d senders: %llu malformed, %llu refused\n", senders, senders,
                static_cast<unsigned long long>(cigiMalformed), static_cast<unsigned long long>(cigiRefused));
    EXPECT_GE(cigiMalformed, 2000u);  // 4 in 5 bad, 2400 (UDP on loopback may drop a few under load)
    // Of the 600 good ones, all but the first kMaxCigiSenders (16) senders are refused.
    EXPECT_GE(cigiRefused, 450u);
  }
  expectHealthy("hostile CIGI datagrams");
  EXPECT_EQ(rejected("handler_failed"), 0u) << "a probe reached the last boundary";
}

// skyshell-weatherd --max-subscribers sets the cap: with 3, the fourth
// subscriber is told the server is full and closed, and the three are served.
TEST(WeatherdSubscriberCap, TheCommandLineSetsHowManySubscribersAreServed) {
  Weatherd weatherd("subscriber-cap", SKY_SCENARIO_CLOUDY, false, {"--max-subscribers", "3"});
  std::vector<std::unique_ptr<StreamPeer>> admitted;
  for (int i = 0; i < 3; ++i) {
    admitted.push_back(std::make_unique<StreamPeer>(weatherd.streamPort));
    auto hello = admitted.back()->read();
    ASSERT_TRUE(hello && std::holds_alternative<stream::Hello>(*hello)) << "subscriber " << i;
  }
  StreamPeer extra(weatherd.streamPort);
  extra.expectRefused("server full: 3 subscribers, at most 3");
  ASSERT_FALSE(weatherd.process->wait(0ms)) << weatherd.process->log();
}

}  // namespace
}  // namespace sky::test
