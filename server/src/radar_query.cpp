// GET /api/radar's query string (see radar_api.hpp): pure,
// so the fuzz target builds it without the server.
#include <cmath>

#include "query_number.hpp"
#include "sky/server/radar_api.hpp"

namespace sky::server {

Result<RadarQuery> parseRadarQuery(std::string_view query) {
  RadarQuery q;
  bool lat = false, lon = false, range = false, tilt = false, alt = false, size = false;
  double sizeValue = q.size;
  const NumberKey keys[] = {{"lat", &lat, &q.lat_deg, -90, 90},         {"lat_deg", &lat, &q.lat_deg, -90, 90},
                            {"lon", &lon, &q.lon_deg, -180, 180},       {"lon_deg", &lon, &q.lon_deg, -180, 180},
                            {"range_km", &range, &q.range_km, 0, 300},  {"tilt_deg", &tilt, &q.tilt_deg, -2, 30},
                            {"alt_m", &alt, &q.alt_m, -500, 10000},     {"size", &size, &sizeValue, 16, kMaxRadarSize}};
  const auto pairs = parseNumberKeys(query, keys, "lat, lon, range_km, tilt_deg, alt_m, size");
  if (!pairs) return tl::unexpected(pairs.error());
  if (!lat) return fail(ErrorCode::InvalidArgument, "lat: missing");
  if (!lon) return fail(ErrorCode::InvalidArgument, "lon: missing");
  if (!(q.range_km > 0)) return fail(ErrorCode::InvalidArgument, "range_km: must be above 0");
  if (sizeValue != std::floor(sizeValue)) return fail(ErrorCode::InvalidArgument, "size: not an integer");
  q.size = static_cast<int>(sizeValue);
  return q;
}

}  // namespace sky::server
