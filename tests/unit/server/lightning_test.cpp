// The server's lightning: the storm process over the areas subscribers
// watch (its count against the rate over the cells S2 covers the area with),
// none where there is no cumulonimbus or no subscriber, an asked-for flash
// under its cloud, the API's request checks, the event queue's bound, and a
// flash reaching a subscriber on a real socket (and not one far away).
#include <chrono>
#include <cmath>
#include <cstdio>
#include <thread>

#include <gtest/gtest.h>

#include "sky/server/api_json.hpp"
#include "sky/server/lightning_service.hpp"
#include "sky/server/live_weather.hpp"
#include "sky/server/outbox.hpp"
#include "sky/server/scenario.hpp"
#include "sky/server/server.hpp"
#include "sky/weather/tiling.hpp"
#include "stream_test_client.hpp"

namespace sky::server {
namespace {

using namespace std::chrono_literals;

weather::CloudLayer storm(weather::CloudType type, double coverage) {
  weather::CloudLayer l;
  l.id = 1;
  l.type = type;
  l.base_m = 1100;
  l.thickness_m = 9000;
  l.coverage = coverage;
  l.density = 1;
  return l;
}

// A LiveWeather whose wall clock the test moves (the weather clock runs at
// the scenario's rate, 1).
struct MovingWeather {
  WallClock::time_point now{std::chrono::seconds(1000)};
  LiveWeather weather{Scenario{}, now, [this] { return now; }, [] { return std::int64_t{1700000000000}; }};
  void set(const weather::CloudLayer& layer) {
    auto ok = weather.submit({{SetLayer{layer, Timing{}}}, "test", "api"});
    ASSERT_TRUE(ok) << ok.error().detail;
  }
};

TEST(LightningService, StormsFlashAtTheirRateWhereSubscribersLook) {
  MovingWeather w;
  w.set(storm(weather::CloudType::Cumulonimbus, 0.5));
  constexpr double kRate = 6.0;  // per minute per 100 km^2
  LightningService service({kRate, 11});
  const weather::SphericalCap area{46.0, 8.0, 20'000};
  // What the rate gives over the S2 cells of the process's level that
  // cover the area, at half cover, over 300 s.
  double km2 = 0;
  for (std::uint64_t c : weather::coverCap(area, kLightningTileLevel, 100000)) km2 += weather::cellArea_m2(c) / 1e6;
  const double expected = 0.5 * km2 / 100.0 * kRate / 60.0 * 300.0;
  ASSERT_GT(expected, 100.0);
  const weather::SphericalCap areas[] = {area};
  std::size_t n = 0;
  EXPECT_TRUE(service.tick(w.weather, w.weather.clockNow(), areas).empty()) << "the first tick only starts the clock";
  for (int s = 0; s < 300; ++s) {
    w.now += 1s;
    for (const auto& f : service.tick(w.weather, w.weather.clockNow(), areas)) {
      ++n;
      EXPECT_TRUE(flashReaches(area, f));
      EXPECT_LT(sphereDistance_m(46.0, 8.0, f.lat_deg, f.lon_deg), 20'000 + 2 * weather::averageCellEdge_m(10))
          << "in a cell of the area's covering";
    }
  }
  // Poisson: 4 standard deviations.
  EXPECT_NEAR(static_cast<double>(n), expected, 4 * std::sqrt(expected)) << km2 << " km^2";
  EXPECT_EQ(service.counters().drawn, n);
  EXPECT_EQ(service.recent(100000).size(), std::min<std::size_t>(n, kMaxRecentFlashes));

  // The cost of a tick over the widest area the process draws in (150 km,
  // ~900 cells), computing the storm cells and keeping them: printed, not
  // asserted (timings are the bench's business).
  {
    const weather::SphericalCap wide[] = {{46.0, 8.0, kLightningReach_m}};
    LightningService timed({kRate, 11});
    timed.tick(w.weather, w.weather.clockNow(), wide);
    w.now += 1s;
    auto t0 = std::chrono::steady_clock::now();
    timed.tick(w.weather, w.weather.clockNow(), wide);
    const double first = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
    t0 = std::chrono::steady_clock::now();
    for (int s = 0; s < 9; ++s) {
      w.now += 1s;
      timed.tick(w.weather, w.weather.clockNow(), wide);
    }
    std::printf("[ lightning] a tick over a %.0f km area: %.2f ms computing its storm cells, %.3f ms keeping them\n",
                kLightningReach_m / 1000, first,
                std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count() / 9);
  }

  // Nobody watching: no flashes. A clock that jumped: none for the gap.
  w.now += 1s;
  EXPECT_TRUE(service.tick(w.weather, w.weather.clockNow(), {}).empty());
  w.now += std::chrono::seconds(static_cast<int>(kMaxLightningGap_s) + 30);
  EXPECT_TRUE(service.tick(w.weather, w.weather.clockNow(), areas).empty());
}

TEST(LightningService, CumulusDoesNotFlash) {
  MovingWeather w;
  w.set(storm(weather::CloudType::Cumulonimbus, 1.0));
  LightningService service({100.0, 1});
  const weather::SphericalCap areas[] = {{46.0, 8.0, 50'000}};
  service.tick(w.weather, w.weather.clockNow(), areas);
  w.now += 5s;
  EXPECT_FALSE(service.tick(w.weather, w.weather.clockNow(), areas).empty()) << "a storm at 100 a minute";
  // The storm becomes cumulus: the storm cells kept are not used again.
  w.set(storm(weather::CloudType::Cumulus, 1.0));
  w.now += 5s;
  EXPECT_TRUE(service.tick(w.weather, w.weather.clockNow(), areas).empty());
  w.now += 30s;
  EXPECT_TRUE(service.tick(w.weather, w.weather.clockNow(), areas).empty());
}

TEST(LightningService, AnAskedForFlashComesFromTheCloudThere) {
  MovingWeather w;
  w.set(storm(weather::CloudType::Cumulonimbus, 0.8));
  LightningService service({0.0, 1});  // the process off: asked-for flashes still go
  const auto f = service.trigger(w.weather, w.weather.clockNow(), {45.5, 7.25, weather::FlashKind::CloudToGround, 3e9});
  EXPECT_EQ(f.lat_deg, 45.5);
  EXPECT_EQ(f.lon_deg, 7.25);
  EXPECT_EQ(f.time_s, w.weather.clockNow());
  EXPECT_EQ(f.bottom_m, 0.0);
  EXPECT_EQ(f.top_m, 1100.0) << "the bolt leaves the storm's base";
  EXPECT_EQ(f.energy_j, 3e9);
  const auto g = service.trigger(w.weather, w.weather.clockNow(), {45.5, 7.25, weather::FlashKind::InCloud, 1e9});
  EXPECT_NE(f.seed, g.seed) << "each asked-for flash has its own bolt";
  EXPECT_GT(g.bottom_m, 1100.0);
  ASSERT_EQ(service.recent(10).size(), 2u);
  EXPECT_EQ(service.recent(10)[1], g);
}

TEST(LightningApi, TheRequestNamesWhatIsWrong) {
  auto r = parseFlashRequest(R"({"lightning": {"lat_deg": 46.5, "lon_deg": -179.5, "kind": "in-cloud"}})");
  ASSERT_TRUE(r) << r.error().detail;
  EXPECT_EQ(r->lat_deg, 46.5);
  EXPECT_EQ(r->lon_deg, -179.5);
  EXPECT_EQ(r->kind, weather::FlashKind::InCloud);
  EXPECT_EQ(r->energy_j, weather::kTypicalFlashEnergy_j);
  r = parseFlashRequest(R"({"lightning": {"lat_deg": 0, "lon_deg": 0}})");
  ASSERT_TRUE(r);
  EXPECT_EQ(r->kind, weather::FlashKind::CloudToGround) << "the default: the flash pilots are warned of";
  const std::pair<const char*, const char*> bad[] = {
      {"[", "not JSON"},
      {"{}", "lightning"},
      {R"({"thunder": {}})", "thunder: unknown key"},
      {R"({"lightning": {"lon_deg": 0}})", "lightning.lat_deg: missing"},
      {R"({"lightning": {"lat_deg": 95, "lon_deg": 0}})", "lightning.lat_deg"},
      {R"({"lightning": {"lat_deg": 0, "lon_deg": "east"}})", "lightning.lon_deg: expected a number"},
      {R"({"lightning": {"lat_deg": 0, "lon_deg": 0, "kind": "sheet"}})", "lightning.kind"},
      {R"({"lightning": {"lat_deg": 0, "lon_deg": 0, "energy_j": -1}})", "lightning.energy_j"},
      {R"({"lightning": {"lat_deg": 0, "lon_deg": 0, "colour": 1}})", "lightning.colour: unknown key"},
  };
  for (const auto& [body, what] : bad) {
    const auto e = parseFlashRequest(body);
    ASSERT_FALSE(e) << body;
    EXPECT_NE(e.error().detail.find(what), std::string::npos) << body << ": " << e.error().detail;
  }
}

TEST(LightningApi, AFlashAsJsonKeepsItsSeedExact) {
  weather::LightningFlash f;
  f.seed = 0xfedcba9876543210ull;  // past a double's 53 bits
  f.kind = weather::FlashKind::CloudToGround;
  const auto j = toJson(f);
  EXPECT_EQ(j.at("seed").get<std::string>(), "18364758544493064720");
  EXPECT_EQ(j.at("kind").get<std::string>(), "cloud-to-ground");
}

TEST(LightningOutbox, EventsWaitInOrderAndAreBounded) {
  Outbox o;
  for (std::uint8_t i = 0; i < kMaxEventFrames + 5; ++i) o.pushEvent(Frame{i});
  EXPECT_EQ(o.droppedEvents(), 5u) << "a peer that stopped reading loses the oldest, counted";
  stream::Subscribe s;
  o.requestSnapshot(s);
  auto first = o.takeNext();
  ASSERT_TRUE(first);
  ASSERT_TRUE(std::holds_alternative<Frame>(*first)) << "events go before weather";
  EXPECT_EQ(std::get<Frame>(*first), Frame{5});
  for (std::size_t i = 1; i < kMaxEventFrames; ++i) ASSERT_TRUE(std::holds_alternative<Frame>(*o.takeNext()));
  auto next = o.takeNext();
  ASSERT_TRUE(next);
  EXPECT_TRUE(std::holds_alternative<stream::Subscribe>(*next));
}

// What a replay asks for (drawIn) is what the live process drew as its
// clock ran through the same interval: the same flashes, in order, and an
// asked-for flash of the interval that reaches the area; nothing is
// counted as drawn, and another service with the same seed answers alike.
TEST(LightningService, AnIntervalAskedForHoldsWhatTheLiveProcessDrewInIt) {
  MovingWeather w;
  w.set(storm(weather::CloudType::Cumulonimbus, 0.8));
  LightningService live({6.0, 11});
  const weather::SphericalCap area{46.0, 8.0, 20'000};
  const weather::SphericalCap areas[] = {area};
  const double from = w.weather.clockNow();
  live.tick(w.weather, from, areas);
  std::vector<weather::LightningFlash> drawn;
  for (int s = 0; s < 60; ++s) {
    w.now += 1s;
    for (const auto& f : live.tick(w.weather, w.weather.clockNow(), areas)) drawn.push_back(f);
    if (s == 30) drawn.push_back(live.trigger(w.weather, w.weather.clockNow(), {46.01, 8.0, weather::FlashKind::InCloud}));
  }
  const double to = w.weather.clockNow();
  live.trigger(w.weather, to, {-33.9, 151.2, weather::FlashKind::InCloud});  // far away, and at `to`
  ASSERT_GT(drawn.size(), 20u);
  std::stable_sort(drawn.begin(), drawn.end(), [](const auto& a, const auto& b) { return a.time_s < b.time_s; });
  const std::uint64_t drawnBefore = live.counters().drawn;
  const std::vector<weather::LightningFlash> asked = live.drawIn(w.weather, from, to, areas);
  EXPECT_EQ(asked, drawn);
  EXPECT_EQ(live.counters().drawn, drawnBefore) << "an answer is not a new flash";
  LightningService other({6.0, 11});
  const auto again = other.drawIn(w.weather, from, to, areas);
  EXPECT_EQ(again.size(), drawn.size() - 1) << "the same process; the asked-for flash is the first service's";
  // A part of the interval: the flashes in it, cut where the clock is.
  const double mid = from + 20.5;
  std::size_t inFirst = 0;
  for (const auto& f : drawn) inFirst += f.time_s <= mid ? 1 : 0;
  EXPECT_EQ(live.drawIn(w.weather, from, mid, areas).size(), inFirst);
  EXPECT_TRUE(live.drawIn(w.weather, to, to, areas).empty());
}

// A real server and two subscribers: one whose area holds the flash, one
// on the other side of the Earth.
TEST(LightningSocket, AFlashReachesTheSubscribersItLights) {
  auto scenario = loadScenario(SKY_SOURCE_DIR "/deploy/scenarios/skeleton-cumulus.toml");
  ASSERT_TRUE(scenario) << scenario.error().detail;
  const WallClock::time_point t0{std::chrono::seconds(1)};
  ServerOptions options;
  options.port = 0;
  options.heartbeatInterval = 50ms;
  options.handleSignals = false;
  options.wallNow = [t0] { return t0; };  // frozen: the process draws nothing; only the asked-for flash
  auto created = Server::create(options, WeatherState(*scenario, t0));
  ASSERT_TRUE(created) << created.error().detail;
  std::unique_ptr<Server> server = std::move(*created);
  std::thread thread([&] { server->run(); });

  TestClient near(server->port()), far(server->port());
  ASSERT_TRUE(near.readNext<stream::Hello>());
  ASSERT_TRUE(far.readNext<stream::Hello>());
  stream::Subscribe a;
  a.area = {47.0, 8.5, 20'000};
  a.tileLevel = 8;
  near.send(a);
  stream::Subscribe b = a;
  b.area = {-33.9, 151.2, 20'000};
  far.send(b);
  ASSERT_TRUE(near.readNext<weather::WeatherSnapshot>());
  ASSERT_TRUE(far.readNext<weather::WeatherSnapshot>());
  // 100 km from the near area's centre: beyond its tiles, within the reach
  // of its sky.
  const weather::LightningFlash sent =
      onIo(server->io(), [&] { return server->triggerLightning({47.9, 8.5, weather::FlashKind::CloudToGround, 2e9}); });
  auto got = near.readNext<stream::Lightning>();
  ASSERT_TRUE(got) << got.error().detail;
  ASSERT_EQ(got->flashes.size(), 1u);
  EXPECT_EQ(got->flashes[0], sent) << "sent as drawn: every channel lights the same flash";
  // The far subscriber gets heartbeats only (a read of 300 ms of them).
  const auto until = std::chrono::steady_clock::now() + 300ms;
  while (std::chrono::steady_clock::now() < until) {
    auto m = far.read(200ms);
    ASSERT_TRUE(m) << m.error().detail;
    EXPECT_FALSE(std::holds_alternative<stream::Lightning>(*m)) << "a flash 16000 km away is not sent";
  }
  EXPECT_EQ(server->streamCounters().flashesTriggered.load(), 1u);
  EXPECT_EQ(onIo(server->io(), [&] { return server->recentFlashes(5); }).size(), 1u);
  server->stop();
  thread.join();
}

// On real sockets: a renderer asks for the flashes of an interval and gets
// them as one Lightning, marked as the answer to that interval's end.
TEST(LightningSocket, ARendererAsksForTheFlashesOfAnInterval) {
  Scenario scenario;
  scenario.layers = {storm(weather::CloudType::Cumulonimbus, 1.0)};
  const WallClock::time_point t0{std::chrono::seconds(1)};
  ServerOptions options;
  options.port = 0;
  options.heartbeatInterval = 50ms;
  options.handleSignals = false;
  options.wallNow = [t0] { return t0; };  // frozen: the live process draws nothing
  options.lightning = {60.0, 5};
  auto created = Server::create(options, WeatherState(scenario, t0));
  ASSERT_TRUE(created) << created.error().detail;
  std::unique_ptr<Server> server = std::move(*created);
  std::thread thread([&] { server->run(); });
  TestClient client(server->port());
  auto hello = client.readNext<stream::Hello>();
  ASSERT_TRUE(hello);
  EXPECT_NE(hello->features & stream::kFeatureLightningRequests, 0u);
  stream::Subscribe a;
  a.area = {47.0, 8.5, 20'000};
  a.tileLevel = 8;
  client.send(a);
  ASSERT_TRUE(client.readNext<weather::WeatherSnapshot>());
  // An hour ahead of the server's clock, as a replay may be.
  const double from = 3600, to = 3630;
  client.send(stream::LightningRequest{from, to});
  auto got = client.readNext<stream::Lightning>();
  ASSERT_TRUE(got) << got.error().detail;
  ASSERT_TRUE(got->answersTo_s);
  EXPECT_EQ(*got->answersTo_s, to);
  ASSERT_FALSE(got->flashes.empty()) << "a closed storm at 60 a minute per 100 km^2 over 30 s";
  for (const auto& f : got->flashes) {
    EXPECT_GT(f.time_s, from);
    EXPECT_LE(f.time_s, to);
  }
  client.send(stream::LightningRequest{from, to});
  auto again = client.readNext<stream::Lightning>();
  ASSERT_TRUE(again);
  EXPECT_EQ(again->flashes, got->flashes) << "asked twice, the same flashes";
  EXPECT_EQ(server->streamCounters().lightningRequests.load(), 2u);
  server->stop();
  thread.join();
}

}  // namespace
}  // namespace sky::server

namespace sky::server {
namespace {

// A replay's frames ask within one 10 s interval of weather clock many
// times: the storm cells are computed once for them, and an answer does not
// depend on what was asked before (a second service asked only the last
// interval draws the same flashes). A weather change, or an interval asked
// for after more than kRequestCellsKept others, computes them again.
TEST(LightningService, TheFramesOfOneIntervalComputeItsStormCellsOnce) {
  MovingWeather w;
  w.set(storm(weather::CloudType::Cumulonimbus, 0.8));
  LightningService service({60.0, 3});
  const weather::SphericalCap areas[] = {{46.0, 8.0, 20'000}};
  const double t0 = std::floor(w.weather.clockNow() / kStormCellRefresh_s) * kStormCellRefresh_s + 1000;
  bool computed = false;
  std::size_t flashes = 0;
  for (int frame = 0; frame < 270; ++frame) {  // 9 s at 30 frames a second
    const double from = t0 + frame / 30.0, to = from + 1 / 30.0;
    flashes += service.drawIn(w.weather, from, to, areas, &computed).size();
    EXPECT_EQ(computed, frame == 0) << "frame " << frame;
  }
  EXPECT_GT(flashes, 0u) << "a storm of 60 a minute per 100 km^2 over 9 s";
  EXPECT_EQ(service.counters().requestCellsComputed, 1u);
  const auto next = service.drawIn(w.weather, t0 + 10, t0 + 10.5, areas, &computed);
  EXPECT_TRUE(computed) << "the next interval";
  LightningService fresh({60.0, 3});
  EXPECT_EQ(fresh.drawIn(w.weather, t0 + 10, t0 + 10.5, areas), next) << "the same answer without the history";
  // More than kRequestCellsKept other intervals, then the first again.
  for (std::size_t k = 2; k < kRequestCellsKept + 3; ++k)
    service.drawIn(w.weather, t0 + 10.0 * static_cast<double>(k), t0 + 10.0 * static_cast<double>(k) + 1, areas);
  service.drawIn(w.weather, t0, t0 + 1, areas, &computed);
  EXPECT_TRUE(computed) << "forgotten: the cache holds at most kRequestCellsKept";
  const std::uint64_t before = service.counters().requestCellsComputed;
  service.drawIn(w.weather, t0, t0 + 1, areas, &computed);
  EXPECT_FALSE(computed);
  w.set(storm(weather::CloudType::Cumulonimbus, 0.3));
  service.drawIn(w.weather, t0, t0 + 1, areas, &computed);
  EXPECT_TRUE(computed) << "the weather changed";
  EXPECT_EQ(service.counters().requestCellsComputed, before + 1);
}

// On a real socket: a peer that asks for 40 intervals all over the clock
// (each computing storm cells) gets every answer, in order, but no faster
// than its budget lets the server compute them: the storm cells computed
// stay within the burst plus the rate times the time it took, and the
// input was paused. Another subscriber is served meanwhile.
TEST(LightningSocket, APeerAskingAllOverTheClockWaitsForItsBudget) {
  Scenario scenario;
  scenario.layers = {storm(weather::CloudType::Cumulonimbus, 1.0)};
  const WallClock::time_point t0{std::chrono::seconds(1)};
  ServerOptions options;
  options.port = 0;
  options.heartbeatInterval = 50ms;
  options.handleSignals = false;
  options.wallNow = [t0] { return t0; };
  options.lightning = {60.0, 5};
  auto created = Server::create(options, WeatherState(scenario, t0));
  ASSERT_TRUE(created) << created.error().detail;
  std::unique_ptr<Server> server = std::move(*created);
  std::thread thread([&] { server->run(); });
  TestClient greedy(server->port()), other(server->port());
  ASSERT_TRUE(greedy.readNext<stream::Hello>());
  ASSERT_TRUE(other.readNext<stream::Hello>());
  stream::Subscribe a;
  a.area = {47.0, 8.5, 20'000};
  a.tileLevel = 8;
  greedy.send(a);
  ASSERT_TRUE(greedy.readNext<weather::WeatherSnapshot>());
  constexpr int kAsked = 40;
  const auto start = std::chrono::steady_clock::now();
  for (int k = 0; k < kAsked; ++k) greedy.send(stream::LightningRequest{100.0 * k, 100.0 * k + 5});
  // The other subscriber's snapshot while the greedy one's requests wait.
  other.send(a);
  ASSERT_TRUE(other.readNext<weather::WeatherSnapshot>());
  for (int k = 0; k < kAsked; ++k) {
    auto got = greedy.readNext<stream::Lightning>();
    ASSERT_TRUE(got) << "answer " << k << ": " << got.error().detail;
    ASSERT_TRUE(got->answersTo_s);
    EXPECT_EQ(*got->answersTo_s, 100.0 * k + 5) << "in the order asked";
  }
  const double took_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  const auto& c = server->streamCounters();
  EXPECT_EQ(c.lightningRequests.load(), static_cast<std::uint64_t>(kAsked));
  EXPECT_EQ(c.lightningCellsComputed.load(), static_cast<std::uint64_t>(kAsked)) << "each a new interval";
  EXPECT_GE(c.lightningInputPauses.load(), 1u);
  // Every computation was within the budget: 40 take at least
  // (40 - burst) / rate seconds.
  EXPECT_GE(took_s, (kAsked - kLightningComputeBurst - 1) / kLightningComputeRate_perS);
  server->stop();
  thread.join();
}

}  // namespace
}  // namespace sky::server
