// GET /api/wind's query string (see wind_api.hpp): pure, so the fuzz target
// builds it without the server.
#include "query_number.hpp"
#include "sky/server/wind_api.hpp"

namespace sky::server {

Result<WindQuery> parseWindQuery(std::string_view query) {
  WindQuery q;
  bool lat = false, lon = false, alt = false, radius = false;
  if (query.size() > 512) return fail(ErrorCode::InvalidArgument, "query: longer than 512 bytes");
  while (!query.empty()) {
    const std::size_t amp = query.find('&');
    const std::string_view pair = query.substr(0, amp);
    query = amp == std::string_view::npos ? std::string_view{} : query.substr(amp + 1);
    const std::size_t eq = pair.find('=');
    if (eq == std::string_view::npos) return fail(ErrorCode::Malformed, "query: '" + std::string(pair) + "' is not key=value");
    const std::string_view key = pair.substr(0, eq), value = pair.substr(eq + 1);
    struct Key {
      std::string_view name;
      bool* seen;
      double* out;
      double lo, hi;
    };
    const Key keys[] = {{"lat_deg", &lat, &q.lat_deg, -90, 90},
                        {"lon_deg", &lon, &q.lon_deg, -180, 180},
                        {"alt_m", &alt, &q.alt_m, -1000, 20000},
                        {"radius_m", &radius, &q.radius_m, 1000, 2e6}};
    const Key* k = nullptr;
    for (const Key& c : keys)
      if (c.name == key) k = &c;
    if (!k)
      return fail(ErrorCode::InvalidArgument,
                  "query: unknown key '" + std::string(key) + "' (lat_deg, lon_deg, alt_m, radius_m)");
    if (*k->seen) return fail(ErrorCode::InvalidArgument, std::string(key) + ": given twice");
    *k->seen = true;
    const auto v = queryNumber(key, value, k->lo, k->hi);
    if (!v) return tl::unexpected(v.error());
    *k->out = *v;
  }
  if (!lat) return fail(ErrorCode::InvalidArgument, "lat_deg: missing");
  if (!lon) return fail(ErrorCode::InvalidArgument, "lon_deg: missing");
  if (!alt) return fail(ErrorCode::InvalidArgument, "alt_m: missing");
  return q;
}

}  // namespace sky::server
