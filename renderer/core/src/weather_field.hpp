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

// The map has rings of detail about one anchor, each a square grid of
// kWeatherMapSize texels per edge in the anchor's gnomonic plane: ring 0
// (fine) 256 over 200 km, ~780 m per texel, about the server's finest tiles;
// ring 1 (coarse) 256 over 1200 km, ~4.7 km per texel (the ~5 km tiles the
// renderer subscribes to), out past the horizon of a layer seen from cruise
// altitude (~550 km for a deck at 2 km seen from 12 km). A point takes the
// finest ring that covers it; across the fine ring's outer band the two
// blend (ringBlendWeight), so there is no seam.
inline constexpr std::uint32_t kWeatherMapSize = 256;
inline constexpr std::uint32_t kWeatherRings = 2;
// Half the edge of each ring in the gnomonic plane, m; beyond the last ring
// coverage is 0.
inline constexpr std::array<double, kWeatherRings> kWeatherRingHalfExtent_m = {100000.0, 600000.0};
inline constexpr double kWeatherHalfExtent_m = kWeatherRingHalfExtent_m[0];
// The blend band, in fractions of the fine ring's half extent (max norm):
// fine inside kRingBlendStart, coarse beyond kRingBlendEnd (which leaves the
// fine ring's bilinear filter a texel and more inside its edge).
inline constexpr double kRingBlendStart = 0.85, kRingBlendEnd = 0.95;
// The map's anchor is the camera's ECEF position rounded to a cubic lattice
// of this spacing, m, brought down to the ellipsoid (weatherAnchorFor): the
// camera stays within ~4.4 km of it (half the cube's diagonal), so at least
// ~80 km of fine ring lies ahead in every direction; the map moves when the
// camera's lattice point changes. A function of the camera alone, so the GPU
// map and the CPU reference's are built at the same anchor.
inline constexpr double kWeatherAnchorLattice_m = 5000.0;

// Weight of the coarse ring at gnomonic plane point (x, y) m: 0 inside the
// fine ring's blend band, 1 outside it, linear in the max norm between. The
// GPU's sampleWeather (shaders/clouds.comp) computes the same from the
// frame's weatherMap.x and weatherRings.
double ringBlendWeight(double x_m, double y_m);

struct WeatherField {
  geo::EnuFrame frame;          // anchor point (ECEF) and its east/north/up
  double anchorAlt_m = 0;       // anchor altitude above the ellipsoid
  double radius_m = 0;          // |anchor ECEF|: radius of the anchor sphere
  geo::Vec3d centreEcef_m;      // anchor sphere centre = anchor - up * radius
  std::array<double, kWeatherRings> halfExtent_m = kWeatherRingHalfExtent_m;
  std::uint32_t size = kWeatherMapSize;
  std::uint32_t sliceCount = 0;        // slices per ring in texels (always gpu::kMaxLayers)
  std::vector<std::uint8_t> texels;    // unorm8 (the stream's 1/255 steps): ring, slice, row (north),
                                       // column (east), (coverage, density, blend, 0); the GPU's
                                       // array layer ring * sliceCount + slice
  // Per slice, the one type its tiles blend towards (None: no blend). A tile
  // may name another type than the slice's; the slice takes the type with the
  // largest summed blend in its tiles and such tiles draw unblended.
  std::array<weather::CloudType, gpu::kMaxLayers> blendType{};
  // Per slice, whether the layer came with tiles (else the slice is uniform
  // over the map and drifting it changes nothing).
  std::array<bool, gpu::kMaxLayers> tiled{};
  std::uint64_t contentKey = 0;        // weatherContentKey() of the source snapshot
  geo::Geodetic anchor;                // where the map was built
  // Per ring and texel (ring, row, column), the S2 cell of level cellLevel
  // at the texel's centre; empty (cellLevel -1) when the snapshot had no
  // tiles. A new snapshot at the same anchor and level reuses them.
  int cellLevel = -1;
  std::vector<std::uint64_t> cells;

  // (coverage, density, blend) at gnomonic plane coordinates (m, east/north
  // of the anchor): the rings blended by ringBlendWeight, as the GPU.
  glm::dvec3 sample(std::uint32_t slice, double x_m, double y_m) const;
  // One ring alone: bilinear, zero outside it, as the GPU's clamp-to-border.
  glm::dvec3 sampleRing(std::uint32_t ring, std::uint32_t slice, double x_m, double y_m) const;
};

// Hash of everything in a snapshot that the map depends on (layer ids, order,
// coverage and density; tiles with their blend; tile level). nullptr hashes as "no weather".
std::uint64_t weatherContentKey(const weather::WeatherSnapshot* snapshot);

// weatherContentKey and everything else about the weather that changes the
// image, apart from the clock and the camera: each layer's base, thickness
// and wind. A change of it drops an interleaved renderer's history.
std::uint64_t weatherSceneKey(const weather::WeatherSnapshot* snapshot);

// Fills the map around anchor. A layer without tiles is uniform (its own
// coverage and density); a layer with tiles is empty where a cell has none.
// The snapshot must already be validated (at most gpu::kMaxLayers layers).
// With `previous` built at the same anchor and its cells at the snapshot's
// tile level, the texels' cells are taken from it instead of found again
// (no geodesy: new tiles cost a hash lookup per texel); the result is the
// same as without it.
WeatherField buildWeatherField(const weather::WeatherSnapshot* snapshot, const geo::Geodetic& anchor,
                               const WeatherField* previous = nullptr);

// The anchor of the map for a camera at this position (see kWeatherAnchorLattice_m).
geo::Geodetic weatherAnchorFor(const geo::Geodetic& camera);

// True when the map must be rebuilt for this snapshot key and anchor
// (weatherAnchorFor the camera).
bool weatherFieldStale(const WeatherField& field, std::uint64_t contentKey, const geo::Geodetic& anchor);

}  // namespace sky::render
