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
  bool lat = false, lon = false, alt = false, level = false;
  // Bounded: a query of more than a few keys is not one of ours.
  if (query.size() > 512) return fail(ErrorCode::InvalidArgument, "query: longer than 512 bytes");
  while (!query.empty()) {
    const std::size_t amp = query.find('&');
    const std::string_view pair = query.substr(0, amp);
    query = amp == std::string_view::npos ? std::string_view{} : query.substr(amp + 1);
    const std::size_t eq = pair.find('=');
    if (eq == std::string_view::npos)
      return fail(ErrorCode::Malformed, "query: '" + std::string(pair) + "' is not key=value");
    const std::string_view key = pair.substr(0, eq), value = pair.substr(eq + 1);
    auto once = [&](bool& seen) -> Result<void> {
      if (seen) return fail(ErrorCode::InvalidArgument, std::string(key) + ": given twice");
      seen = true;
      return {};
    };
    Result<double> v = 0.0;
    if (key == "lat_deg") {
      if (auto r = once(lat); !r) return tl::unexpected(r.error());
      if (!(v = queryNumber(key, value, -90, 90))) return tl::unexpected(v.error());
      q.lat_deg = *v;
    } else if (key == "lon_deg") {
      if (auto r = once(lon); !r) return tl::unexpected(r.error());
      if (!(v = queryNumber(key, value, -180, 180))) return tl::unexpected(v.error());
      q.lon_deg = *v;
    } else if (key == "alt_m") {
      if (auto r = once(alt); !r) return tl::unexpected(r.error());
      if (!(v = queryNumber(key, value, -1000, 100000))) return tl::unexpected(v.error());
      q.alt_m = *v;
    } else if (key == "level") {
      if (auto r = once(level); !r) return tl::unexpected(r.error());
      if (!(v = queryNumber(key, value, 0, kMaxConditionsLevel))) return tl::unexpected(v.error());
      if (*v != std::floor(*v)) return fail(ErrorCode::InvalidArgument, "level: '" + std::string(value) + "' is not an integer");
      q.level = static_cast<int>(*v);
    } else {
      return fail(ErrorCode::InvalidArgument,
                  "query: unknown key '" + std::string(key) + "' (lat_deg, lon_deg, alt_m, level)");
    }
  }
  if (!lat) return fail(ErrorCode::InvalidArgument, "lat_deg: missing");
  if (!lon) return fail(ErrorCode::InvalidArgument, "lon_deg: missing");
  if (!alt) return fail(ErrorCode::InvalidArgument, "alt_m: missing");
  return q;
}

}  // namespace sky::server
