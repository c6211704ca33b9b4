// S2 coverings of spherical caps.
#include "sky/weather/tiling.hpp"

#include <s2/s1angle.h>
#include <s2/s2cap.h>
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

double averageCellEdge_m(int level) {
  return S2::kAvgEdge.GetValue(level) * kMeanEarthRadius_m;
}

}  // namespace sky::weather
