// libFuzzer target: query strings of the weather server's GET
// /api/conditions, GET /api/wind and GET /api/radar. The parsers may refuse (naming the key),
// never crash, hang or read out of bounds; what they accept is in range.
// Seeds: tests/fuzz/corpus/conditions_query/.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <string_view>

#include "sky/server/conditions_api.hpp"
#include "sky/server/radar_api.hpp"
#include "sky/server/wind_api.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view query(reinterpret_cast<const char*>(data), size);
  if (const auto w = sky::server::parseWindQuery(query)) {
    if (!(std::abs(w->lat_deg) <= 90) || !(std::abs(w->lon_deg) <= 180) || !(w->alt_m >= -1000 && w->alt_m <= 20000) ||
        !(w->radius_m >= 1000 && w->radius_m <= 2e6))
      std::abort();
  } else if (w.error().detail.empty()) {
    std::abort();
  }
  if (const auto r = sky::server::parseRadarQuery(query)) {
    if (!(std::abs(r->lat_deg) <= 90) || !(std::abs(r->lon_deg) <= 180) || !(r->range_km > 0 && r->range_km <= 300) ||
        !(r->tilt_deg >= -2 && r->tilt_deg <= 30) || !(r->alt_m >= -500 && r->alt_m <= 10000) || r->size < 16 ||
        r->size > sky::server::kMaxRadarSize)
      std::abort();
  } else if (r.error().detail.empty()) {
    std::abort();
  }
  const auto q = sky::server::parseConditionsQuery(query);
  if (!q) {
    if (q.error().detail.empty()) std::abort();
    return 0;
  }
  if (!(std::abs(q->lat_deg) <= 90) || !(std::abs(q->lon_deg) <= 180) || !(q->alt_m >= -1000 && q->alt_m <= 100000) ||
      q->level < 0 || q->level > sky::server::kMaxConditionsLevel)
    std::abort();
  return 0;
}
