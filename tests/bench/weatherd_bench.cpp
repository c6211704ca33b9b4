// Weather server benchmark (issue 4): many subscribers on loopback, each with
// its own area (or --channels N to an area, as the channels of one
// simulator), under a storm of changes; not a timed test (ctest only runs
// it briefly, label bench), the numbers come from running it by hand:
//   build/release/tests/bench/sky_weatherd_bench --subscribers 64 --rate 50 --seconds 10
// It measures
// * change-to-delivery latency: from submitting a change on the server's io
//   thread to a subscriber holding a frame that has it (p50 / p99 over every
//   delivery; a subscriber that is behind gets the newest state, so changes
//   it never saw are counted as coalesced, not as deliveries);
// * the server thread's CPU time at idle (heartbeats only) and in the storm,
//   as a percentage of one core;
// * frames and bytes sent (a change goes out as a Delta when that is smaller
//   than a snapshot), and the size of one snapshot for a 300 km wide
//   area with 3 layers, and of the frame one layer's coverage change costs.
// With --storms 1 the lowest layer is cumulonimbus, so the server's lightning
// process runs over every subscriber's area as well (its cost at idle and in
// the storm of changes, which make it recompute its storm cells).
// The server runs in this process on its own thread (real TCP sockets on
// loopback); the subscribers share one client thread.
#include <pthread.h>
#include <time.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <chrono>
#include <cstdio>
#include <fstream>
#include <memory>
#include <mutex>
#include <random>
#include <string>
#include <thread>
#include <vector>

#include <utility>  // before asio: Boost 1.74 asio uses std::exchange without including it
#include <boost/asio.hpp>
#include <nlohmann/json.hpp>

#include "sky/server/server.hpp"
#include "sky/server/snapshot_builder.hpp"
#include "sky/stream/framing.hpp"
#include "sky/stream/messages.hpp"
#include "sky/weather/tiling.hpp"
#include "weatherd_bench_clients.hpp"

using namespace std::chrono_literals;
using namespace sky::bench;

namespace {

struct Options {
  int subscribers = 64;
  // Subscribers per area: the channels of one simulator subscribe the same
  // area round one camera (1: every subscriber its own area).
  int channels = 1;
  double rate = 50;           // changes per second
  double seconds = 10;        // storm length
  double idleSeconds = 5;     // idle measurement
  double radius_m = 120000;   // each subscriber's area (the renderer's)
  std::size_t maxTiles = 4096;  // the renderer's tile budget (levelForRadius)
  bool regional = false;  // the storm's weather has a region over every subscriber's area
  // The lowest layer is cumulonimbus: the server's lightning process draws
  // flashes over every subscriber's area at each heartbeat (its storm cells
  // recomputed after every change and every 10 s of clock).
  bool storms = false;
  std::string json;
};

std::vector<sky::weather::CloudLayer> threeLayers() {
  std::vector<sky::weather::CloudLayer> layers;
  const sky::weather::CloudType types[] = {sky::weather::CloudType::Cumulus, sky::weather::CloudType::Altostratus,
                                           sky::weather::CloudType::Cirrus};
  for (std::uint32_t i = 0; i < 3; ++i) {
    sky::weather::CloudLayer l;
    l.id = i + 1;
    l.type = types[i];
    l.base_m = 600 + 4000.0 * i;  // layer 1 below kMarkerBase: the first marker is change 0
    l.thickness_m = 800;
    l.coverage = 0.5;
    l.density = 0.8;
    l.wind = {10.0 + 10 * i, 250, 0};
    layers.push_back(l);
  }
  return layers;
}

}  // namespace

