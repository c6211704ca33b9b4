// The server on a real loopback socket, driven by a plain asio client: Hello,
// Subscribe -> Snapshot, Heartbeats, and protocol errors answered with Error and
// a close while another client keeps being served.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <optional>
#include <thread>

#include "sky/geo/geodetic.hpp"
#include "sky/server/scenario.hpp"
#include "sky/weather/tiling.hpp"
#include "sky/server/server.hpp"
#include "stream_test_client.hpp"

namespace sky::server {
namespace {

// A region over the test areas (46-49 N, 8.5 E) that thins the scenario's
// layer 1: without one the weather is uniform and snapshots carry no tiles.
void addRegion(Server& server, double coverage = 0.25) {
  weather::Region r;
  r.id = 1;
  r.centerLat_deg = 47.5;
  r.centerLon_deg = 10.0;
  r.sizeX_m = r.sizeY_m = 600'000;
  weather::CloudLayer l = server.weather().view().layers.at(0);
  l.coverage = coverage;
  r.layers = {l};
  auto ok = server.weather().submit({{SetRegion{r, Timing{}}}, "test", "api"});
  ASSERT_TRUE(ok) << ok.error().detail;
}

// A server on an ephemeral loopback port, run on its own thread; the weather
// clock is frozen at a known wall time so every clock on the wire is exact.
class ServerFixture : public ::testing::Test {
 protected:
  static constexpr double kStart_s = 500.0;

  void SetUp() override {
    auto scenario = loadScenario(SKY_SOURCE_DIR "/deploy/scenarios/skeleton-cumulus.toml");
    ASSERT_TRUE(scenario) << scenario.error().detail;
    scenario->clock.start_s = kStart_s;
    const WallClock::time_point t0{std::chrono::seconds(1)};
    ServerOptions options;
    options.port = 0;
    options.heartbeatInterval = 50ms;
    options.serverId = "test-server";
    options.handleSignals = false;
    options.wallNow = [t0] { return t0; };
    auto server = Server::create(options, WeatherState(*scenario, t0));
    ASSERT_TRUE(server) << server.error().detail;
    server_ = std::move(*server);
    ASSERT_NE(server_->port(), 0);
    addRegion(*server_);
    thread_ = std::thread([this] { server_->run(); });
  }

  void TearDown() override {
    if (!server_) return;
    server_->stop();
    thread_.join();  // run() returns: shutdown closed every session and the acceptor
  }

