// Weather-map construction from S2 coverage tiles (see weather_field.hpp).
#include "weather_field.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <unordered_map>


#include "sky/core/assert.hpp"
#include "sky/weather/tiling.hpp"
#include "sky_shared.h"

namespace sky::render {

namespace {

struct TileValue {
  float coverage = 0;
  float density = 0;
  weather::CloudType blendType = weather::CloudType::None;
  float blend = 0;
};

// Channels per texel of the map: coverage, density, blend, unused.
constexpr std::size_t kChannels = 4;

void mix64(std::uint64_t& h, std::uint64_t v) {
  // FNV-1a over the value's bytes.
  for (int i = 0; i < 8; ++i) {
    h ^= (v >> (8 * i)) & 0xffu;
    h *= 1099511628211ull;
  }
}

std::uint64_t bitsOf(double d) {
  std::uint64_t u = 0;
  std::memcpy(&u, &d, sizeof u);
  return u;
}

}  // namespace

double ringBlendWeight(double x_m, double y_m) {
  const double e = std::max(std::abs(x_m), std::abs(y_m)) / kWeatherRingHalfExtent_m[0];
  return std::clamp((e - kRingBlendStart) / (kRingBlendEnd - kRingBlendStart), 0.0, 1.0);
}

glm::dvec3 WeatherField::sample(std::uint32_t slice, double x_m, double y_m) const {
  const double w = ringBlendWeight(x_m, y_m);
  glm::dvec3 v(0);
  if (w < 1) v = sampleRing(0, slice, x_m, y_m);
  if (w > 0) v += w * (sampleRing(1, slice, x_m, y_m) - v);
  return v;
}

glm::dvec3 WeatherField::sampleRing(std::uint32_t ring, std::uint32_t slice, double x_m, double y_m) const {
  SKY_ASSERT(slice < sliceCount && ring < kWeatherRings);
  const int n = static_cast<int>(size);
  const double tx = (x_m / (2 * halfExtent_m[ring]) + 0.5) * size - 0.5;
  const double ty = (y_m / (2 * halfExtent_m[ring]) + 0.5) * size - 0.5;
  if (!(std::abs(tx) < 2.0 * size && std::abs(ty) < 2.0 * size)) return {0, 0, 0};  // far outside, or NaN
  const double fx = std::floor(tx), fy = std::floor(ty);
  const int i0 = static_cast<int>(fx), j0 = static_cast<int>(fy);
  const double ax = tx - fx, ay = ty - fy;
  const std::size_t layer = std::size_t(ring) * sliceCount + slice;
  glm::dvec3 sum(0);
  for (int dj = 0; dj <= 1; ++dj)
    for (int di = 0; di <= 1; ++di) {
      const int i = i0 + di, j = j0 + dj;
      if (i < 0 || j < 0 || i >= n || j >= n) continue;
      const std::size_t idx = ((layer * size + std::size_t(j)) * size + std::size_t(i)) * kChannels;
      const double w = (di ? ax : 1 - ax) * (dj ? ay : 1 - ay);
      sum += w * glm::dvec3(texels[idx], texels[idx + 1], texels[idx + 2]) / 255.0;
    }
  return sum;
}

std::uint64_t weatherContentKey(const weather::WeatherSnapshot* snapshot) {
  std::uint64_t h = 14695981039346656037ull;
  if (snapshot == nullptr) return h;
  mix64(h, snapshot->layers.size());
  for (const auto& layer : snapshot->layers) {
    mix64(h, layer.id);
    mix64(h, static_cast<std::uint64_t>(layer.type));
    mix64(h, bitsOf(layer.coverage));
    mix64(h, bitsOf(layer.density));
  }
  mix64(h, static_cast<std::uint64_t>(snapshot->tileLevel));
  mix64(h, snapshot->tiles.size());
  for (const auto& tile : snapshot->tiles) {
    mix64(h, tile.cellId);
    mix64(h, tile.layerId);
    mix64(h, bitsOf(tile.coverage));
    mix64(h, bitsOf(tile.density));
    mix64(h, static_cast<std::uint64_t>(tile.blendType));
    mix64(h, bitsOf(tile.blend));
  }
  return h;
}

std::uint64_t weatherSceneKey(const weather::WeatherSnapshot* snapshot) {
  std::uint64_t h = weatherContentKey(snapshot);
  if (snapshot == nullptr) return h;
  for (const auto& layer : snapshot->layers) {
    mix64(h, bitsOf(layer.base_m));
    mix64(h, bitsOf(layer.thickness_m));
    mix64(h, bitsOf(layer.wind.speed_mps));
    mix64(h, bitsOf(layer.wind.fromDirection_deg));
    mix64(h, bitsOf(layer.wind.vertical_mps));
  }
  return h;
}

WeatherField buildWeatherField(const weather::WeatherSnapshot* snapshot, const geo::Geodetic& anchor,
                               const WeatherField* previous) {
  WeatherField field;
  field.anchor = anchor;
  field.frame = geo::enuFrameAt(anchor);
  field.anchorAlt_m = anchor.alt_m;
  field.radius_m = geo::length(field.frame.originEcef_m);
  field.centreEcef_m = field.frame.originEcef_m - field.frame.up * field.radius_m;
  field.sliceCount = gpu::kMaxLayers;
  field.contentKey = weatherContentKey(snapshot);
  const std::size_t sliceTexels = std::size_t(field.size) * field.size;
  field.texels.assign(sliceTexels * field.sliceCount * kWeatherRings * kChannels, 0);
  field.blendType.fill(weather::CloudType::None);
  field.tiled.fill(false);
  if (snapshot == nullptr) return field;
  SKY_ASSERT(snapshot->layers.size() <= gpu::kMaxLayers);

  // Per slice: the tiles of that layer by cell id (empty map = uniform layer).
  std::vector<std::unordered_map<std::uint64_t, TileValue>> tilesBySlice(snapshot->layers.size());
  std::vector<std::array<double, weather::kMaxCloudType + 1>> blendWeight(snapshot->layers.size());
  bool anyTiles = false;
  for (const auto& tile : snapshot->tiles)
    for (std::size_t s = 0; s < snapshot->layers.size(); ++s)
      if (snapshot->layers[s].id == tile.layerId) {
        tilesBySlice[s][tile.cellId] = {tile.coverage, tile.density, tile.blendType, tile.blend};
        const auto type = static_cast<std::size_t>(tile.blendType);
        if (tile.blend > 0 && type > 0 && type < blendWeight[s].size() && tile.blendType != snapshot->layers[s].type)
          blendWeight[s][type] += tile.blend;
        anyTiles = true;
      }
  // Each slice blends towards the type with the most blend weight (ties: the
  // lower enum value).
  for (std::size_t s = 0; s < snapshot->layers.size(); ++s) {
    field.tiled[s] = !tilesBySlice[s].empty();
    double best = 0;
    for (std::size_t type = 1; type < blendWeight[s].size(); ++type)
      if (blendWeight[s][type] > best) {
        best = blendWeight[s][type];
        field.blendType[s] = static_cast<weather::CloudType>(type);
      }
  }

  const std::size_t cellCount = std::size_t(kWeatherRings) * sliceTexels;
  const bool reuse = anyTiles && previous != nullptr && previous->cellLevel == snapshot->tileLevel &&
                     previous->cells.size() == cellCount && previous->anchor.lat_deg == anchor.lat_deg &&
                     previous->anchor.lon_deg == anchor.lon_deg && previous->anchor.alt_m == anchor.alt_m;
  if (anyTiles) {
    field.cellLevel = snapshot->tileLevel;
    if (reuse)
      field.cells = previous->cells;
    else
      field.cells.assign(cellCount, 0);
  }
  const double groundRadius_m = field.radius_m - anchor.alt_m;
  for (std::uint32_t ring = 0; ring < kWeatherRings; ++ring)
    for (std::uint32_t j = 0; j < field.size; ++j)
      for (std::uint32_t i = 0; i < field.size; ++i) {
        const double x_m = ((i + 0.5) / field.size - 0.5) * 2 * field.halfExtent_m[ring];
        const double y_m = ((j + 0.5) / field.size - 0.5) * 2 * field.halfExtent_m[ring];
        std::uint64_t cell = 0;
        const std::size_t cellIndex = (std::size_t(ring) * field.size + j) * field.size + i;
        if (reuse) {
          cell = field.cells[cellIndex];
        } else if (anyTiles) {
          // Inverse gnomonic: the direction from the sphere centre through the
          // plane point, down to the ground on the anchor sphere. The coarse
          // ring takes the tile at its texel's centre.
          const geo::Vec3d dir = geo::normalize(field.frame.east * x_m + field.frame.north * y_m +
                                                field.frame.up * field.radius_m);
          const geo::Geodetic g = geo::fromEcef(field.centreEcef_m + dir * groundRadius_m);
          cell = weather::cellAt(g.lat_deg, g.lon_deg, snapshot->tileLevel);
          field.cells[cellIndex] = cell;
        }
        for (std::size_t s = 0; s < snapshot->layers.size(); ++s) {
          const auto& layer = snapshot->layers[s];
          TileValue v{static_cast<float>(layer.coverage), static_cast<float>(layer.density)};
          if (!tilesBySlice[s].empty()) {
            const auto it = tilesBySlice[s].find(cell);
            v = it == tilesBySlice[s].end() ? TileValue{} : it->second;
          }
          const std::size_t idx = (((ring * field.sliceCount + s) * field.size + j) * field.size + i) * kChannels;
          const float blend = v.blendType == field.blendType[s] ? std::clamp(v.blend, 0.0f, 1.0f) : 0.0f;
          field.texels[idx] = weather::quantizeUnit(v.coverage);
          field.texels[idx + 1] = weather::quantizeUnit(v.density);
          field.texels[idx + 2] = weather::quantizeUnit(blend);
        }
      }
  return field;
}

geo::Geodetic weatherAnchorFor(const geo::Geodetic& camera) {
  const geo::Vec3d e = geo::toEcef(camera);
  const double a = kWeatherAnchorLattice_m;
  const geo::Vec3d lattice{std::round(e.x / a) * a, std::round(e.y / a) * a, std::round(e.z / a) * a};
  geo::Geodetic g = geo::fromEcef(lattice);
  g.alt_m = 0;
  return g;
}

bool weatherFieldStale(const WeatherField& field, std::uint64_t contentKey, const geo::Geodetic& anchor) {
  if (field.texels.empty() || field.contentKey != contentKey) return true;
  return field.anchor.lat_deg != anchor.lat_deg || field.anchor.lon_deg != anchor.lon_deg ||
         field.anchor.alt_m != anchor.alt_m;
}

}  // namespace sky::render
