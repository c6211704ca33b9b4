// S2 coverings of spherical caps.
#include "sky/weather/tiling.hpp"

#include <algorithm>
#include <cmath>

#include <s2/s1angle.h>
#include <s2/s2cap.h>
#include <s2/s2cell.h>
#include <s2/s2cell_id.h>
#include <s2/s2latlng.h>
#include <s2/s2metrics.h>
#include <s2/s2region_coverer.h>

namespace sky::weather {

namespace {
// Mean Earth radius (IUGG R1), the radius S2 uses to turn metres into angles.
constexpr double kMeanEarthRadius_m = 6371008.8;
}

std::vector<std::uint64_t> coverCap(const SphericalCap& cap, int level, std::size_t maxCells) {
  const S2Point centre =
      S2LatLng::FromDegrees(cap.centerLat_deg, cap.centerLon_deg).Normalized().ToPoint();
  const S2Cap s2cap(centre, S1Angle::Radians(cap.radius_m / kMeanEarthRadius_m));
  S2RegionCoverer::Options options;
  options.set_fixed_level(level);
  options.set_max_cells(static_cast<int>(maxCells));
  S2RegionCoverer coverer(options);
  std::vector<S2CellId> cells;
  coverer.GetCovering(s2cap, &cells);
  std::vector<std::uint64_t> out;
  out.reserve(cells.size());
  for (const S2CellId& c : cells) out.push_back(c.id());
  return out;
}

std::uint64_t cellAt(double lat_deg, double lon_deg, int level) {
  return S2CellId(S2LatLng::FromDegrees(lat_deg, lon_deg).Normalized()).parent(level).id();
}

CellCentre cellCentre(std::uint64_t id) {
  const S2LatLng c(S2CellId(id).ToPoint());
  return {c.lat().degrees(), c.lng().degrees()};
}

double averageCellEdge_m(int level) {
  return S2::kAvgEdge.GetValue(level) * kMeanEarthRadius_m;
}

int levelForRadius(double radius_m, std::size_t maxCells, int maxLevel) {
  // Cap area on the sphere: 2 pi R^2 (1 - cos(r / R)).
  const double capArea_m2 =
      2.0 * M_PI * kMeanEarthRadius_m * kMeanEarthRadius_m * (1.0 - std::cos(radius_m / kMeanEarthRadius_m));
  // A covering also takes the ring of cells cut by the cap's edge: about
  // perimeter / edge more. Both terms are estimated with S2's averages.
  const double perimeter_m = 2.0 * M_PI * kMeanEarthRadius_m * std::sin(std::min(radius_m / kMeanEarthRadius_m, M_PI / 2));
  for (int level = maxLevel; level > 0; --level) {
    const double cellArea = S2::kAvgArea.GetValue(level) * kMeanEarthRadius_m * kMeanEarthRadius_m;
    const double edge = averageCellEdge_m(level);
    const double expected = capArea_m2 / cellArea + perimeter_m / edge + 4;
    if (expected <= static_cast<double>(maxCells)) return level;
  }
  return 0;
}

bool isCellAtLevel(std::uint64_t id, int level) {
  const S2CellId c(id);
  return c.is_valid() && c.level() == level;
}

double cellArea_m2(std::uint64_t id) {
  return S2Cell(S2CellId(id)).ExactArea() * kMeanEarthRadius_m * kMeanEarthRadius_m;
}

}  // namespace sky::weather
