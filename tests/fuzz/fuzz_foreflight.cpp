// libFuzzer target: the ForeFlight UDP text decoder (X-Plane's and
// FlightGear's XGPS/XATT lines) on arbitrary datagrams. What decodes is what
// the renderer's pose source may use: every number finite and in its
// documented range, and a position written back out parses again.
// Seeds: tests/fuzz/corpus/foreflight/.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdlib>

#include "sky/foreflight/foreflight.hpp"

namespace {
void require(bool ok) {
  if (!ok) std::abort();
}
bool within(double v, double lo, double hi) { return std::isfinite(v) && v >= lo && v <= hi; }
}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace sky::foreflight;
  const auto messages = parseDatagram(std::span(data, size));
  if (!messages) return 0;
  require(!messages->empty() && messages->size() <= kMaxLinesPerDatagram);
  for (const auto& m : *messages) {
    if (const auto* p = std::get_if<Position>(&m)) {
      require(within(p->lat_deg, -90, 90) && within(p->lon_deg, -180, 180) && within(p->alt_m, -1000, 30000) &&
              within(p->track_deg, 0, 360) && within(p->groundSpeed_mps, 0, 1000));
      require(p->sim.size() <= 64);
      require(parseLine(formatLine(*p)).has_value());
    } else if (const auto* a = std::get_if<Attitude>(&m)) {
      require(within(a->heading_deg, 0, 360) && within(a->pitch_deg, -90, 90) && within(a->roll_deg, -180, 180));
      require(parseLine(formatLine(*a)).has_value());
    }
  }
  return 0;
}
