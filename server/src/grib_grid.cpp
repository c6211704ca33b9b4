// Grid geometry of GRIB2 messages (grib.hpp): pure math, no ecCodes. The
// Lambert conformal conic is Snyder's spherical form (Map Projections: A
// Working Manual, USGS 1395, eqs. 15-1 to 15-5 and 14-4 for the scale), the
// projection GRIB2 template 3.30 names.
#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <string>

#include "sky/geo/geodetic.hpp"
#include "sky/server/grib.hpp"

namespace sky::server {

namespace {

constexpr double kDeg = std::numbers::pi / 180;
// A grid whose row spans 360 degrees to within this share of a step closes
// round the Earth (the last point is one step before the first).
constexpr double kGlobalSlack = 0.01;
// Points up to half a step outside the edge rows or columns still take the
// edge's values: a cell centred on the edge point reaches that far.
constexpr double kEdgeReach = 0.5;

// The cone of a Lambert grid: n, and R·F of Snyder's 15-1 and 15-2.
struct Cone {
  double n = 0, rf = 0;
};

Cone coneOf(const GribGrid& g) {
  const double p1 = g.latin1_deg * kDeg, p2 = g.latin2_deg * kDeg;
  const auto t = [](double p) { return std::tan(std::numbers::pi / 4 + p / 2); };
  const double n = std::abs(p1 - p2) < 1e-12 ? std::sin(p1)
                                             : std::log(std::cos(p1) / std::cos(p2)) / std::log(t(p2) / t(p1));
  return {n, g.radius_m * std::cos(p1) * std::pow(t(p1), n) / n};
}

double rhoOf(const Cone& c, double lat_rad) {
  return c.rf / std::pow(std::tan(std::numbers::pi / 4 + lat_rad / 2), c.n);
}

struct Xy {
  double x = 0, y = 0;
};

// Projected coordinates (m on the projection plane, y up towards the apex's
// side as Snyder has it), ρ0 taken at LaD.
Xy project(const GribGrid& g, const Cone& c, double lat_deg, double lon_deg) {
  const double theta = c.n * geo::normalizeLon_deg(lon_deg - g.lov_deg) * kDeg;
  const double rho = rhoOf(c, lat_deg * kDeg), rho0 = rhoOf(c, g.lad_deg * kDeg);
  return {rho * std::sin(theta), rho0 - rho * std::cos(theta)};
}

// Metres on the projection plane per grid step: Dx and Dy hold at LaD,
// where the projection's scale is k (Snyder 15-4).
double planeScale(const GribGrid& g, const Cone& c) {
  const double lad = g.lad_deg * kDeg;
  return rhoOf(c, lad) * c.n / (g.radius_m * std::cos(lad));
}

double lonStep_deg(const GribGrid& g) {
  if (g.ni < 2) return 360;
  double span = g.iNegative ? g.lon1_deg - g.lon2_deg : g.lon2_deg - g.lon1_deg;
  span = std::fmod(span, 360.0);
  if (span <= 0) span += 360;
  return span / (g.ni - 1);
}

double latStep_deg(const GribGrid& g) { return g.nj < 2 ? 180 : std::abs(g.lat2_deg - g.lat1_deg) / (g.nj - 1); }

bool inRange(double v, int n) { return v >= -kEdgeReach && v <= n - 1 + kEdgeReach; }

}  // namespace

Result<void> validate(const GribGrid& g) {
  auto bad = [](std::string what) { return fail(ErrorCode::InvalidArgument, std::move(what)); };
  if (g.ni < 1 || g.nj < 1 || g.ni > (1 << 20) || g.nj > (1 << 20))
    return bad("grid: " + std::to_string(g.ni) + " x " + std::to_string(g.nj) + " points");
  auto lat = [&](const char* key, double v) -> Result<void> {
    if (!(v >= -90 && v <= 90)) return bad(std::string("grid: ") + key + " " + std::to_string(v));
    return {};
  };
  auto finite = [&](const char* key, double v) -> Result<void> {
    if (!std::isfinite(v)) return bad(std::string("grid: ") + key + " not finite");
    return {};
  };
  for (auto r : {lat("latitudeOfFirstGridPoint", g.lat1_deg), finite("longitudeOfFirstGridPoint", g.lon1_deg)})
    if (!r) return r;
  if (g.projection == GribGrid::Projection::LatLon) {
    for (auto r : {lat("latitudeOfLastGridPoint", g.lat2_deg), finite("longitudeOfLastGridPoint", g.lon2_deg)})
      if (!r) return r;
    if (g.nj > 1 && g.lat1_deg == g.lat2_deg) return bad("grid: first and last rows at the same latitude");
    if (g.nj > 1 && (g.lat2_deg > g.lat1_deg) != g.jPositive)
      return bad("grid: the last row lies against the j scanning direction");
    return {};
  }
  for (auto r : {lat("Latin1", g.latin1_deg), lat("Latin2", g.latin2_deg), lat("LaD", g.lad_deg),
                 finite("LoV", g.lov_deg)})
    if (!r) return r;
  if (std::abs(g.latin1_deg) > 89.9 || std::abs(g.latin2_deg) > 89.9 || std::abs(g.latin1_deg) < 0.1 ||
      std::abs(g.latin2_deg) < 0.1 || (g.latin1_deg > 0) != (g.latin2_deg > 0) || std::abs(g.lad_deg) > 89.9)
    return bad("Lambert: standard parallels " + std::to_string(g.latin1_deg) + ", " + std::to_string(g.latin2_deg) +
               " make no cone");
  if (!(g.dx_m > 0 && g.dx_m < 1e7 && g.dy_m > 0 && g.dy_m < 1e7))
    return bad("Lambert: Dx, Dy " + std::to_string(g.dx_m) + ", " + std::to_string(g.dy_m) + " m");
  if (!(g.radius_m > 6e6 && g.radius_m < 7e6)) return bad("Lambert: Earth radius " + std::to_string(g.radius_m));
  const Cone c = coneOf(g);
  if (!std::isfinite(c.n) || !std::isfinite(c.rf) || std::abs(c.n) < 1e-6) return bad("Lambert: degenerate cone");
  return {};
}

bool isGlobalInLongitude(const GribGrid& g) {
  if (g.projection != GribGrid::Projection::LatLon || g.ni < 2) return false;
  const double step = lonStep_deg(g);
  return std::abs(step * g.ni - 360) < kGlobalSlack * step;
}

std::size_t valueIndex(const GribGrid& g, int i, int j) {
  return g.jConsecutive ? static_cast<std::size_t>(i) * g.nj + j : static_cast<std::size_t>(j) * g.ni + i;
}

std::optional<GridPoint> locate(const GribGrid& g, double lat_deg, double lon_deg) {
  if (!(lat_deg >= -90 && lat_deg <= 90) || !std::isfinite(lon_deg)) return std::nullopt;
  GridPoint p;
  if (g.projection == GribGrid::Projection::LatLon) {
    const double dlat = latStep_deg(g), dlon = lonStep_deg(g);
    p.j = (g.jPositive ? lat_deg - g.lat1_deg : g.lat1_deg - lat_deg) / dlat;
    double d = std::fmod(g.iNegative ? g.lon1_deg - lon_deg : lon_deg - g.lon1_deg, 360.0);
    if (d < 0) d += 360;
    p.i = d / dlon;
    if (isGlobalInLongitude(g)) {
      if (p.i >= g.ni) p.i -= g.ni;  // rounding at the seam
    } else if (p.i > g.ni - 1 + kEdgeReach) {
      // Just west of the first column reads as almost 360 degrees east.
      const double before = p.i - 360 / dlon;
      if (before < -kEdgeReach) return std::nullopt;
      p.i = before;
    }
    if (!inRange(p.j, g.nj)) return std::nullopt;
    return p;
  }
  const Cone c = coneOf(g);
  // The apex's opposite pole is at infinity on the plane.
  if ((c.n > 0 && lat_deg <= -90 + 1e-9) || (c.n < 0 && lat_deg >= 90 - 1e-9)) return std::nullopt;
  const Xy first = project(g, c, g.lat1_deg, g.lon1_deg), q = project(g, c, lat_deg, lon_deg);
  const double k = planeScale(g, c);
  p.i = (g.iNegative ? first.x - q.x : q.x - first.x) / (g.dx_m * k);
  p.j = (g.jPositive ? q.y - first.y : first.y - q.y) / (g.dy_m * k);
  if (!std::isfinite(p.i) || !std::isfinite(p.j) || !inRange(p.i, g.ni) || !inRange(p.j, g.nj)) return std::nullopt;
  return p;
}

LatLon gridLatLon(const GribGrid& g, double i, double j) {
  if (g.projection == GribGrid::Projection::LatLon) {
    const double lat = g.lat1_deg + (g.jPositive ? 1 : -1) * j * latStep_deg(g);
    const double lon = g.lon1_deg + (g.iNegative ? -1 : 1) * i * lonStep_deg(g);
    return {std::clamp(lat, -90.0, 90.0), geo::normalizeLon_deg(lon)};
  }
  const Cone c = coneOf(g);
  const Xy first = project(g, c, g.lat1_deg, g.lon1_deg);
  const double k = planeScale(g, c);
  const double x = first.x + (g.iNegative ? -1 : 1) * i * g.dx_m * k;
  const double y = first.y + (g.jPositive ? 1 : -1) * j * g.dy_m * k;
  const double rho0 = rhoOf(c, g.lad_deg * kDeg), s = c.n > 0 ? 1 : -1;
  const double rho = s * std::hypot(x, rho0 - y);
  const double theta = std::atan2(s * x, s * (rho0 - y));
  const double lat = 2 * std::atan(std::pow(c.rf / rho, 1 / c.n)) - std::numbers::pi / 2;
  return {lat / kDeg, geo::normalizeLon_deg(theta / c.n / kDeg + g.lov_deg)};
}

float sampleField(const GribGrid& g, std::span<const float> values, double lat_deg, double lon_deg) {
  constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();
  if (values.size() != static_cast<std::size_t>(g.ni) * g.nj) return kNaN;
  const auto at = locate(g, lat_deg, lon_deg);
  if (!at) return kNaN;
  const bool wraps = isGlobalInLongitude(g);
  // Within half a step outside an edge the edge's value holds.
  const double fi = wraps ? at->i : std::clamp(at->i, 0.0, static_cast<double>(g.ni - 1));
  const double fj = std::clamp(at->j, 0.0, static_cast<double>(g.nj - 1));
  const int i0 = std::min(static_cast<int>(std::floor(fi)), g.ni - 1);
  const int j0 = std::min(static_cast<int>(std::floor(fj)), g.nj - 1);
  const double ti = fi - i0, tj = fj - j0;
  double sum = 0, weight = 0;
  for (int dj = 0; dj < 2; ++dj)
    for (int di = 0; di < 2; ++di) {
      const double w = (di ? ti : 1 - ti) * (dj ? tj : 1 - tj);
      if (w <= 0) continue;
      int i = i0 + di;
      const int j = std::min(j0 + dj, g.nj - 1);
      if (i >= g.ni) i = wraps ? i - g.ni : g.ni - 1;
      const float v = values[valueIndex(g, i, j)];
      if (std::isnan(v)) continue;
      sum += w * v;
      weight += w;
    }
  if (weight < 0.5) return kNaN;
  return static_cast<float>(sum / weight);
}

std::pair<double, double> eastNorthWind(const GribGrid& grid, double lat_deg, double lon_deg, double u, double v) {
  (void)lat_deg;  // a conic projection's convergence depends on longitude alone
  if (!grid.uvRelativeToGrid || grid.projection != GribGrid::Projection::Lambert) return {u, v};
  const double theta = coneOf(grid).n * geo::normalizeLon_deg(lon_deg - grid.lov_deg) * kDeg;
  // The grid's +y is north turned clockwise by theta (east of LoV, where the
  // meridians lean towards the apex), its +x east turned the same way.
  return {u * std::cos(theta) + v * std::sin(theta), -u * std::sin(theta) + v * std::cos(theta)};
}

}  // namespace sky::server
