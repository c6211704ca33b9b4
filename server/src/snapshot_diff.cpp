// The delta between two snapshots the server built, layer by layer (see
// diffBuilt in snapshot_builder.hpp).
#include <algorithm>

#include "sky/server/snapshot_builder.hpp"

namespace sky::server {

namespace {

// Whether `s` keeps its tiles in its runs, one run per layer.
bool byLayer(const BuiltSnapshot& s) {
  return s.runs.size() == s.snapshot.layers.size() && s.snapshot.tiles.empty();
}

// The snapshot's layer table alone, at `tileLevel`.
weather::WeatherSnapshot tableOf(const BuiltSnapshot& s, int tileLevel) {
  weather::WeatherSnapshot t;
  t.weatherClock_s = s.snapshot.weatherClock_s;
  t.layers = s.snapshot.layers;
  t.tileLevel = tileLevel;
  t.areaIndex = s.snapshot.areaIndex;
  return t;
}

const LayerRun* runOf(const BuiltSnapshot& s, std::uint32_t layerId) {
  for (std::size_t i = 0; i < s.snapshot.layers.size(); ++i)
    if (s.snapshot.layers[i].id == layerId) return &s.runs[i];
  return nullptr;
}

// Whether two runs hold tiles for the same cells in the same order (known
// without reading them when both are over one covering).
bool sameCells(const LayerTiles& was, const LayerTiles& now) {
  if (was.size() != now.size() || was.layerId != now.layerId) return false;
  if ((was.covering != 0 && was.covering == now.covering) || was.cells == now.cells) return true;
  return *was.cells == *now.cells;
}

// Appends to `out` the tiles of `now` that differ from `was` (same cells, in
// order). Where both have the same value outside the cells regions reach,
// only the reached cells of either can differ: a storm cell moving over an
// area compares its few hundred cells, not the area's thousands.
void changedTiles(const LayerTiles& was, const LayerTiles& now, std::vector<weather::CoverageTile>& out) {
  if (was.coverage != now.coverage || was.density != now.density) {
    std::vector<weather::CoverageTile> a, b;
    was.appendTo(a);
    now.appendTo(b);
    for (std::size_t k = 0; k < b.size(); ++k)
      if (!(a[k] == b[k])) out.push_back(b[k]);
    return;
  }
  // The union of both reached sets, ascending (so `out` keeps `now`'s order);
  // a cell only one side reaches has the other's own value there.
  const auto tileOf = [](const LayerTiles& t, std::size_t pos) {
    return t.dense ? t.tiles[t.reached[pos]] : t.tiles[pos];
  };
  const auto unreached = [](const LayerTiles& t, std::uint32_t k) {
    return t.dense ? t.tiles[k] : weather::CoverageTile{(*t.cells)[k], t.layerId, t.coverage, t.density};
  };
  std::size_t i = 0, j = 0;
  while (i < was.reached.size() || j < now.reached.size()) {
    weather::CoverageTile a, b;
    if (j == now.reached.size() || (i < was.reached.size() && was.reached[i] < now.reached[j])) {
      a = tileOf(was, i);
      b = unreached(now, was.reached[i++]);
    } else if (i == was.reached.size() || now.reached[j] < was.reached[i]) {
      a = unreached(was, now.reached[j]);
      b = tileOf(now, j++);
    } else {
      a = tileOf(was, i++);
      b = tileOf(now, j++);
    }
    if (!(a == b)) out.push_back(b);
  }
}

}  // namespace

std::optional<weather::WeatherDelta> diffBuilt(const BuiltSnapshot& before, const BuiltSnapshot& after) {
  const auto whole = [&] { return weather::diffSnapshots(wholeSnapshot(before), wholeSnapshot(after)); };
  if (!byLayer(before) || !byLayer(after)) return whole();
  const std::size_t beforeTiles = tileCount(before), afterTiles = tileCount(after);
  const int beforeLevel = before.snapshot.tileLevel, afterLevel = after.snapshot.tileLevel;
  if (beforeTiles != 0 && afterTiles != 0 && beforeLevel != afterLevel) return std::nullopt;
  // The layer table's part of the delta (upserts, removals, and no delta
  // when layers were reordered), from the tables alone.
  auto delta = weather::diffSnapshots(tableOf(before, afterLevel), tableOf(after, afterLevel));
  if (!delta) return std::nullopt;
  // Wind and air tiles (thousands at most) by the general diff, on the tables.
  const auto fields = [](const weather::WeatherSnapshot& s) {
    return !s.windTiles.empty() || !s.airTiles.empty() || s.windTileLevel != 0 || s.airTileLevel != 0 ||
           !s.airLevels_m.empty();
  };
  if (fields(before.snapshot) || fields(after.snapshot)) {
    const auto withFields = [&](const BuiltSnapshot& s) {
      weather::WeatherSnapshot t = tableOf(s, afterLevel);
      t.windTileLevel = s.snapshot.windTileLevel;
      t.windTiles = s.snapshot.windTiles;
      t.airLevels_m = s.snapshot.airLevels_m;
      t.airTileLevel = s.snapshot.airTileLevel;
      t.airTiles = s.snapshot.airTiles;
      return t;
    };
    const auto changed = weather::diffSnapshots(withFields(before), withFields(after));
    if (!changed) return std::nullopt;
    delta->windTileLevel = changed->windTileLevel;
    delta->windTiles = changed->windTiles;
    delta->airTileLevel = changed->airTileLevel;
    delta->airTiles = changed->airTiles;
  }
  // Tiles, in the order of `after`'s: per layer, the tiles that differ from
  // the same layer's before. Any layer whose cells are not the ones it had
  // (a layer gaining or losing tiles, a covering that moved) goes through
  // the general diff, which knows when a delta cannot say it.
  for (std::size_t i = 0; i < after.snapshot.layers.size(); ++i) {
    const LayerRun& now = after.runs[i];
    const LayerRun* was = runOf(before, after.snapshot.layers[i].id);
    if (!was) {  // a new layer: all its tiles
      if (now.tiles) now.tiles->appendTo(delta->tiles);
      continue;
    }
    if (now.generation != 0 && now.generation == was->generation && beforeLevel == afterLevel) continue;
    if (!now.tiles) {
      if (!was->tiles) continue;
      return whole();  // the layer lost its tiles: no delta says that
    }
    if (!was->tiles) {  // the layer gained tiles (a region came): all of them
      now.tiles->appendTo(delta->tiles);
      continue;
    }
    if (!sameCells(*was->tiles, *now.tiles)) return whole();
    changedTiles(*was->tiles, *now.tiles, delta->tiles);
  }
  // With no tiles a delta cannot move the snapshot's level.
  if (delta->tiles.empty() && beforeLevel != afterLevel) return std::nullopt;
  return delta;
}

}  // namespace sky::server
