// The query string of GET /api/conditions (see conditions_api.hpp). Pure:
// fuzzed by tests/fuzz/fuzz_conditions_query.cpp.
#include <charconv>
#include <cmath>
#include <string>

#include "query_number.hpp"
#include "sky/server/conditions_api.hpp"

namespace sky::server {


Result<ConditionsQuery> parseConditionsQuery(std::string_view query) {
  ConditionsQuery q;
  bool lat = false, lon = false, alt = false;
  const auto pairs = forEachQueryPair(query, [&](std::string_view key, std::string_view value) -> Result<void> {
    Result<double> v = 0.0;
    if (key == "lat_deg") {
      if (!(v = queryNumber(key, value, -90, 90))) return tl::unexpected(v.error());
      q.lat_deg = *v;
      lat = true;
    } else if (key == "lon_deg") {
      if (!(v = queryNumber(key, value, -180, 180))) return tl::unexpected(v.error());
      q.lon_deg = *v;
      lon = true;
    } else if (key == "alt_m") {
      if (!(v = queryNumber(key, value, -1000, 100000))) return tl::unexpected(v.error());
      q.alt_m = *v;
      alt = true;
    } else if (key == "level") {
      if (!(v = queryNumber(key, value, 0, kMaxConditionsLevel))) return tl::unexpected(v.error());
      if (*v != std::floor(*v)) return fail(ErrorCode::InvalidArgument, "level: '" + std::string(value) + "' is not an integer");
      q.level = static_cast<int>(*v);
    } else {
      return fail(ErrorCode::InvalidArgument,
                  "query: unknown key '" + std::string(key) + "' (lat_deg, lon_deg, alt_m, level)");
    }
    return {};
  });
  if (!pairs) return tl::unexpected(pairs.error());
  if (!lat) return fail(ErrorCode::InvalidArgument, "lat_deg: missing");
  if (!lon) return fail(ErrorCode::InvalidArgument, "lon_deg: missing");
  if (!alt) return fail(ErrorCode::InvalidArgument, "alt_m: missing");
  return q;
}

}  // namespace sky::server
