// The weather map on the CPU: per layer, coverage, density and type blend on a
// square grid in the gnomonic plane of an anchor point (the camera when it was
// built), filled from the snapshot's S2 coverage tiles. The GPU uploads it as
// a texture array; the CPU reference samples it here with the same filter.
#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include <glm/vec3.hpp>

#include "sky/core/result.hpp"
#include "sky/geo/geodetic.hpp"
#include "sky/weather/model.hpp"
#include "sky_shared.h"

namespace sky::render {

// Texels per edge of the weather map: 256 over 200 km is ~780 m per texel,
// about the server's ~1 km tiles.
inline constexpr std::uint32_t kWeatherMapSize = 256;
// Half the map's edge in the gnomonic plane, m; beyond it coverage is 0.
inline constexpr double kWeatherHalfExtent_m = 100000.0;
// The map is rebuilt around the camera when it has moved this far from the
// anchor, m, so at least ~90 km of map remains ahead in every direction.
inline constexpr double kWeatherRecentre_m = 10000.0;

struct WeatherField {
  geo::EnuFrame frame;          // anchor point (ECEF) and its east/north/up
  double anchorAlt_m = 0;       // anchor altitude above the ellipsoid
  double radius_m = 0;          // |anchor ECEF|: radius of the anchor sphere
  geo::Vec3d centreEcef_m;      // anchor sphere centre = anchor - up * radius
  double halfExtent_m = kWeatherHalfExtent_m;
  std::uint32_t size = kWeatherMapSize;
  std::uint32_t sliceCount = 0;        // slices in texels (always gpu::kMaxLayers)
  std::vector<std::uint8_t> texels;    // unorm8 (the stream's 1/255 steps): slice, row (north),
                                       // column (east), (coverage, density, blend, 0)
  // Per slice, the one type its tiles blend towards (None: no blend). A tile
  // may name another type than the slice's; the slice takes the type with the
  // largest summed blend in its tiles and such tiles draw unblended.
  std::array<weather::CloudType, gpu::kMaxLayers> blendType{};
  // Per slice, whether the layer came with tiles (else the slice is uniform
  // over the map and drifting it changes nothing).
  std::array<bool, gpu::kMaxLayers> tiled{};
  std::uint64_t contentKey = 0;        // weatherContentKey() of the source snapshot

  // (coverage, density, blend) at gnomonic plane coordinates (m, east/north
  // of the anchor): bilinear, zero outside the map, as the GPU's clamp-to-border.
  glm::dvec3 sample(std::uint32_t slice, double x_m, double y_m) const;
};

// Hash of everything in a snapshot that the map depends on (layer ids, order,
// coverage and density; tiles with their blend; tile level). nullptr hashes as "no weather".
std::uint64_t weatherContentKey(const weather::WeatherSnapshot* snapshot);

// Fills the map around anchor. A layer without tiles is uniform (its own
// coverage and density); a layer with tiles is empty where a cell has none.
// The snapshot must already be validated (at most gpu::kMaxLayers layers).
WeatherField buildWeatherField(const weather::WeatherSnapshot* snapshot, const geo::Geodetic& anchor);

// True when the map must be rebuilt for this snapshot key and camera position.
bool weatherFieldStale(const WeatherField& field, std::uint64_t contentKey, const geo::Vec3d& cameraEcef_m);

}  // namespace sky::render