  std::unique_ptr<Server> server_;
  std::thread thread_;
};

stream::Subscribe subscribe(double lat_deg, double lon_deg, double radius_m, int level) {
  stream::Subscribe s;
  s.area = {lat_deg, lon_deg, radius_m};
  s.tileLevel = level;
  return s;
}

void expectServing(TestClient& client, double lat_deg) {
  client.send(subscribe(lat_deg, 8.5, 20'000, 10));
  auto snapshot = client.readNext<weather::WeatherSnapshot>();
  ASSERT_TRUE(snapshot) << snapshot.error().detail;
  EXPECT_EQ(snapshot->tileLevel, 10);
  EXPECT_FALSE(snapshot->tiles.empty());
}

TEST_F(ServerFixture, HelloSubscribeSnapshotHeartbeat) {
  TestClient client(server_->port());
  auto hello = client.readNext<stream::Hello>();
  ASSERT_TRUE(hello) << hello.error().detail;
  EXPECT_EQ(hello->protocolVersion, stream::kProtocolVersion);
  EXPECT_EQ(hello->serverId, "test-server");
  EXPECT_DOUBLE_EQ(hello->weatherClock_s, kStart_s);
  EXPECT_DOUBLE_EQ(hello->clockRate, 1.0);

  client.send(subscribe(47.4, 8.5, 30'000, 10));
  auto snapshot = client.readNext<weather::WeatherSnapshot>();
  ASSERT_TRUE(snapshot) << snapshot.error().detail;
  EXPECT_DOUBLE_EQ(snapshot->weatherClock_s, kStart_s);
  EXPECT_EQ(snapshot->tileLevel, 10);
  ASSERT_EQ(snapshot->layers.size(), 1u);
  EXPECT_EQ(snapshot->layers[0].type, weather::CloudType::Cumulus);
  EXPECT_NEAR(snapshot->layers[0].coverage, 0.6, 1e-6);
  ASSERT_FALSE(snapshot->tiles.empty());
  for (const auto& t : snapshot->tiles) {
    EXPECT_EQ(t.layerId, 1u);
    EXPECT_NEAR(t.coverage, 0.25f, 0.5f / 255) << "the region's coverage, quantised to 1/255";
  }

  auto heartbeat = client.readNext<stream::Heartbeat>();
  ASSERT_TRUE(heartbeat) << heartbeat.error().detail;
  EXPECT_DOUBLE_EQ(heartbeat->weatherClock_s, kStart_s);

  // Re-subscribing (the camera moved) gets a new snapshot for the new area.
  client.send(subscribe(-33.9, 151.2, 10'000, 11));
  auto again = client.readNext<weather::WeatherSnapshot>();
  ASSERT_TRUE(again) << again.error().detail;
  EXPECT_EQ(again->tileLevel, 11);
  // Far from the region: uniform weather, no tiles, only the layer table.
  EXPECT_TRUE(again->tiles.empty());
  ASSERT_EQ(again->layers.size(), 1u);
  EXPECT_NEAR(again->layers[0].coverage, 0.6, 1e-6);
}

// A change in a subscriber's area goes out as a Delta from the snapshot it
// holds when that is smaller; applied, it equals what a fresh subscription
// gets. Here the global layer changes while the region (covering the whole
// area) keeps its tiles: the delta is the one layer and no tiles.
TEST_F(ServerFixture, AChangeArrivesAsADeltaThatEqualsAFreshSnapshot) {
  TestClient client(server_->port());
  ASSERT_TRUE(client.readNext<stream::Hello>());
  client.send(subscribe(47.4, 8.5, 30'000, 10));
  auto held = client.readNext<weather::WeatherSnapshot>();
  ASSERT_TRUE(held) << held.error().detail;
  ASSERT_FALSE(held->tiles.empty());
  asio::post(server_->io(), [this] {
    weather::CloudLayer l = server_->weather().view().layers.at(0);
    l.coverage = 0.7;
    ASSERT_TRUE(server_->weather().submit({{SetLayer{l, Timing{}}}, "test", "api"}));
  });
  auto delta = client.readNext<weather::WeatherDelta>();
  ASSERT_TRUE(delta) << delta.error().detail;
  ASSERT_EQ(delta->layers.size(), 1u);
  EXPECT_NEAR(delta->layers[0].coverage, 0.7, 1e-6);
  EXPECT_TRUE(delta->tiles.empty()) << "inside the region the tiles did not change";
  ASSERT_TRUE(weather::applyDelta(*held, *delta));
  TestClient fresh(server_->port());
  ASSERT_TRUE(fresh.readNext<stream::Hello>());
  fresh.send(subscribe(47.4, 8.5, 30'000, 10));
  auto expected = fresh.readNext<weather::WeatherSnapshot>();
  ASSERT_TRUE(expected);
  ASSERT_EQ(held->layers.size(), expected->layers.size());
  EXPECT_NEAR(held->layers[0].coverage, expected->layers[0].coverage, 1e-6);
  EXPECT_EQ(held->tiles, expected->tiles);
  // The region itself changes: every tile is new, so a whole Snapshot comes.
  asio::post(server_->io(), [this] {
    addRegion(*server_, 0.8);
  });
  auto m = client.read();
  while (m && std::holds_alternative<stream::Heartbeat>(*m)) m = client.read();
  ASSERT_TRUE(m);
  ASSERT_TRUE(std::holds_alternative<weather::WeatherSnapshot>(*m)) << stream::kindName(*m);
  for (const auto& t : std::get<weather::WeatherSnapshot>(*m).tiles) EXPECT_NEAR(t.coverage, 0.8f, 0.5f / 255);
}

// Two areas on one connection (a renderer's detailed area and its wide
// coarse one): the Hello says the server takes them; each Subscribe is
// answered with a Snapshot of its own area index, level and cells; a weather
// change gives each area its own Delta, which applies to that area's snapshot
// only; and re-subscribing one area leaves the other's Delta chain alone.
TEST_F(ServerFixture, TwoAreasAreAnsweredEachOnItsOwn) {
  TestClient client(server_->port());
  auto hello = client.readNext<stream::Hello>();
  ASSERT_TRUE(hello);
  EXPECT_NE(hello->features & stream::kFeatureAreas, 0u);
  client.send(subscribe(47.4, 8.5, 30'000, 10));
  auto fine = client.readNext<weather::WeatherSnapshot>();
  ASSERT_TRUE(fine) << fine.error().detail;
  stream::Subscribe wide = subscribe(47.4, 8.5, 400'000, 7);
  wide.areaIndex = 1;
  client.send(wide);
  auto coarse = client.readNext<weather::WeatherSnapshot>();
  ASSERT_TRUE(coarse) << coarse.error().detail;
  EXPECT_EQ(fine->areaIndex, 0);
  EXPECT_EQ(fine->tileLevel, 10);
  EXPECT_EQ(coarse->areaIndex, 1);
  EXPECT_EQ(coarse->tileLevel, 7);
  ASSERT_FALSE(coarse->tiles.empty());
  // The wide area's cells reach far beyond the detailed one's 30 km: the
  // region's tiles there arrive only through it.
  double farthest_m = 0;
  for (const auto& t : coarse->tiles) {
    EXPECT_TRUE(weather::isCellAtLevel(t.cellId, 7));
    const auto c = weather::cellCentre(t.cellId);
    farthest_m = std::max(farthest_m, geo::geodesicDistance_m(47.4, 8.5, c.lat_deg, c.lon_deg));
  }
  EXPECT_GT(farthest_m, 300'000.0);

  asio::post(server_->io(), [this] {
    weather::CloudLayer l = server_->weather().view().layers.at(0);
    l.coverage = 0.7;
    ASSERT_TRUE(server_->weather().submit({{SetLayer{l, Timing{}}}, "test", "api"}));
  });
  std::array<std::optional<weather::WeatherDelta>, 2> deltas;
  for (int n = 0; n < 2; ++n) {
    auto d = client.readNext<weather::WeatherDelta>();
    ASSERT_TRUE(d) << d.error().detail;
    ASSERT_LT(d->areaIndex, 2);
    EXPECT_FALSE(deltas[d->areaIndex]) << "one delta per area";
    deltas[d->areaIndex] = *d;
  }
  ASSERT_TRUE(deltas[0] && deltas[1]);
  weather::WeatherSnapshot crossed = *fine;
  EXPECT_FALSE(weather::applyDelta(crossed, *deltas[1])) << "area 1's delta must not apply to area 0";
  ASSERT_TRUE(weather::applyDelta(*fine, *deltas[0]));
  ASSERT_TRUE(weather::applyDelta(*coarse, *deltas[1]));
  EXPECT_NEAR(fine->layers[0].coverage, 0.7, 1e-6);
  EXPECT_NEAR(coarse->layers[0].coverage, 0.7, 1e-6);

  // The wide area moves; the detailed area still gets Deltas from what it holds.
  wide.area.centerLat_deg = 50.0;
  client.send(wide);
  auto moved = client.readNext<weather::WeatherSnapshot>();
  ASSERT_TRUE(moved);
  EXPECT_EQ(moved->areaIndex, 1);
  asio::post(server_->io(), [this] {
    weather::CloudLayer l = server_->weather().view().layers.at(0);
    l.coverage = 0.5;
    ASSERT_TRUE(server_->weather().submit({{SetLayer{l, Timing{}}}, "test", "api"}));
  });
  bool fineDelta = false;
  for (int n = 0; n < 2; ++n) {
    auto m = client.read();
    while (m && std::holds_alternative<stream::Heartbeat>(*m)) m = client.read();
    ASSERT_TRUE(m);
    if (const auto* d = std::get_if<weather::WeatherDelta>(&*m); d && d->areaIndex == 0) {
      fineDelta = true;
      ASSERT_TRUE(weather::applyDelta(*fine, *d));
    }
  }
  EXPECT_TRUE(fineDelta);
  EXPECT_NEAR(fine->layers[0].coverage, 0.5, 1e-6);
}

TEST_F(ServerFixture, TooFineALevelIsLoweredAndReported) {
  TestClient client(server_->port());
  ASSERT_TRUE(client.readNext<stream::Hello>());
  client.send(subscribe(45.0, 10.0, 1'000'000, 20));
  auto snapshot = client.readNext<weather::WeatherSnapshot>();
  ASSERT_TRUE(snapshot) << snapshot.error().detail;
  EXPECT_LT(snapshot->tileLevel, 20);
  EXPECT_LE(snapshot->tiles.size(), kDefaultMaxCells);
}

TEST_F(ServerFixture, GarbageGetsErrorAndCloseWhileOthersKeepWorking) {
  TestClient good(server_->port());
  ASSERT_TRUE(good.readNext<stream::Hello>());
  expectServing(good, 47.0);

  TestClient bad(server_->port());
  ASSERT_TRUE(bad.readNext<stream::Hello>());
  bad.sendBytes(stream::encodeFrame(std::vector<std::uint8_t>(16, 0xAB)));
  auto error = bad.readNext<stream::StreamError>();
  ASSERT_TRUE(error) << error.error().detail;
  EXPECT_EQ(error->code, static_cast<std::uint16_t>(ErrorCode::Malformed));
  EXPECT_FALSE(error->detail.empty());
  auto after = bad.read();
  ASSERT_FALSE(after);
  EXPECT_EQ(after.error().detail, "eof");

  expectServing(good, 48.0);
  ASSERT_TRUE(good.readNext<stream::Heartbeat>());
}

TEST_F(ServerFixture, OversizedFrameGetsTooLargeError) {
  TestClient bad(server_->port());
  ASSERT_TRUE(bad.readNext<stream::Hello>());
  bad.sendBytes({0xFF, 0xFF, 0xFF, 0xFF, 0x00});
  auto error = bad.readNext<stream::StreamError>();
  ASSERT_TRUE(error) << error.error().detail;
  EXPECT_EQ(error->code, static_cast<std::uint16_t>(ErrorCode::TooLarge));
  EXPECT_EQ(bad.read().error().detail, "eof");
}

TEST_F(ServerFixture, ServerOnlyMessagesFromAClientAreRejected) {
  for (const stream::Message& m :
       {stream::Message(stream::Hello{}), stream::Message(weather::WeatherSnapshot{})}) {
    TestClient bad(server_->port());
    ASSERT_TRUE(bad.readNext<stream::Hello>());
    bad.send(m);
    auto error = bad.readNext<stream::StreamError>();
    ASSERT_TRUE(error) << error.error().detail;
    EXPECT_EQ(error->code, static_cast<std::uint16_t>(ErrorCode::Unsupported));
    EXPECT_NE(error->detail.find(stream::kindName(m)), std::string::npos) << error->detail;
    EXPECT_EQ(bad.read().error().detail, "eof");
  }
  TestClient good(server_->port());
  ASSERT_TRUE(good.readNext<stream::Hello>());
  expectServing(good, 47.2);
}

TEST_F(ServerFixture, SubscribeOfAnotherProtocolVersionGetsErrorAndClose) {
  TestClient old(server_->port());
  ASSERT_TRUE(old.readNext<stream::Hello>());
  stream::Subscribe s;
  s.protocolVersion = stream::kProtocolVersion - 1;
  s.area = {46.2, 12.8, 50000};
  old.send(s);
  auto error = old.readNext<stream::StreamError>();
  ASSERT_TRUE(error) << error.error().detail;
  EXPECT_EQ(error->code, static_cast<std::uint16_t>(ErrorCode::Unsupported));
  EXPECT_NE(error->detail.find("protocol_version " + std::to_string(stream::kProtocolVersion - 1)),
            std::string::npos)
      << error->detail;
  EXPECT_EQ(old.read().error().detail, "eof");
}

TEST_F(ServerFixture, StopsWithClientsConnected) {
  TestClient a(server_->port());
  TestClient b(server_->port());
  ASSERT_TRUE(a.readNext<stream::Hello>());
  ASSERT_TRUE(b.readNext<stream::Hello>());
  server_->stop();
  thread_.join();
  server_.reset();
  // Both connections are closed by the shutdown (possibly after heartbeats).
  for (TestClient* c : {&a, &b}) {
    for (;;) {
      auto m = c->read();
      if (!m) {
        EXPECT_NE(m.error().code, ErrorCode::Timeout);
        break;
      }
    }
  }
}

// A subscriber that stops reading is dropped after the stall bound (300 ms
// here) while the server pushes snapshots at it; another subscriber keeps
// getting its weather all along, and the drop is counted.
TEST(Server, ASubscriberThatStopsReadingIsDroppedOthersGoOn) {
  auto scenario = loadScenario(SKY_SOURCE_DIR "/deploy/scenarios/skeleton-cumulus.toml");
  ASSERT_TRUE(scenario);
  const WallClock::time_point t0{std::chrono::seconds(1)};
  ServerOptions options;
  options.heartbeatInterval = 50ms;
  options.handleSignals = false;
  options.wallNow = [t0] { return t0; };
  options.stallTimeout = 300ms;
  auto created = Server::create(options, WeatherState(*scenario, t0));
  ASSERT_TRUE(created);
  std::unique_ptr<Server> server = std::move(*created);
  addRegion(*server);
  std::thread thread([&] { server->run(); });

  TestClient good(server->port());
  ASSERT_TRUE(good.readNext<stream::Hello>());
  expectServing(good, 47.0);
  TestClient slow(server->port());
  ASSERT_TRUE(slow.readNext<stream::Hello>());
  // ~20000 cells at ~1 km: a ~0.5 MB snapshot per change, never read.
  slow.send(subscribe(46.0, 13.0, 80'000, 13));
  const auto start = std::chrono::steady_clock::now();
  // Each change moves the region's coverage: every tile changes, so each
  // update is about a whole snapshot.
  int step = 0;
  while (server->streamCounters().stalledDropped.load() == 0 && std::chrono::steady_clock::now() - start < 20s) {
    asio::post(server->io(), [&server, coverage = 0.1 + 0.1 * (step++ % 5)] {
      addRegion(*server, coverage);
    });
    std::this_thread::sleep_for(20ms);
  }
  EXPECT_EQ(server->streamCounters().stalledDropped.load(), 1u);
  EXPECT_GT(server->streamCounters().bytes.load(), 1'000'000u) << "the buffers filled before the stall";
  // The good subscriber was served throughout and still is.
  expectServing(good, 48.0);
  // The registry is the io thread's: asked there (a read from here races).
  auto subscribers = [&] { return onIo(server->io(), [&] { return server->subscribers(); }); };
  for (int i = 0; i < 50 && subscribers() != 1; ++i) std::this_thread::sleep_for(20ms);
  EXPECT_EQ(subscribers(), 1u);
  server->stop();
  thread.join();
}

TEST(Server, BadListenAddressIsAnError) {
  Scenario scenario;
  ServerOptions options;
  options.listenAddress = "not-an-address";
  auto server = Server::create(options, WeatherState(scenario, WallClock::now()));
  ASSERT_FALSE(server);
  EXPECT_EQ(server.error().code, ErrorCode::InvalidArgument);
}

TEST(Server, PortInUseIsAnIoError) {
  Scenario scenario;
  ServerOptions options;
  options.handleSignals = false;
  auto first = Server::create(options, WeatherState(scenario, WallClock::now()));
  ASSERT_TRUE(first) << first.error().detail;
  options.port = (*first)->port();
  auto second = Server::create(options, WeatherState(scenario, WallClock::now()));
  ASSERT_FALSE(second);
  EXPECT_EQ(second.error().code, ErrorCode::Io);
}

}  // namespace
}  // namespace sky::server
