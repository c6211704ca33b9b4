// The renderer's stream client against a server on a loopback socket: which
// layers' tiles move with the wind after a snapshot is the server's to say
// (Layer.tiles_drift, Hello's kFeatureTileDrift); a server without the
// feature meant all of them to, and the client reads its snapshots so. A
// client that asks for its lightning keeps only its answers' flashes.
#include <chrono>
#include <optional>
#include <thread>
#include <utility>
#include <vector>

#include <boost/asio.hpp>
#include <gtest/gtest.h>

#include "sky/app/shared_state.hpp"
#include "sky/app/weather_client.hpp"
#include "sky/stream/framing.hpp"
#include "sky/stream/messages.hpp"

namespace sky::app {
namespace {

namespace asio = boost::asio;
using asio::ip::tcp;
using namespace std::chrono_literals;

// The layers of the snapshot the client holds after a server with
// `features` sends one layer whose tiles it marks as held in place.
std::vector<weather::CloudLayer> layersHeldAfter(std::uint32_t features) {
  asio::io_context serverIo;
  tcp::acceptor acceptor(serverIo, tcp::endpoint(asio::ip::make_address("127.0.0.1"), 0));
  asio::io_context io;
  SharedState state;
  WeatherClient client(io, state, "127.0.0.1", acceptor.local_endpoint().port(), "test");
  client.start();
  std::thread clientThread([&] { io.run(); });
  tcp::socket peer(serverIo);
  acceptor.accept(peer);
  weather::WeatherSnapshot s;
  s.weatherClock_s = 10;
  weather::CloudLayer l;
  l.id = 1;
  l.base_m = 1000;
  l.thickness_m = 1000;
  l.coverage = 0.5;
  l.wind = {10.0, 270.0, 0.0};
  l.tilesDrift = false;
  s.layers = {l};
  for (const stream::Message& m : {stream::Message(stream::Hello{stream::kProtocolVersion, "old", 10.0, 1.0, features}),
                                   stream::Message(s)})
    asio::write(peer, asio::buffer(stream::encodeFrame(stream::encodeMessage(m))));
  std::vector<weather::CloudLayer> held;
  for (auto until = std::chrono::steady_clock::now() + 10s; std::chrono::steady_clock::now() < until;) {
    const WeatherView v = state.weather();
    if (v.version > 0) {
      held = v.snapshot.layers;
      break;
    }
    std::this_thread::sleep_for(5ms);
  }
  client.stop();
  io.stop();
  clientThread.join();
  return held;
}

TEST(WeatherClientTileDrift, AServerThatMarksTheLayersIsTakenAtItsWord) {
  const auto held = layersHeldAfter(stream::kFeatureCameraReports | stream::kFeatureTileDrift);
  ASSERT_EQ(held.size(), 1u);
  EXPECT_FALSE(held[0].tilesDrift);
}

TEST(WeatherClientTileDrift, AnOlderServersTilesAllDrift) {
  const auto held = layersHeldAfter(stream::kFeatureCameraReports | stream::kFeatureAreas | stream::kFeatureHostClock);
  ASSERT_EQ(held.size(), 1u);
  EXPECT_TRUE(held[0].tilesDrift);
}

// A client that asks for its flashes (a headless replay, its clock at
// 5000 s) keeps its answers' flashes, and leaves out those the server sends
// at its own clock (9000 s here): kept, such a message's clock would prune
// the answers' flashes as long past.
std::vector<weather::LightningFlash> flashesHeld(bool onlyAsked) {
  asio::io_context serverIo;
  tcp::acceptor acceptor(serverIo, tcp::endpoint(asio::ip::make_address("127.0.0.1"), 0));
  asio::io_context io;
  SharedState state;
  WeatherClient client(io, state, "127.0.0.1", acceptor.local_endpoint().port(), "test");
  if (onlyAsked) client.takeOnlyAskedFlashes();
  client.start();
  std::thread clientThread([&] { io.run(); });
  tcp::socket peer(serverIo);
  acceptor.accept(peer);
  weather::LightningFlash asked;
  asked.seed = 1;
  asked.time_s = 5000.2;
  asked.lat_deg = 46;
  asked.lon_deg = 13;
  asked.energy_j = 1e9;
  asked.top_m = 5000;
  weather::LightningFlash live = asked;
  live.seed = 2;
  live.time_s = 8999.5;
  const std::uint32_t features = stream::kFeatureCameraReports | stream::kFeatureLightningRequests;
  for (const stream::Message& m :
       {stream::Message(stream::Hello{stream::kProtocolVersion, "s", 9000.0, 1.0, features}),
        stream::Message(stream::Lightning{9000.0, {asked}, 5001.0}),
        stream::Message(stream::Lightning{9000.0, {live}, std::nullopt}),
        stream::Message(stream::Lightning{9000.0, {}, 5002.0})})
    asio::write(peer, asio::buffer(stream::encodeFrame(stream::encodeMessage(m))));
  // The last answer comes after the live message: once it is in, all are.
  for (auto until = std::chrono::steady_clock::now() + 10s; std::chrono::steady_clock::now() < until;) {
    if (state.lightningAnsweredTo() == std::optional<double>(5002.0)) break;
    std::this_thread::sleep_for(5ms);
  }
  EXPECT_EQ(state.lightningAnsweredTo(), std::optional<double>(5002.0));
  const std::vector<weather::LightningFlash> held = state.weather().flashes;
  client.stop();
  io.stop();
  clientThread.join();
  return held;
}

TEST(WeatherClientLightning, AnAskingClientKeepsItsAnswersFlashes) {
  const auto held = flashesHeld(true);
  ASSERT_EQ(held.size(), 1u);
  EXPECT_EQ(held[0].seed, 1u);
}

TEST(WeatherClientLightning, LiveFlashesAtTheServersClockWouldPruneThem) {
  // A live channel's client (it does not ask): the live message's clock,
  // 4000 s past the answer's flash, prunes it.
  const auto held = flashesHeld(false);
  ASSERT_EQ(held.size(), 1u);
  EXPECT_EQ(held[0].seed, 2u);
}

}  // namespace
}  // namespace sky::app
