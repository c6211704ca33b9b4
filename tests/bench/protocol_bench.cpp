// Protocol throughput: CIGI datagram decode (datagrams/s) and weather-stream
// Snapshot decode with FlatBuffers verification and range checks (MB/s).
// Run: build/test/tests/bench/sky_protocol_bench (numbers are for this machine;
// compare runs made in one session).
#include <benchmark/benchmark.h>

#include "sky/cigi/codec.hpp"
#include "sky/stream/framing.hpp"
#include "sky/stream/messages.hpp"
#include "sky/weather/tiling.hpp"

namespace {

using namespace sky;

std::vector<std::uint8_t> hostDatagram(bool withWeather) {
  cigi::DatagramWriter w;
  cigi::IgControl ig;
  ig.hostFrame = 1234;
  cigi::EntityControl e;
  e.lat_deg = 47.46;
  e.lon_deg = 8.55;
  e.alt_m = 1200;
  e.yaw_deg = 270;
  w.add(ig).add(e);
  if (withWeather) {
    cigi::WeatherControl wc;
    wc.cloudType = weather::CloudType::Cumulus;
    wc.coverage_pct = 60;
    wc.baseElevation_m = 1500;
    wc.thickness_m = 1500;
    w.add(wc);
  }
  return w.bytes();
}

void BM_CigiDecodeOwnship(benchmark::State& state) {
  const auto bytes = hostDatagram(false);
  for (auto _ : state) benchmark::DoNotOptimize(cigi::decodeDatagram(bytes));
  state.SetItemsProcessed(state.iterations());
  state.SetBytesProcessed(state.iterations() * static_cast<std::int64_t>(bytes.size()));
}
BENCHMARK(BM_CigiDecodeOwnship);

void BM_CigiDecodeWithWeather(benchmark::State& state) {
  const auto bytes = hostDatagram(true);
  for (auto _ : state) benchmark::DoNotOptimize(cigi::decodeDatagram(bytes));
  state.SetItemsProcessed(state.iterations());
  state.SetBytesProcessed(state.iterations() * static_cast<std::int64_t>(bytes.size()));
}
BENCHMARK(BM_CigiDecodeWithWeather);

void BM_CigiEncodeOwnship(benchmark::State& state) {
  for (auto _ : state) benchmark::DoNotOptimize(hostDatagram(false));
  state.SetItemsProcessed(state.iterations());
}
BENCHMARK(BM_CigiEncodeOwnship);

// A snapshot like the renderer's subscription: one layer over ~100 km in S2
// level-11 cells, or as many tiles as the argument asks for.
std::vector<std::uint8_t> snapshotPayload(std::size_t tiles) {
  weather::WeatherSnapshot s;
  s.tileLevel = 13;
  weather::CloudLayer l;
  l.id = 1;
  l.base_m = 1500;
  l.thickness_m = 1500;
  l.coverage = 0.6;
  s.layers.push_back(l);
  const auto cells = weather::coverCap({46.2, 12.8, 200000}, s.tileLevel, tiles);
  for (std::size_t i = 0; i < cells.size() && i < tiles; ++i)
    s.tiles.push_back({cells[i], 1, static_cast<float>(i % 256) / 255.0f, 1.0f});
  return stream::encodeMessage(s);
}

void BM_SnapshotDecodeVerify(benchmark::State& state) {
  const auto payload = snapshotPayload(static_cast<std::size_t>(state.range(0)));
  for (auto _ : state) {
    auto m = stream::decodeMessage(payload);
    if (!m) state.SkipWithError(m.error().detail.c_str());
    benchmark::DoNotOptimize(m);
  }
  state.SetBytesProcessed(state.iterations() * static_cast<std::int64_t>(payload.size()));
  state.counters["tiles"] = static_cast<double>(state.range(0));
}
BENCHMARK(BM_SnapshotDecodeVerify)->Arg(1000)->Arg(20000);

void BM_FrameReassembly(benchmark::State& state) {
  const auto frame = stream::encodeFrame(snapshotPayload(20000));
  for (auto _ : state) {
    stream::FrameDecoder d;
    // Arrives in 16 KiB reads, as the renderer's socket reads it.
    for (std::size_t off = 0; off < frame.size(); off += 16384)
      d.append(std::span(frame).subspan(off, std::min<std::size_t>(16384, frame.size() - off)));
    benchmark::DoNotOptimize(d.next());
  }
  state.SetBytesProcessed(state.iterations() * static_cast<std::int64_t>(frame.size()));
}
BENCHMARK(BM_FrameReassembly);

}  // namespace

BENCHMARK_MAIN();
