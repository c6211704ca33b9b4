// Cloud type names and layer validation.
#include "sky/weather/model.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <string>
#include <map>

namespace sky::weather {

namespace {
constexpr std::array<std::string_view, kMaxCloudType + 1> kNames = {
    "none",       "altocumulus",  "altostratus",  "cirrocumulus",  "cirrostratus", "cirrus",
    "cumulonimbus", "cumulus",    "nimbostratus", "stratocumulus", "stratus",      "fog",
    "rain",       "snow",         "sleet",        "hail"};

Result<void> checkRange(const CloudLayer& layer, const char* field, double value, double lo,
                        double hi, bool openLow = false) {
  const bool ok = std::isfinite(value) && (openLow ? value > lo : value >= lo) && value <= hi;
  if (ok) return {};
  return fail(ErrorCode::InvalidArgument,
              "layer " + std::to_string(layer.id) + ": " + field + " " + std::to_string(value) +
                  " outside " + (openLow ? "(" : "[") + std::to_string(lo) + ", " +
                  std::to_string(hi) + "]");
}
}  // namespace

std::string_view toString(CloudType type) {
  const auto i = static_cast<std::size_t>(type);
  return i < kNames.size() ? kNames[i] : std::string_view("unknown");
}

std::optional<CloudType> cloudTypeFromString(std::string_view name) {
  for (std::size_t i = 0; i < kNames.size(); ++i)
    if (kNames[i] == name) return static_cast<CloudType>(i);
  return std::nullopt;
}

Result<void> validate(const CloudLayer& layer) {
  if (static_cast<std::uint8_t>(layer.type) > kMaxCloudType)
    return fail(ErrorCode::InvalidArgument,
                "layer " + std::to_string(layer.id) + ": cloud type " +
                    std::to_string(static_cast<int>(layer.type)) + " outside [0, " + std::to_string(kMaxCloudType) + "]");
  Result<void> r;
  // Tiles carry the layer id in 16 bits on the stream.
  if (!(r = checkRange(layer, "id", layer.id, 0, 65535))) return r;
  if (!(r = checkRange(layer, "base_m", layer.base_m, -500, 20000))) return r;
  if (!(r = checkRange(layer, "thickness_m", layer.thickness_m, 0, 20000, true))) return r;
  if (!(r = checkRange(layer, "transition_band_m", layer.transitionBand_m, 0, 5000))) return r;
  if (!(r = checkRange(layer, "coverage", layer.coverage, 0, 1))) return r;
  if (!(r = checkRange(layer, "density", layer.density, 0, 1))) return r;
  if (!(r = checkRange(layer, "wind.speed_mps", layer.wind.speed_mps, 0, 150))) return r;
  if (!(r = checkRange(layer, "wind.from_deg", layer.wind.fromDirection_deg, 0, 360))) return r;
  if (!(r = checkRange(layer, "wind.vertical_mps", layer.wind.vertical_mps, -50, 50))) return r;
  return {};
}

namespace {

// Tiles are keyed by (cell, layer); air tiles by (cell, air level), and
// removing a layer does not touch them.
std::pair<std::uint64_t, std::uint32_t> tileKey(const CoverageTile& t) { return {t.cellId, t.layerId}; }
std::pair<std::uint64_t, std::uint32_t> tileKey(const WindTile& t) { return {t.cellId, t.layerId}; }
std::pair<std::uint64_t, std::uint32_t> tileKey(const AirTile& t) { return {t.cellId, t.level}; }
bool goesWithLayer(const CoverageTile& t, std::uint32_t id) { return t.layerId == id; }
bool goesWithLayer(const WindTile& t, std::uint32_t id) { return t.layerId == id; }
bool goesWithLayer(const AirTile&, std::uint32_t) { return false; }

// Whether a delta's tile may go into the snapshot `next`: its layer exists
// (a cover or wind tile), its air level does (an air tile).
template <class LayerTile>
Result<void> fits(const LayerTile& t, const WeatherSnapshot& next, const char* what) {
  if (std::any_of(next.layers.begin(), next.layers.end(), [&](const CloudLayer& l) { return l.id == t.layerId; }))
    return {};
  return fail(ErrorCode::InvalidArgument,
              std::string("delta ") + what + " of layer " + std::to_string(t.layerId) + ", which does not exist");
}
Result<void> fits(const AirTile& t, const WeatherSnapshot& next, const char* what) {
  if (t.level < next.airLevels_m.size()) return {};
  return fail(ErrorCode::InvalidArgument, std::string("delta ") + what + " at air level " + std::to_string(t.level) +
                                              ", the snapshot has " + std::to_string(next.airLevels_m.size()));
}

// Upserts `add` into `tiles` by key; tiles of one kind share a level.
template <class Tile>
Result<void> upsertTiles(std::vector<Tile>& tiles, int& level, const std::vector<Tile>& add, int addLevel,
                         const WeatherSnapshot& next, const char* what) {
  if (add.empty()) return {};
  if (!tiles.empty() && addLevel != level)
    return fail(ErrorCode::InvalidArgument, std::string("delta ") + what + "s at S2 level " + std::to_string(addLevel) +
                                                ", the snapshot's are at " + std::to_string(level));
  level = addLevel;
  std::map<std::pair<std::uint64_t, std::uint32_t>, std::size_t> index;  // key -> position
  for (std::size_t i = 0; i < tiles.size(); ++i) index.emplace(tileKey(tiles[i]), i);
  for (const Tile& t : add) {
    if (auto r = fits(t, next, what); !r) return r;
    auto it = index.find(tileKey(t));
    if (it != index.end()) {
      tiles[it->second] = t;
    } else {
      index.emplace(tileKey(t), tiles.size());
      tiles.push_back(t);
    }
  }
  return {};
}

// The tiles of `after` that a delta must carry (into `out`); false when a
// delta cannot say it: a (cell, layer) of `before` whose layer stays is gone,
// or the level moves with no tile to carry it.
template <class Tile>
bool diffTiles(const std::vector<Tile>& before, const std::vector<Tile>& after, int beforeLevel, int afterLevel,
               const std::vector<std::uint32_t>& removedLayerIds, std::vector<Tile>& out) {
  // Fast path: the same tiles in the same order (one area, one covering).
  const bool sameOrder = before.size() == after.size() && removedLayerIds.empty() &&
                         std::equal(before.begin(), before.end(), after.begin(),
                                    [](const Tile& a, const Tile& b) { return tileKey(a) == tileKey(b); });
  if (sameOrder) {
    for (std::size_t i = 0; i < after.size(); ++i)
      if (!(before[i] == after[i])) out.push_back(after[i]);
    return !(out.empty() && beforeLevel != afterLevel);
  }
  std::map<std::pair<std::uint64_t, std::uint32_t>, const Tile*> was;
  for (const Tile& t : before) was[tileKey(t)] = &t;
  std::size_t matched = 0;
  for (const Tile& t : after) {
    const auto it = was.find(tileKey(t));
    if (it == was.end()) {
      out.push_back(t);
      continue;
    }
    ++matched;
    if (!(*it->second == t)) out.push_back(t);
  }
  std::size_t kept = 0;  // tiles of `before` whose layer is not removed
  for (const Tile& t : before)
    if (std::none_of(removedLayerIds.begin(), removedLayerIds.end(),
                     [&](std::uint32_t id) { return goesWithLayer(t, id); }))
      ++kept;
  if (matched != kept) return false;  // a tile (or a layer's tiles) went away
  // With no tiles the delta cannot move the snapshot's level.
  return !(out.empty() && beforeLevel != afterLevel);
}

}  // namespace

std::int16_t quantizeWind(double mps, double limit_mps) {
  if (!std::isfinite(mps)) return 0;
  return static_cast<std::int16_t>(std::lround(std::clamp(mps, -limit_mps, limit_mps) * 100.0));
}

WindTile quantized(const WindTile& tile) {
  WindTile t = tile;
  t.east_mps = dequantizeWind(quantizeWind(tile.east_mps, 150));
  t.north_mps = dequantizeWind(quantizeWind(tile.north_mps, 150));
  t.up_mps = dequantizeWind(quantizeWind(tile.up_mps, 50));
  return t;
}

AirTile quantizedAir(const AirTile& tile) {
  AirTile t = tile;
  const double c = std::isfinite(tile.temperature_c)
                       ? std::clamp(double(tile.temperature_c), kMinAirTemperature_c, kMaxAirTemperature_c)
                       : 0.0;
  t.temperature_c = static_cast<float>(static_cast<double>(std::lround(c * 10.0)) / 10.0);
  if (std::isfinite(tile.humidity_pct) && tile.humidity_pct >= 0)
    t.humidity_pct = static_cast<float>(static_cast<double>(std::lround(std::min(double(tile.humidity_pct), 100.0) * 2.0)) / 2.0);
  else
    t.humidity_pct = kNoHumidity;
  return t;
}

std::uint8_t quantizeUnit(double v) {
  if (!(v > 0)) return 0;
  if (v >= 1) return 255;
  return static_cast<std::uint8_t>(std::lround(v * 255.0));
}

Result<void> applyDelta(WeatherSnapshot& snapshot, const WeatherDelta& delta) {
  if (delta.areaIndex != snapshot.areaIndex)
    return fail(ErrorCode::InvalidArgument, "delta for area " + std::to_string(delta.areaIndex) +
                                                " applied to the snapshot of area " + std::to_string(snapshot.areaIndex));
  WeatherSnapshot next = snapshot;  // all or nothing
  next.weatherClock_s = delta.weatherClock_s;
  for (const CloudLayer& layer : delta.layers) {
    auto it = std::find_if(next.layers.begin(), next.layers.end(),
                           [&](const CloudLayer& l) { return l.id == layer.id; });
    if (it != next.layers.end())
      *it = layer;
    else
      next.layers.push_back(layer);
  }
  for (std::uint32_t id : delta.removedLayerIds) {
    auto it = std::find_if(next.layers.begin(), next.layers.end(),
                           [&](const CloudLayer& l) { return l.id == id; });
    if (it == next.layers.end())
      return fail(ErrorCode::InvalidArgument, "delta removes layer " + std::to_string(id) + ", which does not exist");
    next.layers.erase(it);
    std::erase_if(next.tiles, [&](const CoverageTile& t) { return t.layerId == id; });
    std::erase_if(next.windTiles, [&](const WindTile& t) { return t.layerId == id; });
  }
  if (auto r = upsertTiles(next.tiles, next.tileLevel, delta.tiles, delta.tileLevel, next, "tile"); !r) return r;
  if (auto r = upsertTiles(next.windTiles, next.windTileLevel, delta.windTiles, delta.windTileLevel, next, "wind tile");
      !r)
    return r;
  if (auto r = upsertTiles(next.airTiles, next.airTileLevel, delta.airTiles, delta.airTileLevel, next, "air tile"); !r)
    return r;
  if (const std::size_t n = next.tiles.size() + next.windTiles.size() + next.airTiles.size(); n > kMaxSnapshotTiles)
    return fail(ErrorCode::TooLarge, "delta would grow the snapshot to " + std::to_string(n) + " tiles, more than " +
                                         std::to_string(kMaxSnapshotTiles));
  snapshot = std::move(next);
  return {};
}

std::optional<WeatherDelta> diffSnapshots(const WeatherSnapshot& before, const WeatherSnapshot& after) {
  WeatherDelta d;
  d.weatherClock_s = after.weatherClock_s;
  d.tileLevel = after.tileLevel;
  d.areaIndex = after.areaIndex;
  if (before.areaIndex != after.areaIndex) return std::nullopt;
  if (!before.tiles.empty() && !after.tiles.empty() && before.tileLevel != after.tileLevel) return std::nullopt;
  if (!before.windTiles.empty() && !after.windTiles.empty() && before.windTileLevel != after.windTileLevel)
    return std::nullopt;
  d.windTileLevel = after.windTileLevel;
  if (!before.airTiles.empty() && !after.airTiles.empty() && before.airTileLevel != after.airTileLevel)
    return std::nullopt;
  // A delta's air tiles index the snapshot's air levels: other levels, a snapshot.
  if (before.airLevels_m != after.airLevels_m) return std::nullopt;
  d.airTileLevel = after.airTileLevel;
  // Layers: the ones kept must stay in their order, new ones come last.
  std::vector<std::uint32_t> kept;
  for (const CloudLayer& b : before.layers) {
    const auto it = std::find_if(after.layers.begin(), after.layers.end(),
                                 [&](const CloudLayer& l) { return l.id == b.id; });
    if (it == after.layers.end())
      d.removedLayerIds.push_back(b.id);
    else
      kept.push_back(b.id);
  }
  for (std::size_t i = 0; i < after.layers.size(); ++i) {
    const CloudLayer& a = after.layers[i];
    if (i < kept.size()) {
      if (a.id != kept[i]) return std::nullopt;  // reordered
      const auto b = std::find_if(before.layers.begin(), before.layers.end(),
                                  [&](const CloudLayer& l) { return l.id == a.id; });
      const bool same = b->type == a.type && b->base_m == a.base_m && b->thickness_m == a.thickness_m &&
                        b->transitionBand_m == a.transitionBand_m && b->coverage == a.coverage &&
                        b->density == a.density && b->wind.speed_mps == a.wind.speed_mps &&
                        b->wind.fromDirection_deg == a.wind.fromDirection_deg &&
                        b->wind.vertical_mps == a.wind.vertical_mps && b->tilesDrift == a.tilesDrift;
      if (!same) d.layers.push_back(a);
    } else {
      d.layers.push_back(a);
    }
  }
  if (!diffTiles(before.tiles, after.tiles, before.tileLevel, after.tileLevel, d.removedLayerIds, d.tiles))
    return std::nullopt;
  if (!diffTiles(before.windTiles, after.windTiles, before.windTileLevel, after.windTileLevel, d.removedLayerIds,
                 d.windTiles))
    return std::nullopt;
  if (!diffTiles(before.airTiles, after.airTiles, before.airTileLevel, after.airTileLevel, d.removedLayerIds,
                 d.airTiles))
    return std::nullopt;
  return d;
}

}  // namespace sky::weather
