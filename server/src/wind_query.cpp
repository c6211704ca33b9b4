// GET /api/wind's query string (see wind_api.hpp): pure, so the fuzz target
// builds it without the server.
#include "query_number.hpp"
#include "sky/server/wind_api.hpp"

namespace sky::server {

Result<WindQuery> parseWindQuery(std::string_view query) {
  WindQuery q;
  bool lat = false, lon = false, alt = false, radius = false;
  const NumberKey keys[] = {{"lat_deg", &lat, &q.lat_deg, -90, 90},
                            {"lon_deg", &lon, &q.lon_deg, -180, 180},
                            {"alt_m", &alt, &q.alt_m, -1000, 20000},
                            {"radius_m", &radius, &q.radius_m, 1000, 2e6}};
  const auto pairs = parseNumberKeys(query, keys, "lat_deg, lon_deg, alt_m, radius_m");
  if (!pairs) return tl::unexpected(pairs.error());
  if (!lat) return fail(ErrorCode::InvalidArgument, "lat_deg: missing");
  if (!lon) return fail(ErrorCode::InvalidArgument, "lon_deg: missing");
  if (!alt) return fail(ErrorCode::InvalidArgument, "alt_m: missing");
  return q;
}

}  // namespace sky::server