int main(int argc, char** argv) {
  Options o;
  const char* usage = "usage: sky_weatherd_bench [--subscribers N] [--rate HZ] [--seconds S] [--idle-seconds S] "
                      "[--radius-m M] [--regional 0|1] [--storms 0|1] [--channels N] [--json FILE]\n";
  if (argc == 2 && std::string(argv[1]) == "--help") {
    std::printf("%s", usage);
    return 0;
  }
  for (int i = 1; i + 1 < argc; i += 2) {
    const std::string k = argv[i], v = argv[i + 1];
    if (k == "--subscribers") o.subscribers = std::stoi(v);
    else if (k == "--rate") o.rate = std::stod(v);
    else if (k == "--seconds") o.seconds = std::stod(v);
    else if (k == "--idle-seconds") o.idleSeconds = std::stod(v);
    else if (k == "--radius-m") o.radius_m = std::stod(v);
    else if (k == "--json") o.json = v;
    else if (k == "--regional") o.regional = v == "1";
    else if (k == "--storms") o.storms = v == "1";
    else if (k == "--channels") o.channels = std::stoi(v);
    else {
      std::fprintf(stderr, "unknown option %s\n", k.c_str());
      return 2;
    }
  }
  if (argc % 2 == 0 || o.subscribers < 1 || o.channels < 1) {
    std::fprintf(stderr, "%s", usage);
    return 2;
  }
  auto layers = threeLayers();
  if (o.storms) layers[0].type = sky::weather::CloudType::Cumulonimbus;

  // Sizes, without sockets: a 300 km wide area (150 km radius) at ~1 km
  // tiles, 3 layers all varying (a region 200 km across changes each), so
  // every layer carries tiles; and the Delta one layer's coverage change
  // costs a renderer's subscription (what the server sends, see Session),
  // with uniform weather (a layer in the table) and with that region in its
  // area (that layer's tiles that change, outside the region's core).
  sky::weather::Region region;
  region.id = 1;
  region.centerLat_deg = 46.0;
  region.centerLon_deg = 13.0;
  region.sizeX_m = region.sizeY_m = 200000;
  region.transition_m = 20000;
  for (auto l : layers) {
    l.coverage = 0.9;
    region.layers.push_back(l);
  }
  const std::vector<sky::weather::Region> regions = {region};
  auto frameBytes = [](const sky::weather::WeatherSnapshot& s) {
    return sky::stream::encodeFrame(sky::stream::encodeMessage(s)).size();
  };
  sky::stream::Subscribe wide;
  wide.area = {46.0, 13.0, 150000};
  wide.tileLevel = 13;
  const auto wideSnapshot = sky::server::buildSnapshot(wide, layers, 0, sky::server::kDefaultMaxCells, regions);
  const std::size_t wideBytes = frameBytes(wideSnapshot);
  sky::stream::Subscribe renderer;
  renderer.area = {46.0, 13.0, o.radius_m};
  renderer.tileLevel = sky::weather::levelForRadius(o.radius_m, o.maxTiles);
  auto changed = layers;
  changed[1].coverage = 0.6;
  auto deltaBytes = [&](std::span<const sky::weather::Region> rs, sky::weather::WeatherSnapshot& before,
                        std::size_t& tiles) -> std::size_t {
    before = sky::server::buildSnapshot(renderer, layers, 0, sky::server::kDefaultMaxCells, rs);
    const auto after = sky::server::buildSnapshot(renderer, changed, 0, sky::server::kDefaultMaxCells, rs);
    const auto delta = sky::weather::diffSnapshots(before, after);
    if (!delta) return 0;
    tiles = delta->tiles.size();
    return sky::stream::encodeFrame(sky::stream::encodeMessage(*delta)).size();
  };
  sky::weather::WeatherSnapshot uniformSnapshot, regionalSnapshot;
  std::size_t uniformDeltaTiles = 0, regionalDeltaTiles = 0;
  const std::size_t changeBytes = deltaBytes({}, uniformSnapshot, uniformDeltaTiles);
  const std::size_t regionalChangeBytes = deltaBytes(regions, regionalSnapshot, regionalDeltaTiles);
  const std::size_t regionalSnapshotBytes = frameBytes(regionalSnapshot);

  sky::server::Scenario scenario;
  scenario.layers = layers;
  sky::server::ServerOptions options;
  options.handleSignals = false;
  options.heartbeatInterval = 1000ms;
  // Room for every subscriber: past the default cap (64) the server refuses
  // connections, and a refused subscriber measures nothing.
  options.maxSubscribers = std::max<std::size_t>(options.maxSubscribers, static_cast<std::size_t>(o.subscribers));
  auto created = sky::server::Server::create(options, sky::server::WeatherState(scenario, Clock::now()));
  if (!created) {
    std::fprintf(stderr, "server: %s\n", created.error().detail.c_str());
    return 1;
  }
  std::unique_ptr<sky::server::Server> server = std::move(*created);
  if (o.regional) {
    // A region 800 km across over every subscriber's area: every snapshot
    // carries tiles for all 3 layers; the storm is a cell moving inside it.
    sky::weather::Region everywhere = region;
    everywhere.sizeX_m = everywhere.sizeY_m = 800000;
    auto ok = server->weather().submit({{sky::server::SetRegion{everywhere, {}}}, "bench", "api"});
    if (!ok) {
      std::fprintf(stderr, "region: %s\n", ok.error().detail.c_str());
      return 1;
    }
  }
  std::thread serverThread([&] { server->run(); });

  Shared shared;
  const std::size_t changes = static_cast<std::size_t>(o.rate * o.seconds);
  shared.submitted.resize(changes);
  asio::io_context clientIo;
  auto guard = asio::make_work_guard(clientIo);
  std::vector<std::shared_ptr<Subscriber>> subs;
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> jitter(-2.0, 2.0);
  sky::stream::Subscribe area = renderer;
  for (int i = 0; i < o.subscribers; ++i) {
    auto s = std::make_shared<Subscriber>(clientIo, shared);
    if (i % o.channels == 0) {
      area.area.centerLat_deg = 46.0 + jitter(rng);
      area.area.centerLon_deg = 13.0 + jitter(rng);
    }
    s->start(server->port(), area);
    subs.push_back(s);
  }
  std::thread clientThread([&] { clientIo.run(); });
  const auto waitStart = Clock::now();
  while (Clock::now() - waitStart < 30s &&
         !std::all_of(subs.begin(), subs.end(), [](const auto& s) { return s->ready(); }))
    std::this_thread::sleep_for(10ms);
  const auto served = std::count_if(subs.begin(), subs.end(), [](const auto& s) { return s->ready(); });

  // Idle: heartbeats only.
  const pthread_t st = serverThread.native_handle();
  double cpu0 = threadCpu_s(st);
  std::this_thread::sleep_for(std::chrono::duration<double>(o.idleSeconds));
  const double idlePct = 100.0 * (threadCpu_s(st) - cpu0) / o.idleSeconds;
  const auto bytes0 = server->streamCounters().bytes.load();
  const auto frames0 = server->streamCounters().frames.load();

  // The storm: one change every 1/rate s, each moving layer 1's base (the
  // marker) and its coverage.
  cpu0 = threadCpu_s(st);
  const auto stormStart = Clock::now();
  for (std::size_t i = 0; i < changes; ++i) {
    std::this_thread::sleep_until(stormStart + std::chrono::duration_cast<Clock::duration>(
                                                   std::chrono::duration<double>(double(i) / o.rate)));
    asio::post(server->io(), [&, i] {
      {
        std::lock_guard lock(shared.mutex);
        shared.submitted[i] = Clock::now();
      }
      sky::server::WeatherChange change;
      if (!o.regional) {
        auto layer = layers[0];
        layer.base_m = kMarkerBase + double(i);
        layer.coverage = 0.2 + 0.6 * double(i % 10) / 10;
        change = sky::server::SetLayer{layer, {}};
      } else {
        // A storm cell 60 km across moving east 300 m per change: the tiles
        // about its edge change for the subscribers near it; its layer
        // (in every snapshot's table) carries the marker.
        sky::weather::Region storm;
        storm.id = 9;
        storm.centerLat_deg = 46.0;
        storm.centerLon_deg = 12.0 + 0.004 * double(i);
        storm.sizeX_m = storm.sizeY_m = 60000;
        storm.cornerRadius_m = 30000;
        storm.transition_m = 5000;
        auto cell = layers[0];
        cell.id = 9;
        cell.type = sky::weather::CloudType::Cumulonimbus;
        cell.base_m = kMarkerBase + double(i);
        cell.thickness_m = 8000;
        cell.coverage = 0.9;
        storm.layers = {cell};
        change = sky::server::SetRegion{storm, {}};
      }
      // Accepted, it reaches every subscriber through the server's listener.
      (void)server->weather().submit({{change}, "bench", "api"});
    });
  }
  std::this_thread::sleep_for(1s);  // let the last deliveries land
  const double stormWall_s = std::chrono::duration<double>(Clock::now() - stormStart).count();
  const double stormPct = 100.0 * (threadCpu_s(st) - cpu0) / stormWall_s;
  const auto bytes = server->streamCounters().bytes.load() - bytes0;
  const auto frames = server->streamCounters().frames.load() - frames0;

  for (auto& s : subs) asio::post(clientIo, [s] { s->close(); });
  guard.reset();
  clientThread.join();
  server->stop();
  serverThread.join();

  std::lock_guard lock(shared.mutex);
  const double p50 = percentile(shared.latencies_ms, 50), p99 = percentile(shared.latencies_ms, 99);
  const double expected = double(changes) * o.subscribers;
  std::printf("weatherd bench: %d subscribers (%lld served a snapshot; %d per area; radius %.0f km, level %d), %zu "
              "changes at %.0f/s, %s weather\n",
              o.subscribers, static_cast<long long>(served), o.channels, o.radius_m / 1000, renderer.tileLevel, changes, o.rate,
              o.regional ? "regional (tiles in every snapshot; a storm cell moves)" : "uniform (layer tables only)");
  if (o.storms)
    std::printf("  lightning                   flashes drawn %llu (layer 1 cumulonimbus over every area)\n",
                static_cast<unsigned long long>(server->streamCounters().flashesDrawn.load()));
  std::printf("  change-to-delivery latency  p50 %.2f ms  p99 %.2f ms  (%llu deliveries, %llu coalesced of %.0f)\n",
              p50, p99, static_cast<unsigned long long>(shared.deliveries),
              static_cast<unsigned long long>(shared.coalesced), expected);
  std::printf("  server CPU                  idle %.2f %% of a core, storm %.1f %%\n", idlePct, stormPct);
  std::printf("  storm traffic               %llu frames, %.1f MB\n", static_cast<unsigned long long>(frames),
              double(bytes) / 1e6);
  std::printf("  snapshot 300 km wide, 3 varying layers: %zu bytes (level %d, %zu tiles)\n", wideBytes,
              wideSnapshot.tileLevel, wideSnapshot.tiles.size());
  std::printf("  one layer's coverage change, per subscriber: Delta %zu bytes with uniform weather (layer "
              "table), Delta %zu bytes (%zu tiles) with a region in its area (its snapshot: %zu bytes, level %d, "
              "%zu tiles)\n",
              changeBytes, regionalChangeBytes, regionalDeltaTiles, regionalSnapshotBytes, regionalSnapshot.tileLevel,
              regionalSnapshot.tiles.size());
  if (!o.json.empty()) {
    const nlohmann::json j = {{"subscribers", o.subscribers}, {"served", served}, {"channels", o.channels}, {"rate_hz", o.rate}, {"regional", o.regional},
                              {"storms", o.storms}, {"changes", changes},
                              {"latency_p50_ms", p50}, {"latency_p99_ms", p99}, {"deliveries", shared.deliveries},
                              {"coalesced", shared.coalesced}, {"cpu_idle_pct", idlePct}, {"cpu_storm_pct", stormPct},
                              {"frames", frames}, {"bytes", bytes}, {"snapshot_300km_3layers_bytes", wideBytes},
                              {"change_delta_bytes_uniform", changeBytes}, {"change_delta_bytes_regional", regionalChangeBytes},
                              {"regional_snapshot_bytes", regionalSnapshotBytes}};
    std::ofstream(o.json) << j.dump(2) << "\n";
  }
  // Every subscriber must have received the weather at all.
  return shared.deliveries > 0 && served == o.subscribers ? 0 : 1;
}
