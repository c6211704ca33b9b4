// Per-tile updates of the weather map (see weather_field_update.hpp).
#include "weather_field_update.hpp"

#include <algorithm>
#include <array>
#include <cstdlib>
#include <numeric>

#include "sky/core/assert.hpp"

namespace sky::render {

namespace {

// The layer fields the map is made of; base, thickness and wind move and
// shape the clouds but leave the map alone.
bool sameMapLayers(const std::vector<weather::CloudLayer>& a, const std::vector<weather::CloudLayer>& b) {
  return std::equal(a.begin(), a.end(), b.begin(), b.end(), [](const auto& x, const auto& y) {
    return x.id == y.id && x.type == y.type && x.coverage == y.coverage && x.density == y.density;
  });
}

std::uint64_t allTexels(const WeatherField& f) {
  return std::uint64_t(kWeatherRings) * f.sliceCount * f.size * f.size;
}

}  // namespace

std::span<const std::uint32_t> WeatherFieldUpdater::CellTexels::texelsOf(std::uint64_t cell) const {
  const auto it = std::lower_bound(cells.begin(), cells.end(), cell);
  if (it == cells.end() || *it != cell) return {};
  const std::size_t k = std::size_t(it - cells.begin());
  return std::span(texels).subspan(start[k], start[k + 1] - start[k]);
}

WeatherFieldUpdater::WeatherFieldUpdater() : field_(buildWeatherField(nullptr, geo::Geodetic{})) {
  tiles_ = indexWeatherTiles(nullptr, nullptr);
  keys_ = weatherKeys(nullptr, nullptr);
}

void WeatherFieldUpdater::indexCells(std::uint32_t ring) {
  CellTexels& index = index_[ring];
  const int level = field_.cellLevel[ring];
  SKY_ASSERT(level >= 0 && field_.cells[ring].size() == std::size_t(field_.size) * field_.size);
  if (index.built && index.level == level && sameAnchor(index.anchor, field_.anchor)) return;
  const std::vector<std::uint64_t>& cells = field_.cells[ring];
  index.texels.resize(cells.size());
  std::iota(index.texels.begin(), index.texels.end(), 0u);
  std::sort(index.texels.begin(), index.texels.end(), [&](std::uint32_t a, std::uint32_t b) {
    return cells[a] != cells[b] ? cells[a] < cells[b] : a < b;
  });
  index.cells.clear();
  index.start.clear();
  for (std::uint32_t k = 0; k < index.texels.size(); ++k)
    if (k == 0 || cells[index.texels[k]] != index.cells.back()) {
      index.cells.push_back(cells[index.texels[k]]);
      index.start.push_back(k);
    }
  index.start.push_back(static_cast<std::uint32_t>(index.texels.size()));
  index.built = true;
  index.level = level;
  index.anchor = field_.anchor;
}

std::string WeatherFieldUpdater::snapshotReason(const weather::WeatherSnapshot* fine,
                                                const weather::WeatherSnapshot* coarse,
                                                const geo::Geodetic& anchor) const {
  if (!built_) return "first map";
  if (!sameAnchor(field_.anchor, anchor)) return "anchor moved";
  // No weather before or now: a different map only through these.
  if (fine == nullptr || !hadFine_) return "weather appeared or went away";
  if ((coarse != nullptr) != hadCoarse_) return "coarse weather appeared or went away";
  if (!sameMapLayers(fine->layers, layers_)) return "layers changed";
  const std::array<int, kWeatherRings> level{fine->tileLevel, coarse != nullptr ? coarse->tileLevel : fine->tileLevel};
  if (level != tiles_.level) return "tile level changed";
  return {};
}

std::string WeatherFieldUpdater::tileReason(const WeatherTiles& next, const std::array<bool, kWeatherRings>& unchanged,
                                            std::vector<ChangedTile>* changes) const {
  if (next.duplicates()) return "a cell named twice in one snapshot";
  if (next.blendType != tiles_.blendType) return "blend type of a slice changed";
  // (tiles_.slices() may be gone: a reused ring was moved out of tiles_.)
  SKY_ASSERT(next.ringsShare == tiles_.ringsShare && next.slices() == layers_.size());
  const std::uint32_t sources = next.ringsShare ? 1 : kWeatherRings;
  for (std::uint32_t ring = 0; ring < sources; ++ring) {
    if (unchanged[ring]) continue;  // its snapshot's tiles are the ones the map holds
    for (std::size_t s = 0; s < next.slices(); ++s) {
      const SliceTiles& now = next.tiles(ring, s);
      const SliceTiles& before = tiles_.tiles(ring, s);
      // A uniform slice becoming tiled (or back) changes every texel of it.
      if (now.empty() != before.empty()) return "a layer gained or lost its tiles";
      std::size_t kept = 0;
      for (const auto& [cell, value] : now) {
        const auto it = before.find(cell);
        if (it != before.end()) ++kept;
        if (it == before.end() || !(it->second == value))
          changes->push_back({ring, std::uint32_t(s), cell, value});
      }
      // Every old tile is still there exactly when all were matched.
      if (kept != before.size()) return "a tile removed";
    }
  }
  return {};
}

WeatherFieldChange WeatherFieldUpdater::update(const weather::WeatherSnapshot* fine,
                                               const weather::WeatherSnapshot* coarse, const geo::Geodetic& anchor,
                                               std::optional<std::uint64_t> version) {
  WeatherFieldChange change;
  if (built_ && version && version == version_ && sameAnchor(field_.anchor, anchor)) return change;
  version_ = version;
  const WeatherKeys keys = weatherKeys(fine, coarse);
  const std::uint64_t windKey = weatherWindKey(fine, coarse);
  if (built_ && keys.content == field_.contentKey && sameAnchor(field_.anchor, anchor)) {
    if (windKey != field_.windKey) rewriteWind(fine, coarse, change);
    return change;
  }

  change.reason = snapshotReason(fine, coarse, anchor);
  // A snapshot whose tiles are the ones the map was filled from keeps its
  // sorted tiles (moved out of tiles_, which `next` replaces either way):
  // a change of the fine snapshot does not sort the coarse one's again.
  std::array<bool, kWeatherRings> unchanged{};
  WeatherTiles next;
  if (fine == nullptr) {
    next = indexWeatherTiles(nullptr, nullptr);
  } else {
    const bool perTile = change.reason.empty();
    unchanged = {perTile && keys.fineTiles == keys_.fineTiles,
                 perTile && coarse != nullptr && keys.coarseTiles == keys_.coarseTiles};
    RingTiles fineRing = unchanged[0] ? std::move(tiles_.rings[0]) : indexRingTiles(*fine, fine->layers);
    RingTiles coarseRing = coarse == nullptr ? RingTiles{}
                           : unchanged[1]    ? std::move(tiles_.rings[1])
                                             : indexRingTiles(*coarse, fine->layers);
    next = combineWeatherTiles(*fine, coarse, std::move(fineRing), std::move(coarseRing));
  }
  std::vector<ChangedTile> changes;
  if (change.reason.empty()) change.reason = tileReason(next, unchanged, &changes);
  keys_ = keys;
  if (!change.reason.empty()) {
    // At the same anchor and level the texels' cells are reused (no geodesy).
    field_ = buildWeatherField(next, fine, coarse, anchor, built_ ? &field_ : nullptr);
    tiles_ = std::move(next);
    layers_ = fine != nullptr ? fine->layers : std::vector<weather::CloudLayer>{};
    built_ = true;
    hadFine_ = fine != nullptr;
    hadCoarse_ = coarse != nullptr;
    // The index now, while a rebuild costs far more, so the next tile
    // update costs only its own texels.
    for (std::uint32_t ring = 0; ring < kWeatherRings; ++ring)
      if (field_.cellLevel[ring] >= 0) indexCells(ring);
    change.kind = WeatherFieldChange::Kind::Rebuilt;
    change.texelsRewritten = allTexels(field_);
    return change;
  }

  change.kind = WeatherFieldChange::Kind::Tiles;
  struct Bounds {
    std::uint32_t x0 = ~0u, y0 = ~0u, x1 = 0, y1 = 0;  // inclusive
  };
  std::vector<Bounds> bounds(std::size_t(kWeatherRings) * field_.sliceCount);
  for (const ChangedTile& t : changes) {
    // With shared tiles a fine tile is ring 1's too.
    const std::uint32_t lastRing = next.ringsShare ? kWeatherRings - 1 : t.ring;
    for (std::uint32_t ring = t.ring; ring <= lastRing; ++ring) {
      indexCells(ring);
      Bounds& b = bounds[std::size_t(ring) * field_.sliceCount + t.slice];
      const std::size_t sliceBase =
          (std::size_t(ring) * field_.sliceCount + t.slice) * std::size_t(field_.size) * field_.size;
      for (const std::uint32_t texel : index_[ring].texelsOf(t.cell)) {
        const std::uint8_t* at = &field_.texels[(sliceBase + texel) * kWeatherChannels];
        const std::array<std::uint8_t, 3> before{at[0], at[1], at[2]};
        writeWeatherTexel(field_, ring, t.slice, texel, t.value);
        for (std::size_t c = 0; c < before.size(); ++c)
          change.largestStep = std::max<std::uint32_t>(change.largestStep, std::uint32_t(std::abs(int(at[c]) - int(before[c]))));
        const std::uint32_t x = texel % field_.size, y = texel / field_.size;
        b = {std::min(b.x0, x), std::min(b.y0, y), std::max(b.x1, x), std::max(b.y1, y)};
        ++change.texelsRewritten;
      }
    }
  }
  for (std::uint32_t layer = 0; layer < bounds.size(); ++layer)
    if (const Bounds& b = bounds[layer]; b.x0 <= b.x1)
      change.dirty.push_back({layer, b.x0, b.y0, b.x1 - b.x0 + 1, b.y1 - b.y0 + 1});
  field_.contentKey = keys.content;
  tiles_ = std::move(next);
  if (windKey != field_.windKey) rewriteWind(fine, coarse, change);
  return change;
}

void WeatherFieldUpdater::rewriteWind(const weather::WeatherSnapshot* fine, const weather::WeatherSnapshot* coarse,
                                      WeatherFieldChange& change) {
  writeWindTexels(field_, fine, coarse);
  change.kind = WeatherFieldChange::Kind::Tiles;
  for (std::uint32_t ring = 0; ring < kWeatherRings; ++ring)
    for (std::uint32_t s = 0; s < field_.sliceCount; ++s) {
      change.windDirty.push_back({gpu::kWindMapLayers + ring * field_.sliceCount + s, 0, 0, field_.size, field_.size});
      change.texelsRewritten += std::uint64_t(field_.size) * field_.size;
    }
}

}  // namespace sky::render
