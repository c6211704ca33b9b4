// Areas of interest as spherical caps, covered with S2 cells, so tiling works
// the same at the poles and across the antimeridian.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

namespace sky::weather {

struct SphericalCap {
  double centerLat_deg = 0;  // [-90, 90]
  double centerLon_deg = 0;  // any; normalised internally
  double radius_m = 0;       // along the surface (mean Earth radius), (0, 2e7]
};

// S2 cells of exactly `level` that cover the cap, at most maxCells of them
// (the coverer then returns a coarser, still covering, set which is expanded
// only up to that cap: callers choose level and radius so this does not bite).
std::vector<std::uint64_t> coverCap(const SphericalCap& cap, int level, std::size_t maxCells);

// The S2 cell of `level` containing a point.
std::uint64_t cellAt(double lat_deg, double lon_deg, int level);

// Centre of an S2 cell (a valid id), degrees.
struct CellCentre {
  double lat_deg = 0;
  double lon_deg = 0;
};
CellCentre cellCentre(std::uint64_t id);

// Mean edge length of a cell at `level`, m (S2's average, for choosing levels).
double averageCellEdge_m(int level);

// The finest level (<= maxLevel) at which a covering of a cap of this radius
// is expected to need at most maxCells cells (cap area over S2's average cell
// area, with a margin for the cells cut by the edge).
int levelForRadius(double radius_m, std::size_t maxCells, int maxLevel = 20);

// Whether id is a valid S2CellId of exactly `level`.
bool isCellAtLevel(std::uint64_t id, int level);

// Area of an S2 cell, m^2 (exact on the sphere of mean Earth radius).
double cellArea_m2(std::uint64_t id);

}  // namespace sky::weather
