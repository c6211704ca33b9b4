// Region validation, drift and the blend weight (see region.hpp).
#include "sky/weather/region.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <set>
#include <string>

#include <GeographicLib/Geodesic.hpp>

#include "sky/geo/geodetic.hpp"
#include "sky/weather/advection.hpp"

namespace sky::weather {

namespace {

constexpr double kMaxRegionSize_m = 2e6;
// Beyond this geodesic distance from the centre the azimuthal plane is too
// distorted to measure in; no region reaches that far (its size and perimeter
// are at most 2000 km each).
constexpr double kFarAway_m = 5e6;

std::string num(double v) {
  char buf[48];
  std::snprintf(buf, sizeof buf, "%.10g", v);
  return buf;
}

Result<void> range(const Region& r, const char* field, double v, double lo, double hi, bool openLow,
                   const char* unit) {
  if (std::isfinite(v) && (openLow ? v > lo : v >= lo) && v <= hi) return {};
  return fail(ErrorCode::InvalidArgument, "region " + std::to_string(r.id) + ": " + field + " " + num(v) +
                                              " outside " + (openLow ? "(" : "[") + num(lo) + ", " + num(hi) + "]" +
                                              unit);
}

}  // namespace

Result<void> validate(const Region& r) {
  if (r.id < 1 || r.id > 65535)
    return fail(ErrorCode::InvalidArgument, "region " + std::to_string(r.id) + ": id outside [1, 65535]");
  if (auto ok = range(r, "center_lat_deg", r.centerLat_deg, -90, 90, false, " deg"); !ok) return ok;
  if (!std::isfinite(r.centerLon_deg))
    return fail(ErrorCode::InvalidArgument, "region " + std::to_string(r.id) + ": center_lon_deg must be finite");
  if (auto ok = range(r, "size_x_m", r.sizeX_m, 0, kMaxRegionSize_m, true, " m"); !ok) return ok;
  if (auto ok = range(r, "size_y_m", r.sizeY_m, 0, kMaxRegionSize_m, true, " m"); !ok) return ok;
  if (auto ok = range(r, "corner_radius_m", r.cornerRadius_m, 0, std::min(r.sizeX_m, r.sizeY_m) / 2, false, " m");
      !ok)
    return ok;
  if (auto ok = range(r, "rotation_deg", r.rotation_deg, -180, 180, false, " deg"); !ok) return ok;
  if (auto ok = range(r, "transition_m", r.transition_m, 0, kMaxRegionSize_m, false, " m"); !ok) return ok;
  if (!std::isfinite(r.placedAtClock_s))
    return fail(ErrorCode::InvalidArgument, "region " + std::to_string(r.id) + ": placed_at_clock_s must be finite");
  if (r.layers.size() > kMaxRegionLayers)
    return fail(ErrorCode::InvalidArgument, "region " + std::to_string(r.id) + ": " +
                                                std::to_string(r.layers.size()) + " layers, at most " +
                                                std::to_string(kMaxRegionLayers));
  std::set<std::uint32_t> ids;
  for (std::size_t i = 0; i < r.layers.size(); ++i) {
    const std::string at = "region " + std::to_string(r.id) + ": layers[" + std::to_string(i) + "]: ";
    if (auto ok = validate(r.layers[i]); !ok) return fail(ErrorCode::InvalidArgument, at + ok.error().detail);
    if (!ids.insert(r.layers[i].id).second)
      return fail(ErrorCode::InvalidArgument, at + "layer id " + std::to_string(r.layers[i].id) + " given twice");
  }
  if (r.driftsWithWind && r.layers.empty())
    return fail(ErrorCode::InvalidArgument,
                "region " + std::to_string(r.id) + ": drifts_with_wind needs a layer (the wind of its first)");
  return {};
}

Region regionAt(const Region& region, double clock_s) {
  Region out = region;
  if (region.driftsWithWind && !region.layers.empty()) {
    const SurfacePoint p = advect({region.centerLat_deg, region.centerLon_deg}, region.layers.front().wind,
                                  clock_s - region.placedAtClock_s);
    out.centerLat_deg = p.lat_deg;
    out.centerLon_deg = p.lon_deg;
  }
  out.centerLon_deg = geo::normalizeLon_deg(out.centerLon_deg);
  out.placedAtClock_s = clock_s;
  return out;
}

double regionEdgeDistance_m(const Region& r, double lat_deg, double lon_deg) {
  double s12 = 0, azi1 = 0, azi2 = 0;
  GeographicLib::Geodesic::WGS84().Inverse(r.centerLat_deg, r.centerLon_deg, lat_deg, lon_deg, s12, azi1, azi2);
  if (!(s12 < kFarAway_m)) return kFarAway_m;
  // Coordinates along the region's axes: y points at azimuth rotation, x a
  // quarter turn clockwise of it.
  const double a = (azi1 - r.rotation_deg) * std::numbers::pi / 180.0;
  const double u = std::abs(s12 * std::sin(a));
  const double v = std::abs(s12 * std::cos(a));
  // Rounded rectangle: the rectangle shrunk by the corner radius, then grown
  // by it again.
  const double rc = r.cornerRadius_m;
  const double qx = u - (r.sizeX_m / 2 - rc);
  const double qy = v - (r.sizeY_m / 2 - rc);
  const double outside = std::hypot(std::max(qx, 0.0), std::max(qy, 0.0));
  const double inside = std::min(std::max(qx, qy), 0.0);
  return outside + inside - rc;
}

double regionWeight(const Region& region, double lat_deg, double lon_deg) {
  const double d = regionEdgeDistance_m(region, lat_deg, lon_deg);
  if (d <= 0) return 1.0;
  if (d >= region.transition_m) return 0.0;
  const double t = 1.0 - d / region.transition_m;
  return t * t * (3.0 - 2.0 * t);
}

}  // namespace sky::weather
