// libFuzzer target: the METAR decoder on arbitrary bytes, and the mapping of
// every report it accepts at a fixed station. Neither may crash, hang or read
// out of bounds; the notes of skipped and joined groups stay within their
// bounds; every layer the mapping returns passes weather::validate and ids
// run 1..n; a sky not observed has no layers. Seeds: tests/fuzz/corpus/metar/.
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <string_view>

#include "sky/server/metar.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  const auto report = sky::server::parseMetar(text);
  if (!report) return 0;
  if (report->skipped.size() > sky::server::kMaxNotedGroups || report->joined.size() > sky::server::kMaxNotedGroups ||
      report->skippedCount < report->skipped.size())
    std::abort();
  for (const auto& n : report->skipped)
    if (n.text.size() > sky::server::kMaxNotedGroupBytes || n.position == 0 || n.reason.empty()) std::abort();
  // The station takes the report's ICAO so that the mapping runs in full.
  const sky::server::Station station{report->icao, 46.2, 12.8, 420.0};
  const auto sky = sky::server::skyFromMetar(*report, station);
  if (!sky) return 0;
  if (!sky->observed && !sky->layers.empty()) std::abort();
  const auto* layers = &sky->layers;
  for (std::size_t i = 0; i < layers->size(); ++i) {
    const auto& layer = (*layers)[i];
    if (layer.id != i + 1) std::abort();
    if (!sky::weather::validate(layer)) std::abort();
  }
  return 0;
}
