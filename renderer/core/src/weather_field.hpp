// The weather map on the CPU: per layer, coverage, density and type blend on a
// square grid in the gnomonic plane of an anchor point (the camera when it was
// built), filled from the snapshot's S2 coverage tiles. The GPU uploads it as
// a texture array; the CPU reference samples it here with the same filter.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <unordered_map>
#include <vector>

#include <glm/vec3.hpp>
#include <glm/vec4.hpp>

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
                                       // array layer ring * sliceCount + slice; then the wind map's
                                       // layers (gpu::kWindMapLayers + ring * sliceCount + slice)
  // Per slice, the one type its tiles blend towards (None: no blend). A tile
  // may name another type than the slice's; the slice takes the type with the
  // largest summed blend in its tiles (of both rings) and such tiles draw unblended.
  std::array<weather::CloudType, gpu::kMaxLayers> blendType{};
  // Per slice, whether the layer came with tiles in either ring (else the
  // slice is uniform over the map and drifting it changes nothing).
  std::array<bool, gpu::kMaxLayers> tiled{};
  // Per slice, whether the layer's wind varies over the map (its snapshot
  // has wind tiles for it): its wind slices then hold the wind, in the
  // anchor's east/north, from weather::WindField at each texel (bilinear
  // between every kWindLattice-th texel).
  std::array<bool, gpu::kMaxLayers> windVaries{};
  std::uint64_t contentKey = 0;        // weatherContentKey() of the source snapshots
  std::uint64_t windKey = 0;           // weatherWindKey() of the source snapshots
  geo::Geodetic anchor;                // where the map was built
  // Per ring, the S2 level of its cells (its source snapshot's tile level)
  // and per texel (row, column) the cell of that level at the texel's
  // centre; level -1 and no cells when no slice of the ring has tiles. A
  // new snapshot at the same anchor and level reuses them.
  std::array<int, kWeatherRings> cellLevel{-1, -1};
  std::array<std::vector<std::uint64_t>, kWeatherRings> cells;

  // (coverage, density, blend) at gnomonic plane coordinates (m, east/north
  // of the anchor): the rings blended by ringBlendWeight, as the GPU.
  glm::dvec3 sample(std::uint32_t slice, double x_m, double y_m) const;
  // One ring alone: bilinear, zero outside it, as the GPU's clamp-to-border.
  glm::dvec3 sampleRing(std::uint32_t ring, std::uint32_t slice, double x_m, double y_m) const;
  // Any texture layer of ring 0 (a cover slice, or gpu::kWindMapLayers + a
  // slice) with its ring 1 layer (+ sliceCount), blended as sample: the four
  // channels as the GPU's filter gives them, in [0, 1].
  glm::dvec4 sampleLayer(std::uint32_t fineLayer, double x_m, double y_m) const;
  // One texture layer of a ring of this half extent, bilinear, 0 outside.
  glm::dvec4 sampleTexels(std::size_t layer, double halfExtent_m, double x_m, double y_m) const;
};

// Every kWindLattice-th texel's wind comes from the field; the texels
// between are bilinear (the wind varies over kilometres, a texel is 780 m).
inline constexpr std::uint32_t kWindLattice = 8;

// The wind map's encoding of one component (sky_shared.h): 16 bits as a
// high and a low byte.
std::array<std::uint8_t, 2> encodeWindComponent(double mps);

// Fills the wind slices of a field built at its anchor from the snapshots'
// wind tiles (ring 1 from `coarse` when given), and windVaries, windKey.
void writeWindTexels(WeatherField& field, const weather::WeatherSnapshot* fine, const weather::WeatherSnapshot* coarse);

// Hash of the snapshots' wind tiles and levels (what the wind slices hold).
std::uint64_t weatherWindKey(const weather::WeatherSnapshot* fine, const weather::WeatherSnapshot* coarse);

// Channels per texel of the map: coverage, density, blend, unused.
inline constexpr std::size_t kWeatherChannels = 4;

// One tile's values as the map stores them (before quantisation).
struct TileValue {
  float coverage = 0;
  float density = 0;
  weather::CloudType blendType = weather::CloudType::None;
  float blend = 0;
  bool operator==(const TileValue&) const = default;
};
using SliceTiles = std::unordered_map<std::uint64_t, TileValue>;  // by S2 cell id

// One ring's tiles from its source snapshot, by slice (the fine snapshot's
// layers, in its order; tiles of other layer ids are left out).
struct RingTiles {
  std::vector<SliceTiles> bySlice;
  // Per slice and cloud type, the summed blend of the tiles that blend
  // towards a type other than the layer's own, in the snapshot's tile order.
  std::vector<std::array<double, weather::kMaxCloudType + 1>> blendWeight;
  // A (cell, layer) named twice: the later tile wins on the map but both
  // count towards the blend type, which a per-tile update cannot redo, so
  // such a snapshot is always built whole.
  bool duplicates = false;
};

