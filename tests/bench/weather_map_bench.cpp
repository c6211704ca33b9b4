// The weather map's CPU cost per new snapshot (renderer/core/src/
// weather_field*.cpp): a full build at a new anchor (finding every texel's
// cell: geodesy), a rebuild at the same anchor (cells reused), and a
// per-tile update of 1 and of 100 changed tiles (with the max-coverage mip
// updated over them); and the whole mip, which a rebuilt map needs. Snapshots as a renderer
// holds them: fine level 11 (~4.9 km) over 120 km, coarse level 9 (~20 km)
// over 650 km, two tiled layers and a uniform one.
// Run: build/rel/tests/bench/sky_weather_map_bench (numbers are for this
// machine; compare runs made in one session).
#include <benchmark/benchmark.h>

#include "coverage_mip.hpp"
#include "sky/weather/tiling.hpp"
#include "weather_field.hpp"
#include "weather_field_update.hpp"

namespace {

using namespace sky;
using render::WeatherFieldUpdater;

const geo::Geodetic kCamera{47.0, 8.0, 3000.0};

weather::WeatherSnapshot snapshot(double radius_m, int level) {
  weather::WeatherSnapshot s;
  s.tileLevel = level;
  for (std::uint32_t id : {1u, 2u, 3u}) {
    weather::CloudLayer l;
    l.id = id;
    l.base_m = 1000.0 * id;
    l.thickness_m = 800;
    l.coverage = id == 3 ? 0.4 : 0.0;
    s.layers.push_back(l);
  }
  std::uint32_t n = 0;
  for (std::uint64_t cell : weather::coverCap({kCamera.lat_deg, kCamera.lon_deg, radius_m}, level, 8000))
    for (std::uint32_t id : {1u, 2u}) s.tiles.push_back({cell, id, float(++n % 17) / 16.0f, 1.0f});
  return s;
}

struct Weather {
  weather::WeatherSnapshot fine = snapshot(120000.0, 11);
  weather::WeatherSnapshot coarse = snapshot(650000.0, 9);
};

void BM_FullBuildNewAnchor(benchmark::State& state) {
  Weather w;
  const geo::Geodetic anchors[2] = {render::weatherAnchorFor(kCamera),
                                    render::weatherAnchorFor({kCamera.lat_deg + 0.2, kCamera.lon_deg, 3000.0})};
  WeatherFieldUpdater updater;
  std::size_t i = 0;
  for (auto _ : state) benchmark::DoNotOptimize(updater.update(&w.fine, &w.coarse, anchors[++i % 2]));
  state.counters["tiles"] = double(w.fine.tiles.size() + w.coarse.tiles.size());
}

void BM_RebuildSameAnchor(benchmark::State& state) {
  Weather w;
  const geo::Geodetic anchor = render::weatherAnchorFor(kCamera);
  WeatherFieldUpdater updater;
  updater.update(&w.fine, &w.coarse, anchor);
  std::size_t i = 0;
  for (auto _ : state) {
    w.fine.layers[2].coverage = ++i % 2 ? 0.5 : 0.4;  // a layer's coverage: more than tiles
    benchmark::DoNotOptimize(updater.update(&w.fine, &w.coarse, anchor));
  }
}

// state.range(0) tiles of the fine snapshot (spread over it) change value;
// with the max-coverage mip updated over the changed rectangles, as the
// renderer does.
void BM_TileUpdate(benchmark::State& state) {
  Weather w;
  const geo::Geodetic anchor = render::weatherAnchorFor(kCamera);
  WeatherFieldUpdater updater;
  updater.update(&w.fine, &w.coarse, anchor);
  std::vector<float> mip = render::buildCoverageMip(updater.field());
  const std::size_t k = std::size_t(state.range(0));
  const std::size_t stride = w.fine.tiles.size() / k;
  std::uint64_t texels = 0;
  std::size_t i = 0;
  for (auto _ : state) {
    const float v = ++i % 2 ? 0.25f : 0.75f;
    for (std::size_t t = 0; t < k; ++t) w.fine.tiles[t * stride].coverage = v;
    const auto change = updater.update(&w.fine, &w.coarse, anchor);
    if (change.kind != render::WeatherFieldChange::Kind::Tiles) state.SkipWithError("not a tile update");
    render::updateCoverageMip(mip, updater.field(), change.dirty);
    texels += change.texelsRewritten;
  }
  state.counters["texels"] = benchmark::Counter(double(texels), benchmark::Counter::kAvgIterations);
}

void BM_CoverageMip(benchmark::State& state) {
  Weather w;
  WeatherFieldUpdater updater;
  updater.update(&w.fine, &w.coarse, render::weatherAnchorFor(kCamera));
  for (auto _ : state) benchmark::DoNotOptimize(render::buildCoverageMip(updater.field()));
}

// The two parts of a per-tile update that grow with the snapshots' tiles
// rather than with the changed texels: the content key and sorting the
// tiles into rings and slices.
void BM_ContentKey(benchmark::State& state) {
  Weather w;
  for (auto _ : state) benchmark::DoNotOptimize(render::weatherContentKey(&w.fine, &w.coarse));
}

void BM_IndexTiles(benchmark::State& state) {
  Weather w;
  for (auto _ : state) benchmark::DoNotOptimize(render::indexWeatherTiles(&w.fine, &w.coarse));
}

BENCHMARK(BM_FullBuildNewAnchor)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_RebuildSameAnchor)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_TileUpdate)->Arg(1)->Arg(100)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_CoverageMip)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_ContentKey)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_IndexTiles)->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
