// Weather-map construction from S2 coverage tiles (see weather_field.hpp).
#include "weather_field.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <unordered_map>

#include <glm/glm.hpp>

#include "core_common.hpp"
#include "sky/core/assert.hpp"
#include "sky/weather/tiling.hpp"
#include "sky/weather/wind_field.hpp"
#include "sky_shared.h"

namespace sky::render {

namespace {

constexpr std::size_t kChannels = kWeatherChannels;

void mix64(std::uint64_t& h, std::uint64_t v) {
  // A word at a time (a multiply by the 64-bit golden ratio and a shift to
  // bring the high bits down): the keys are computed every frame over every
  // tile of both snapshots (tens of thousands), and only tell "same" from
  // "changed", so speed matters more than a cryptographic spread. Bytewise
  // FNV-1a took ~1 ms per frame for 17k tiles.
  h = (h ^ v) * 0x9e3779b97f4a7c15ull;
  h ^= h >> 29;
}

std::uint64_t bitsOf(double d) {
  std::uint64_t u = 0;
  std::memcpy(&u, &d, sizeof u);
  return u;
}

}  // namespace

double ringBlendWeight(double x_m, double y_m) {
  return CoreCommon{}.ringBlendWeight(glm::dvec2(x_m, y_m), 1.0 / kWeatherRingHalfExtent_m[0], kRingBlendStart,
                                      kRingBlendEnd);
}

glm::dvec3 WeatherField::sample(std::uint32_t slice, double x_m, double y_m) const {
  SKY_ASSERT(slice < sliceCount);
  return glm::dvec3(sampleLayer(slice, x_m, y_m));
}

glm::dvec3 WeatherField::sampleRing(std::uint32_t ring, std::uint32_t slice, double x_m, double y_m) const {
  SKY_ASSERT(slice < sliceCount && ring < kWeatherRings);
  return glm::dvec3(sampleTexels(std::size_t(ring) * sliceCount + slice, halfExtent_m[ring], x_m, y_m));
}

glm::dvec4 WeatherField::sampleLayer(std::uint32_t fineLayer, double x_m, double y_m) const {
  const double w = ringBlendWeight(x_m, y_m);
  glm::dvec4 v(0);
  if (w < 1) v = sampleTexels(fineLayer, halfExtent_m[0], x_m, y_m);
  if (w > 0) v += w * (sampleTexels(fineLayer + sliceCount, halfExtent_m[1], x_m, y_m) - v);
  return v;
}

glm::dvec4 WeatherField::sampleTexels(std::size_t layer, double halfExtent, double x_m, double y_m) const {
  const int n = static_cast<int>(size);
  const double tx = (x_m / (2 * halfExtent) + 0.5) * size - 0.5;
  const double ty = (y_m / (2 * halfExtent) + 0.5) * size - 0.5;
  if (!(std::abs(tx) < 2.0 * size && std::abs(ty) < 2.0 * size)) return {0, 0, 0, 0};  // far outside, or NaN
  if (layer * size * size * kChannels >= texels.size()) return {0, 0, 0, 0};
  const double fx = std::floor(tx), fy = std::floor(ty);
  const int i0 = static_cast<int>(fx), j0 = static_cast<int>(fy);
  const double ax = tx - fx, ay = ty - fy;
  glm::dvec4 sum(0);
  for (int dj = 0; dj <= 1; ++dj)
    for (int di = 0; di <= 1; ++di) {
      const int i = i0 + di, j = j0 + dj;
      if (i < 0 || j < 0 || i >= n || j >= n) continue;
      const std::size_t idx = ((layer * size + std::size_t(j)) * size + std::size_t(i)) * kChannels;
      const double w = (di ? ax : 1 - ax) * (dj ? ay : 1 - ay);
      sum += w * glm::dvec4(texels[idx], texels[idx + 1], texels[idx + 2], texels[idx + 3]) / 255.0;
    }
  return sum;
}

namespace {

std::uint64_t tilesKey(const weather::WeatherSnapshot& snapshot) {
  std::uint64_t h = 14695981039346656037ull;
  mix64(h, static_cast<std::uint64_t>(snapshot.tileLevel));
  mix64(h, snapshot.tiles.size());
  for (const auto& tile : snapshot.tiles) {
    mix64(h, tile.cellId);
    mix64(h, tile.layerId);
    mix64(h, bitsOf(tile.coverage));
    mix64(h, bitsOf(tile.density));
    mix64(h, static_cast<std::uint64_t>(tile.blendType));
    mix64(h, bitsOf(tile.blend));
  }
  return h;
}

// A layer as the map sees it: its id, type, and uniform coverage and density.
void mixLayerContent(std::uint64_t& h, const weather::CloudLayer& layer) {
  mix64(h, layer.id);
  mix64(h, static_cast<std::uint64_t>(layer.type));
  mix64(h, bitsOf(layer.coverage));
  mix64(h, bitsOf(layer.density));
}

// Marks the start of the coarse snapshot's part of a key, so that tiles
// moved from one snapshot to the other change it.
constexpr std::uint64_t kCoarseKeyMarker = 0x636f6172736552ull;  // "coarseR"

}  // namespace

WeatherKeys weatherKeys(const weather::WeatherSnapshot* snapshot, const weather::WeatherSnapshot* coarse) {
  WeatherKeys k;
  std::uint64_t h = 14695981039346656037ull;
  k.content = h;
  if (snapshot == nullptr) return k;
  mix64(h, snapshot->layers.size());
  for (const auto& layer : snapshot->layers) mixLayerContent(h, layer);
  k.fineTiles = tilesKey(*snapshot);
  mix64(h, k.fineTiles);
  // Only the coarse snapshot's tiles and level reach the map (its layers'
  // own numbers never do), so only they enter the key: a change of a coarse
  // layer's wind does not drop an interleaved renderer's history.
  if (coarse != nullptr) {
    k.coarseTiles = tilesKey(*coarse);
    mix64(h, kCoarseKeyMarker);
    mix64(h, k.coarseTiles);
  }
  k.content = h;
  return k;
}

std::uint64_t weatherContentKey(const weather::WeatherSnapshot* snapshot, const weather::WeatherSnapshot* coarse) {
  return weatherKeys(snapshot, coarse).content;
}

std::uint64_t weatherStructureKey(const weather::WeatherSnapshot* snapshot, const weather::WeatherSnapshot* coarse) {
  std::uint64_t h = 14695981039346656037ull;
  if (snapshot == nullptr) return h;
  mix64(h, snapshot->layers.size());
  for (const auto& layer : snapshot->layers) {
    mixLayerContent(h, layer);
    mix64(h, bitsOf(layer.base_m));
    mix64(h, bitsOf(layer.thickness_m));
    mix64(h, bitsOf(layer.transitionBand_m));
    mix64(h, bitsOf(layer.wind.speed_mps));
    mix64(h, bitsOf(layer.wind.fromDirection_deg));
    mix64(h, bitsOf(layer.wind.vertical_mps));
  }
  // Whether each layer has tiles at all: a layer going from uniform to
  // tiled (or back) changes it everywhere.
  mix64(h, static_cast<std::uint64_t>(snapshot->tileLevel));
  std::vector<std::uint32_t> tiled;
  for (const auto& tile : snapshot->tiles)
    if (std::find(tiled.begin(), tiled.end(), tile.layerId) == tiled.end()) tiled.push_back(tile.layerId);
  std::sort(tiled.begin(), tiled.end());
  for (std::uint32_t id : tiled) mix64(h, id);
  if (coarse != nullptr) {
    mix64(h, kCoarseKeyMarker);
    mix64(h, static_cast<std::uint64_t>(coarse->tileLevel));
  }
  // Which layers have a wind field (their noise flows, their tiles move
  // point by point): not the winds' values, which move clouds smoothly.
  for (const weather::WeatherSnapshot* s : {snapshot, coarse}) {
    if (s == nullptr) continue;
    std::vector<std::uint32_t> windy;
    for (const auto& t : s->windTiles)
      if (std::find(windy.begin(), windy.end(), t.layerId) == windy.end()) windy.push_back(t.layerId);
    std::sort(windy.begin(), windy.end());
    mix64(h, windy.size());
    for (std::uint32_t id : windy) mix64(h, id);
  }
  return h;
}

bool WeatherTiles::ringTiled(std::uint32_t ring) const {
  for (std::size_t s = 0; s < slices(); ++s)
    if (!tiles(ring, s).empty()) return true;
  return false;
}

RingTiles indexRingTiles(const weather::WeatherSnapshot& source, const std::vector<weather::CloudLayer>& layers) {
  RingTiles out;
  out.bySlice.resize(layers.size());
  out.blendWeight.resize(layers.size());
  for (const auto& tile : source.tiles)
    for (std::size_t s = 0; s < layers.size(); ++s)
      if (layers[s].id == tile.layerId) {
        const TileValue value{tile.coverage, tile.density, tile.blendType, tile.blend};
        if (!out.bySlice[s].insert_or_assign(tile.cellId, value).second) out.duplicates = true;
        const auto type = static_cast<std::size_t>(tile.blendType);
        if (tile.blend > 0 && type > 0 && type < out.blendWeight[s].size() && tile.blendType != layers[s].type)
          out.blendWeight[s][type] += tile.blend;
      }
  return out;
}

WeatherTiles combineWeatherTiles(const weather::WeatherSnapshot& fine, const weather::WeatherSnapshot* coarse,
                                 RingTiles fineRing, RingTiles coarseRing) {
  SKY_ASSERT(fine.layers.size() <= gpu::kMaxLayers && fineRing.bySlice.size() == fine.layers.size());
  WeatherTiles out;
  out.blendType.fill(weather::CloudType::None);
  out.tiled.fill(false);
  out.ringsShare = coarse == nullptr;
  out.level = {fine.tileLevel, coarse != nullptr ? coarse->tileLevel : fine.tileLevel};
  out.rings[0] = std::move(fineRing);
  if (!out.ringsShare) {
    SKY_ASSERT(coarseRing.bySlice.size() == fine.layers.size());
    out.rings[1] = std::move(coarseRing);
  }
  for (std::size_t s = 0; s < fine.layers.size(); ++s) {
    out.tiled[s] = !out.tiles(0, s).empty() || !out.tiles(1, s).empty();
    // Each ring's sum, then the two added: without a coarse snapshot the
    // fine ring's sums alone, as they always were.
    std::array<double, weather::kMaxCloudType + 1> weight = out.rings[0].blendWeight[s];
    if (!out.ringsShare)
      for (std::size_t type = 0; type < weight.size(); ++type) weight[type] += out.rings[1].blendWeight[s][type];
    double best = 0;
    for (std::size_t type = 1; type < weight.size(); ++type)
      if (weight[type] > best) {
        best = weight[type];
        out.blendType[s] = static_cast<weather::CloudType>(type);
      }
  }
  return out;
}

WeatherTiles indexWeatherTiles(const weather::WeatherSnapshot* fine, const weather::WeatherSnapshot* coarse) {
  if (fine == nullptr) {
    WeatherTiles none;
    none.blendType.fill(weather::CloudType::None);
    none.tiled.fill(false);
    return none;
  }
  SKY_ASSERT(fine->layers.size() <= gpu::kMaxLayers);
  return combineWeatherTiles(*fine, coarse, indexRingTiles(*fine, fine->layers),
                             coarse != nullptr ? indexRingTiles(*coarse, fine->layers) : RingTiles{});
}

void writeWeatherTexel(WeatherField& field, std::uint32_t ring, std::size_t slice, std::size_t texel,
                       const TileValue& v) {
  const std::size_t sliceTexels = std::size_t(field.size) * field.size;
  const std::size_t idx = ((ring * field.sliceCount + slice) * sliceTexels + texel) * kChannels;
  const float blend = v.blendType == field.blendType[slice] ? std::clamp(v.blend, 0.0f, 1.0f) : 0.0f;
  field.texels[idx] = weather::quantizeUnit(v.coverage);
  field.texels[idx + 1] = weather::quantizeUnit(v.density);
  field.texels[idx + 2] = weather::quantizeUnit(blend);
}

WeatherField buildWeatherField(const weather::WeatherSnapshot* snapshot, const geo::Geodetic& anchor,
                               const WeatherField* previous) {
  return buildWeatherField(snapshot, nullptr, anchor, previous);
}

WeatherField buildWeatherField(const weather::WeatherSnapshot* snapshot, const weather::WeatherSnapshot* coarse,
                               const geo::Geodetic& anchor, const WeatherField* previous) {
  return buildWeatherField(indexWeatherTiles(snapshot, coarse), snapshot, coarse, anchor, previous);
}

WeatherField buildWeatherField(const WeatherTiles& tiles, const weather::WeatherSnapshot* snapshot,
                               const weather::WeatherSnapshot* coarse, const geo::Geodetic& anchor,
                               const WeatherField* previous) {
  WeatherField field;
  field.anchor = anchor;
  field.frame = geo::enuFrameAt(anchor);
  field.anchorAlt_m = anchor.alt_m;
  field.radius_m = geo::length(field.frame.originEcef_m);
  field.centreEcef_m = field.frame.originEcef_m - field.frame.up * field.radius_m;
  field.sliceCount = gpu::kMaxLayers;
  field.contentKey = weatherContentKey(snapshot, coarse);
  const std::size_t sliceTexels = std::size_t(field.size) * field.size;
  // Cover, then wind: two layers of texture per ring and slice.
  field.texels.assign(2 * sliceTexels * field.sliceCount * kWeatherRings * kChannels, 0);
  field.blendType = tiles.blendType;
  field.tiled = tiles.tiled;
  if (snapshot == nullptr) return field;

  const bool sameAnchorAsPrevious = previous != nullptr && sameAnchor(previous->anchor, anchor);
  const double groundRadius_m = field.radius_m - anchor.alt_m;
  for (std::uint32_t ring = 0; ring < kWeatherRings; ++ring) {
    // A ring whose slices are all uniform needs no cells.
    const bool needsCells = tiles.ringTiled(ring);
    const bool reuse = needsCells && sameAnchorAsPrevious && previous->cellLevel[ring] == tiles.level[ring] &&
                       previous->cells[ring].size() == sliceTexels;
    std::vector<std::uint64_t>& cells = field.cells[ring];
    if (needsCells) {
      field.cellLevel[ring] = tiles.level[ring];
      if (reuse)
        cells = previous->cells[ring];
      else
        cells.assign(sliceTexels, 0);
    }
    for (std::uint32_t j = 0; j < field.size; ++j)
      for (std::uint32_t i = 0; i < field.size; ++i) {
        const std::size_t texel = std::size_t(j) * field.size + i;
        std::uint64_t cell = 0;
        if (reuse) {
          cell = cells[texel];
        } else if (needsCells) {
          // Inverse gnomonic: the direction from the sphere centre through the
          // plane point, down to the ground on the anchor sphere. The coarse
          // ring takes the tile at its texel's centre.
          const double x_m = ((i + 0.5) / field.size - 0.5) * 2 * field.halfExtent_m[ring];
          const double y_m = ((j + 0.5) / field.size - 0.5) * 2 * field.halfExtent_m[ring];
          const geo::Vec3d dir = geo::normalize(field.frame.east * x_m + field.frame.north * y_m +
                                                field.frame.up * field.radius_m);
          const geo::Geodetic g = geo::fromEcef(field.centreEcef_m + dir * groundRadius_m);
          cell = weather::cellAt(g.lat_deg, g.lon_deg, tiles.level[ring]);
          cells[texel] = cell;
        }
        for (std::size_t s = 0; s < tiles.slices(); ++s) {
          const auto& layer = snapshot->layers[s];
          const SliceTiles& sliceTiles = tiles.tiles(ring, s);
          TileValue v{static_cast<float>(layer.coverage), static_cast<float>(layer.density)};
          if (!sliceTiles.empty()) {
            const auto it = sliceTiles.find(cell);
            v = it == sliceTiles.end() ? TileValue{} : it->second;
          }
          writeWeatherTexel(field, ring, s, texel, v);
        }
      }
  }
  writeWindTexels(field, snapshot, coarse);
  return field;
}

std::array<std::uint8_t, 2> encodeWindComponent(double mps) {
  const double scale = gpu::kWindMapScale_mps;
  const double f = std::clamp(std::isfinite(mps) ? mps / scale : 0.0, -1.0, 1.0);
  const auto q = static_cast<std::uint32_t>(std::lround((f + 1) / 2 * 65535));
  return {static_cast<std::uint8_t>(q >> 8), static_cast<std::uint8_t>(q & 0xff)};
}

std::uint64_t weatherWindKey(const weather::WeatherSnapshot* fine, const weather::WeatherSnapshot* coarse) {
  std::uint64_t h = 14695981039346656037ull;
  for (const weather::WeatherSnapshot* s : {fine, coarse}) {
    mix64(h, s == nullptr ? 0 : 1);
    if (s == nullptr) continue;
    mix64(h, static_cast<std::uint64_t>(s->windTileLevel));
    mix64(h, s->windTiles.size());
    for (const auto& t : s->windTiles) {
      mix64(h, t.cellId);
      mix64(h, t.layerId);
      std::uint32_t bits[3];
      std::memcpy(&bits[0], &t.east_mps, 4);
      std::memcpy(&bits[1], &t.north_mps, 4);
      std::memcpy(&bits[2], &t.up_mps, 4);
      mix64(h, (std::uint64_t(bits[0]) << 32) | bits[1]);
      mix64(h, bits[2]);
    }
  }
  return h;
}

void writeWindTexels(WeatherField& field, const weather::WeatherSnapshot* fine, const weather::WeatherSnapshot* coarse) {
  field.windVaries.fill(false);
  field.windKey = weatherWindKey(fine, coarse);
  const std::size_t sliceTexels = std::size_t(field.size) * field.size;
  const std::size_t windBase = std::size_t(gpu::kWindMapLayers) * sliceTexels * kChannels;
  std::fill(field.texels.begin() + std::ptrdiff_t(windBase), field.texels.end(), std::uint8_t(0));
  if (fine == nullptr) return;
  const weather::WindField fineWind(*fine);
  const weather::WindField coarseWind = coarse != nullptr ? weather::WindField(*coarse) : weather::WindField();
  const std::uint32_t n = field.size;
  const std::uint32_t nodes = (n + kWindLattice - 1) / kWindLattice + 1;  // every kWindLattice-th texel and the last
  const double groundRadius_m = field.radius_m - field.anchorAlt_m;
  std::vector<glm::dvec2> node(std::size_t(nodes) * nodes);
  for (std::size_t s = 0; s < fine->layers.size() && s < field.sliceCount; ++s) {
    const weather::CloudLayer& layer = fine->layers[s];
    const bool fineVaries = fineWind.varies(layer.id), coarseVaries = coarse != nullptr && coarseWind.varies(layer.id);
    if (!fineVaries && !coarseVaries) continue;
    field.windVaries[s] = true;
    for (std::uint32_t ring = 0; ring < kWeatherRings; ++ring) {
      const weather::WindField& wind = ring == 1 && coarse != nullptr ? coarseWind : fineWind;
      // The wind at the lattice's texel centres, in the anchor's east/north
      // (the map plane's axes; the gnomonic plane's scale is within 1 % of
      // the ground's over the rings).
      auto texelOf = [&](std::uint32_t k) { return std::min(k * kWindLattice, n - 1); };
      for (std::uint32_t b = 0; b < nodes; ++b)
        for (std::uint32_t a = 0; a < nodes; ++a) {
          const double x_m = ((texelOf(a) + 0.5) / n - 0.5) * 2 * field.halfExtent_m[ring];
          const double y_m = ((texelOf(b) + 0.5) / n - 0.5) * 2 * field.halfExtent_m[ring];
          const geo::Vec3d dir =
              geo::normalize(field.frame.east * x_m + field.frame.north * y_m + field.frame.up * field.radius_m);
          const geo::Geodetic g = geo::fromEcef(field.centreEcef_m + dir * groundRadius_m);
          const weather::WindVector v = wind.at(layer, g.lat_deg, g.lon_deg);
          const geo::EnuFrame there = geo::enuFrameAt(g);
          const geo::Vec3d ecef = there.east * v.east_mps + there.north * v.north_mps;
          node[std::size_t(b) * nodes + a] = {geo::dot(ecef, field.frame.east), geo::dot(ecef, field.frame.north)};
        }
      const std::size_t layerBase = (std::size_t(gpu::kWindMapLayers) + std::size_t(ring) * field.sliceCount + s) * sliceTexels;
      for (std::uint32_t j = 0; j < n; ++j)
        for (std::uint32_t i = 0; i < n; ++i) {
          const std::uint32_t a = std::min(i / kWindLattice, nodes - 2), b = std::min(j / kWindLattice, nodes - 2);
          const double fx = double(i - texelOf(a)) / double(texelOf(a + 1) - texelOf(a));
          const double fy = double(j - texelOf(b)) / double(texelOf(b + 1) - texelOf(b));
          const glm::dvec2 v = glm::mix(glm::mix(node[std::size_t(b) * nodes + a], node[std::size_t(b) * nodes + a + 1], fx),
                                        glm::mix(node[std::size_t(b + 1) * nodes + a], node[std::size_t(b + 1) * nodes + a + 1], fx), fy);
          const auto east = encodeWindComponent(v.x), north = encodeWindComponent(v.y);
          std::uint8_t* t = &field.texels[(layerBase + std::size_t(j) * n + i) * kChannels];
          t[0] = east[0];
          t[1] = east[1];
          t[2] = north[0];
          t[3] = north[1];
        }
    }
  }
}

geo::Geodetic weatherAnchorFor(const geo::Geodetic& camera) {
  const geo::Vec3d e = geo::toEcef(camera);
  const double a = kWeatherAnchorLattice_m;
  const geo::Vec3d lattice{std::round(e.x / a) * a, std::round(e.y / a) * a, std::round(e.z / a) * a};
  geo::Geodetic g = geo::fromEcef(lattice);
  g.alt_m = 0;
  return g;
}

bool sameAnchor(const geo::Geodetic& a, const geo::Geodetic& b) {
  return a.lat_deg == b.lat_deg && a.lon_deg == b.lon_deg && a.alt_m == b.alt_m;
}

}  // namespace sky::render
