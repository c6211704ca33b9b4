// libFuzzer target: FlightGear's native FDM decoder on arbitrary datagrams;
// whatever decodes must re-encode to the same 408 bytes' values.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <cstring>

#include "sky/fgfdm/net_fdm.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  auto f = sky::fgfdm::decodeNetFdm(std::span(data, size));
  if (!f) return 0;
  const auto again = sky::fgfdm::encodeNetFdm(*f);
  // NaN payloads may differ bit-wise only where the input had NaN; compare
  // the decoded structs' position fields, which the decoder checked finite.
  auto g = sky::fgfdm::decodeNetFdm(again);
  if (!g || g->lat_rad != f->lat_rad || g->lon_rad != f->lon_rad || g->alt_m != f->alt_m) std::abort();
  // What decodes is what a renderer may use (issue 18): the velocities and
  // the time it could read are finite and bounded.
  for (const float v : {f->vNorth_fps, f->vEast_fps, f->vDown_fps, f->climbRate_fps, f->phidot_rps, f->psidot_rps})
    if (!std::isfinite(v) || std::abs(v) > 40000.0f) std::abort();
  return 0;
}
