// A saved weather state (LiveWeather::toJson) cut by S2 cell, so that a relay
// takes only the part of the weather its renderers' areas need. A state is
// mostly regions: a continent of METAR stations is thousands of them, and a
// change touches a few. The cut: a region that stays where it was put (not
// drifting with the wind) goes to every level-kStateCellLevel cell its reach
// (its half diagonal plus its transition perimeter) touches, and so does a
// region ramp, by the reach of its region at points along the path its
// centre takes (lerpRegion); everything else (layers and
// their ramps, the timeline, the forecast, the clock, drifting regions,
// regions too large to place, ramps that move a region farther than a
// region may reach) is the "global" part every relay takes. A
// renderer's area meets a region only in a cell both touch, so the cells
// covering the areas hold every region that shapes their tiles.
#pragma once

#include <cstddef>
#include <cstdint>
#include <map>
#include <string>
#include <unordered_map>
#include <vector>

#include <nlohmann/json.hpp>

#include "sky/weather/tiling.hpp"

namespace sky::server {

// S2 level of the cells (about 150 km across, 24576 on the Earth), as the
// issue asked: a renderer's fine area (120 km) meets a handful, its coarse
// one (900 km) about 150.
inline constexpr int kStateCellLevel = 6;
// A region whose reach is past this stays in the global part: covering it
// would take more cells than its own bytes are worth.
inline constexpr double kMaxCellRegionReach_m = 600e3;
// Cells one area may ask for before a relay takes the whole state instead.
inline constexpr std::size_t kMaxCellsPerArea = 1024;

struct StateCells {
  // The state without the regions and region ramps placed in cells.
  nlohmann::json global;
  // By cell key (cellKey): {"regions": [...], "region_ramps": [...]}, each
  // in the state's order.
  std::map<std::string, nlohmann::json> cells;
};

// The cells a region's reach touches, remembered by the region's placement
// (a METAR refresh changes a station's layers, not where it is), so that
// cutting a state of thousands of regions after every change costs a look-up
// per region. Bounded: emptied when it grows past kMaxEntries.
class CellReach {
 public:
  static constexpr std::size_t kMaxEntries = 1 << 16;
  // Keys of the cells the region (a saved region's JSON) reaches; empty when
  // it stays global (drifting, too large, or not a region).
  const std::vector<std::string>& cellsOf(const nlohmann::json& region);
  // Keys of the cells a cap touches.
  const std::vector<std::string>& cellsOfCap(const weather::SphericalCap& cap);

 private:
  std::unordered_map<std::string, std::vector<std::string>> byPlacement_;
};

// The key a cell goes by on NATS: "c" and its S2 token ("c.47a1").
std::string cellKey(std::uint64_t cellId);

// Cuts a saved state (moved in: its items move to the parts). A state
// without regions has no cells.
StateCells splitState(nlohmann::json state, CellReach& reach);

// The state again from the global part and the cells held: regions by id,
// region ramps by sequence and region id (the order LiveWeather saves them
// in). A region in several cells is taken once. join(split(s)) == s.
nlohmann::json joinState(const nlohmann::json& global, const std::vector<const nlohmann::json*>& cells);

// The cell keys covering the areas, sorted; empty (and `tooMany` set) when
// one area needs more than kMaxCellsPerArea. Each area's covering comes from
// `cache` (a relay's renderers subscribe anew one at a time, and the others'
// areas stand).
std::vector<std::string> cellsForAreas(const std::vector<weather::SphericalCap>& areas, CellReach& cache,
                                       bool& tooMany);

}  // namespace sky::server
