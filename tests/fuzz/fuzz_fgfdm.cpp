// libFuzzer target: FlightGear's native FDM decoder on arbitrary datagrams;
// whatever decodes must re-encode to the same 408 bytes' values.
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
  return 0;
}
