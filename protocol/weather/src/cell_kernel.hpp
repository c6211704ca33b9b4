// The smooth kernel over S2 cells that the wind and air fields share: a
// point's own cell and its neighbours, each weighted (1 - (d / r)^2)^2 by its
// centre's distance d from the point, r one cell edge. A tile's own value at
// its centre, the two cells' mean on their shared edge, no step at an edge.
#pragma once

#include <cmath>
#include <vector>

#include <s2/s2cell.h>
#include <s2/s2cell_id.h>
#include <s2/s2latlng.h>

namespace sky::weather::detail {

// Calls fn(cellId, weight) for each cell of `level` within reach of the
// point (weight > 0).
template <class Fn>
void forEachKernelCell(int level, double lat_deg, double lon_deg, Fn&& fn) {
  const S2Point p = S2LatLng::FromDegrees(lat_deg, lon_deg).Normalized().ToPoint();
  const S2CellId home = S2CellId(p).parent(level);
  std::vector<S2CellId> around{home};
  home.AppendAllNeighbors(level, &around);
  // Angular reach from the cell's own size (S2 cells differ up to ~2x in
  // size over a cube face, so not one constant per level).
  const double reach = std::sqrt(S2Cell(home).ApproxArea());
  for (const S2CellId& c : around) {
    const double d = p.Angle(c.ToPoint()) / reach;
    if (d >= 1) continue;
    fn(c.id(), (1 - d * d) * (1 - d * d));
  }
}

}  // namespace sky::weather::detail
