// The console's WebSocket feed on a real loopback socket, through the HTTP
// API's upgrade: a console that stops reading is dropped once its messages
// stall (the renderer list here is made large so the socket buffers fill)
// while a reading console goes on being served; at shutdown a reading
// console gets a close frame.
#include <gtest/gtest.h>

#include <atomic>
#include <thread>

#include <utility>  // before asio: Boost 1.74 asio uses std::exchange without including it
// GCC 12 at -O2 reports a boost::optional inside Beast's HTTP response parser
// (the client's handshake) as maybe uninitialized: a false positive.
#if defined(__GNUC__) && !defined(__clang__)
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"
#endif
#include <boost/asio/executor_work_guard.hpp>
#include <boost/beast/core.hpp>
#include <boost/beast/websocket.hpp>
#if defined(__GNUC__) && !defined(__clang__)
#pragma GCC diagnostic pop
#endif
#include <nlohmann/json.hpp>

#include "sky/server/http_api.hpp"
#include "stream_test_client.hpp"

namespace sky::server {
namespace {

namespace beast = boost::beast;
namespace websocket = beast::websocket;

// A console connected to 127.0.0.1:port; reads on its own thread when asked.
class Console {
 public:
  explicit Console(std::uint16_t port) : ws_(io_) {
    beast::get_lowest_layer(ws_).connect(tcp::endpoint(asio::ip::make_address("127.0.0.1"), port));
    ws_.handshake("127.0.0.1", "/api/ws");
  }
  ~Console() {
    if (reader_.joinable()) reader_.join();
  }
  // Reads until the feed closes, counting messages by type.
  void readInBackground() {
    reader_ = std::thread([this] {
      for (;;) {
        beast::flat_buffer b;
        beast::error_code ec;
        ws_.read(b, ec);
        if (ec) {
          error = ec.message();
          closedByServer = ec == websocket::error::closed;
          done = true;
          return;
        }
        // Only the type (the last key: nlohmann sorts them): parsing every
        // large message would make this reader too slow to keep up.
        const std::string text = beast::buffers_to_string(b.data());
        if (text.size() > 30 && text.find("\"type\":\"renderers\"", text.size() - 30) != std::string::npos)
          ++renderers;
        ++messages;
      }
    });
  }
  std::atomic<int> messages{0}, renderers{0};
  std::atomic<bool> done{false}, closedByServer{false};
  std::string error;  // why reading stopped (read once done)

 private:
  asio::io_context io_;
  websocket::stream<beast::tcp_stream> ws_;
  std::thread reader_;
};

TEST(ConsoleFeed, AConsoleThatStopsReadingIsDroppedOthersGoOn) {
  asio::io_context io;
  auto work = asio::make_work_guard(io);
  Scenario scenario;
  LiveWeather weather(scenario, WallClock::now(), [] { return WallClock::now(); }, [] { return std::int64_t{0}; });
  HttpApiOptions options;
  // Long enough that the reading console, starved on a loaded machine, is
  // not taken for a stalled one.
  options.feed.stallTimeout = 2000ms;
  options.feed.pushInterval = 50ms;
  options.feed.healthInterval = 100ms;
  // ~200 kB of renderer list per message at 20 Hz: a console that does not
  // read fills the socket buffers (a few MB on loopback) within seconds.
  nlohmann::json big = nlohmann::json::array();
  for (int i = 0; i < 1000; ++i) big.push_back({{"id", i}, {"channel", std::string(160, 'x')}});
  HttpApiHooks hooks;
  hooks.renderers = [&big] { return big; };
  auto api = HttpApi::create(io, options, weather, hooks);
  ASSERT_TRUE(api) << api.error().detail;
  std::thread ioThread([&] { io.run(); });
  // The renderer list "changes" all the time.
  std::atomic<bool> pumping{true};
  std::thread pump([&] {
    while (pumping) {
      asio::post(io, [&] { (*api)->renderersChanged(); });
      std::this_thread::sleep_for(10ms);
    }
  });

  Console reader((*api)->port());
  reader.readInBackground();
  Console idle((*api)->port());  // never reads
  std::uint64_t dropped = 0;
  for (int i = 0; i < 1000 && dropped == 0; ++i) {
    std::this_thread::sleep_for(20ms);
    dropped = onIo(io, [&] { return (*api)->feed().dropped(); });
  }
  EXPECT_EQ(dropped, 1u) << "the idle console was not dropped";
  // The reading console is still served after the drop.
  const int before = reader.renderers.load();
  for (int i = 0; i < 500 && reader.renderers.load() < before + 5; ++i) std::this_thread::sleep_for(10ms);
  EXPECT_GE(reader.renderers.load(), before + 5);
  EXPECT_FALSE(reader.done.load()) << reader.error;
  EXPECT_EQ(onIo(io, [&] { return (*api)->feed().clients(); }), 1u);

  pumping = false;
  pump.join();
  // Shutdown: the reading console gets a close frame.
  asio::post(io, [&] { (*api)->close(); });
  for (int i = 0; i < 500 && !reader.done.load(); ++i) std::this_thread::sleep_for(10ms);
  EXPECT_TRUE(reader.done.load());
  EXPECT_TRUE(reader.closedByServer.load()) << "closed without a close frame";
  work.reset();
  ioThread.join();
}

}  // namespace
}  // namespace sky::server
