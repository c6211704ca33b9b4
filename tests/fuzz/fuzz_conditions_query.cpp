// libFuzzer target: query strings of the weather server's GET
// /api/conditions. The parser may refuse (naming the key), never crash, hang
// or read out of bounds; what it accepts is in range.
// Seeds: tests/fuzz/corpus/conditions_query/.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <string_view>

#include "sky/server/conditions_api.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view query(reinterpret_cast<const char*>(data), size);
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