// The tiles a map is filled from, sorted by ring and slice. Slices are the
// fine snapshot's layers in its order; ring 0 takes the fine snapshot's
// tiles, ring 1 the coarse snapshot's (its tiles of layer ids the fine
// snapshot lacks are ignored) or, without one, the fine snapshot's too.
struct WeatherTiles {
  std::array<int, kWeatherRings> level{-1, -1};  // each ring's source tile level (-1: no weather)
  std::array<RingTiles, kWeatherRings> rings;    // ring 1 empty when the rings share
  bool ringsShare = false;                       // no coarse snapshot: ring 1 reads ring 0's tiles
  // Per slice: the type with the most blend weight over both rings' tiles
  // (ties: the lower enum value; None without any), and whether either ring
  // has tiles.
  std::array<weather::CloudType, gpu::kMaxLayers> blendType{};
  std::array<bool, gpu::kMaxLayers> tiled{};

  std::size_t slices() const { return rings[0].bySlice.size(); }
  const SliceTiles& tiles(std::uint32_t ring, std::size_t slice) const {
    return rings[ringsShare ? 0 : ring].bySlice[slice];
  }
  bool duplicates() const { return rings[0].duplicates || rings[1].duplicates; }
  // Whether any slice has tiles in this ring (it then needs texel cells).
  bool ringTiled(std::uint32_t ring) const;
};

// One snapshot's tiles sorted into the slices of these layers.
RingTiles indexRingTiles(const weather::WeatherSnapshot& source, const std::vector<weather::CloudLayer>& layers);

// The rings put together (coarseRing ignored without a coarse snapshot),
// with each slice's blend type and tiled flag.
WeatherTiles combineWeatherTiles(const weather::WeatherSnapshot& fine, const weather::WeatherSnapshot* coarse,
                                 RingTiles fineRing, RingTiles coarseRing);

// Sorts the tiles of a fine snapshot (validated, at most gpu::kMaxLayers
// layers) and an optional coarse one into rings and slices, and chooses
// each slice's blend type. fine nullptr: no slices (coarse is then ignored).
WeatherTiles indexWeatherTiles(const weather::WeatherSnapshot* fine, const weather::WeatherSnapshot* coarse);

// Writes one texel (index row * size + column) of (ring, slice) from the
// value it takes: quantised as the stream's fractions, the blend kept only
// when the value blends towards the slice's blend type.
void writeWeatherTexel(WeatherField& field, std::uint32_t ring, std::size_t slice, std::size_t texel,
                       const TileValue& value);

// Hash of everything in the snapshots that the map depends on (layer ids,
// order, coverage and density; tiles with their blend; tile levels; the
// coarse snapshot's tiles and level). nullptr hashes as "no weather"; a
// coarse snapshot without a fine one adds nothing (the map has no slices).
std::uint64_t weatherContentKey(const weather::WeatherSnapshot* snapshot,
                                const weather::WeatherSnapshot* coarse = nullptr);

// The content key and its parts: the hash of each snapshot's tiles and
// level (0 for an absent snapshot), so an update can tell which changed.
struct WeatherKeys {
  std::uint64_t content = 0;
  std::uint64_t fineTiles = 0, coarseTiles = 0;
};
WeatherKeys weatherKeys(const weather::WeatherSnapshot* snapshot, const weather::WeatherSnapshot* coarse);

// What of the weather changes the image everywhere when it changes, apart
// from the clock and the camera: the layers (ids, order, type, uniform
// coverage and density, base, thickness, wind), the tile levels and which
// layers have tiles; not the tiles' values, which change the image only
// where they lie (temporal_plan.cpp drops the history there alone).
std::uint64_t weatherStructureKey(const weather::WeatherSnapshot* snapshot,
                                  const weather::WeatherSnapshot* coarse = nullptr);

// Fills the map around anchor. A layer without tiles is uniform (its own
// coverage and density); a layer with tiles is empty where a cell has none.
// The snapshot must already be validated (at most gpu::kMaxLayers layers).
// With `previous` built at the same anchor and its cells at the snapshot's
// tile level, the texels' cells are taken from it instead of found again
// (no geodesy: new tiles cost a hash lookup per texel); the result is the
// same as without it. Ring 1 takes its tiles from the snapshot too.
WeatherField buildWeatherField(const weather::WeatherSnapshot* snapshot, const geo::Geodetic& anchor,
                               const WeatherField* previous = nullptr);

// The same with ring 1 filled from `coarse` (a second, wider subscription at
// its own tile level; nullptr: from `snapshot`, as above). Per ring the
// cells of `previous` are reused when its level and anchor match. A slice
// whose layer has no coarse tiles is uniform in ring 1 at the fine layer's
// coverage and density.
WeatherField buildWeatherField(const weather::WeatherSnapshot* snapshot, const weather::WeatherSnapshot* coarse,
                               const geo::Geodetic& anchor, const WeatherField* previous = nullptr);

// The same from tiles already sorted (indexWeatherTiles(snapshot, coarse)).
WeatherField buildWeatherField(const WeatherTiles& tiles, const weather::WeatherSnapshot* snapshot,
                               const weather::WeatherSnapshot* coarse, const geo::Geodetic& anchor,
                               const WeatherField* previous);

// The anchor of the map for a camera at this position (see kWeatherAnchorLattice_m).
geo::Geodetic weatherAnchorFor(const geo::Geodetic& camera);

// Whether two anchors are the same point, bit for bit (what cell reuse needs).
bool sameAnchor(const geo::Geodetic& a, const geo::Geodetic& b);

}  // namespace sky::render
