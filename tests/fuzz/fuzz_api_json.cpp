// libFuzzer target: bodies of the weather server's POST /api/changes and
// POST /api/events (a flash). The parsers may refuse (naming a JSON path),
// never crash, hang or read out of bounds; what they accept has 0..n
// changes whose layers' ids fit 16 bits, or a flash in range.
// Seeds: tests/fuzz/corpus/api_json/.
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <string_view>

#include "sky/server/api_json.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view body(reinterpret_cast<const char*>(data), size);
  if (const auto f = sky::server::parseFlashRequest(body)) {
    if (!(f->lat_deg >= -90 && f->lat_deg <= 90 && f->lon_deg >= -180 && f->lon_deg <= 180 && f->energy_j > 0))
      std::abort();
  } else if (f.error().detail.empty()) {
    std::abort();
  }
  const auto r = sky::server::parseChangeRequest(body);
  if (!r) {
    if (r.error().detail.empty()) std::abort();
    return 0;
  }
  for (const auto& c : r->changes) {
    if (const auto* set = std::get_if<sky::server::SetLayer>(&c))
      if (set->layer.id > 65535) std::abort();
  }
  return 0;
}
