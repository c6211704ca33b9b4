// libFuzzer target: the METAR decoder on arbitrary bytes, and the mapping of
// every report it accepts at a fixed station. Neither may crash, hang or read
// out of bounds; every layer the mapping returns passes weather::validate and
// ids run 1..n. Seeds: tests/fuzz/corpus/metar/.
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <string_view>

#include "sky/server/metar.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  const auto report = sky::server::parseMetar(text);
  if (!report) return 0;
  // The station takes the report's ICAO so that the mapping runs in full.
  const sky::server::Station station{report->icao, 46.2, 12.8, 420.0};
  const auto layers = sky::server::layersFromMetar(*report, station);
  if (!layers) return 0;
  for (std::size_t i = 0; i < layers->size(); ++i) {
    const auto& layer = (*layers)[i];
    if (layer.id != i + 1) std::abort();
    if (!sky::weather::validate(layer)) std::abort();
  }
  return 0;
}
