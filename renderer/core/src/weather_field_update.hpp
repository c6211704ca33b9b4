// The weather map kept current as snapshots arrive: a new snapshot (fine or
// coarse) that differs from the last only in new or changed tiles rewrites
// just the texels of those tiles' cells, found through an inverse index
// (cell -> texels, per ring, built once per anchor and level); anything else
// rebuilds the map whole. Either way the map equals a fresh buildWeatherField.
// WeatherTexture uploads what it reports as changed.
#pragma once

#include <array>
#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "sky/geo/geodetic.hpp"
#include "sky/weather/model.hpp"
#include "weather_field.hpp"

namespace sky::render {

// A rectangle of texels in one array layer of the map (ring * sliceCount + slice).
struct TexelRect {
  std::uint32_t layer = 0;
  std::uint32_t x = 0, y = 0;           // first column (east) and row (north)
  std::uint32_t width = 0, height = 0;  // texels
};

struct WeatherFieldChange {
  enum class Kind {
    Unchanged,  // same content and anchor: nothing written
    Tiles,      // only the texels of changed tiles were rewritten (maybe none)
    Rebuilt,    // the whole map was built again
  };
  Kind kind = Kind::Unchanged;
  std::string reason;                 // why it was rebuilt ("anchor moved", "a tile removed", ...)
  std::uint64_t texelsRewritten = 0;  // texels written, counted per array layer (all of them when rebuilt)
  std::vector<TexelRect> dirty;       // Tiles: per array layer touched, the bounding rectangle of its rewrites
  // Tiles: the largest change of a rewritten texel's coverage, density or
  // blend, in the map's 1/255 steps (a ramp moves a few a frame, a step
  // change many).
  std::uint32_t largestStep = 0;
  // Tiles: the wind slices rewritten whole (their wind tiles changed: a
  // forecast's wind moving on, a region's own wind). Not in `dirty`: a wind
  // that changes by centimetres a second leaves the picture, and so the
  // renderer's history, as it is.
  std::vector<TexelRect> windDirty;
};

class WeatherFieldUpdater {
 public:
  // Starts with the clear-sky map (no weather) at a default anchor.
  WeatherFieldUpdater();

  // Makes the map the one buildWeatherField(fine, coarse, anchor) gives,
  // rewriting only what changed where it can. Both snapshots validated
  // (frame_setup.cpp, validateInputs); anchor from weatherAnchorFor.
  // `version` (FrameInputs::weatherVersion): when it is the last call's, at
  // the same anchor, the snapshots are taken to be the last call's and not
  // read at all.
  WeatherFieldChange update(const weather::WeatherSnapshot* fine, const weather::WeatherSnapshot* coarse,
                            const geo::Geodetic& anchor, std::optional<std::uint64_t> version = std::nullopt);

  const WeatherField& field() const { return field_; }

 private:
  // Rewrites the wind slices (the wind tiles changed, nothing else) and
  // says so in `change`.
  void rewriteWind(const weather::WeatherSnapshot* fine, const weather::WeatherSnapshot* coarse,
                   WeatherFieldChange& change);
  // One ring's texels grouped by cell (CSR): the texels (row * size +
  // column) of cells[k] are texels[start[k] .. start[k + 1]). A function of
  // the anchor and the level alone, so it stays valid across rebuilds at
  // the same anchor and level.
  struct CellTexels {
    bool built = false;
    geo::Geodetic anchor;
    int level = -1;
    std::vector<std::uint64_t> cells;  // sorted, unique
    std::vector<std::uint32_t> start;  // cells.size() + 1 offsets into texels
    std::vector<std::uint32_t> texels;
    std::span<const std::uint32_t> texelsOf(std::uint64_t cell) const;
  };

  // A tile that is new or differs from the one the map holds.
  struct ChangedTile {
    std::uint32_t ring = 0;  // the ring whose tiles it is (0 for both when the rings share tiles)
    std::uint32_t slice = 0;
    std::uint64_t cell = 0;
    TileValue value;
  };
  // Why these snapshots cannot be a per-tile update of the current map, as
  // far as that shows without their tiles (empty when they can).
  std::string snapshotReason(const weather::WeatherSnapshot* fine, const weather::WeatherSnapshot* coarse,
                             const geo::Geodetic& anchor) const;
  // The same from their tiles (empty when they can); fills *changes with
  // the new or changed tiles of the rings not `unchanged`.
  std::string tileReason(const WeatherTiles& next, const std::array<bool, kWeatherRings>& unchanged,
                         std::vector<ChangedTile>* changes) const;
  // Builds index_[ring] for the field's anchor and cell level unless it is already.
  void indexCells(std::uint32_t ring);

  WeatherField field_;
  WeatherTiles tiles_;  // what field_ was filled from (a ring moved out while an update reuses it)
  WeatherKeys keys_;    // and its keys: a snapshot whose tiles key is the same needs no new index
  std::optional<std::uint64_t> version_;  // the caller's version of what field_ was made from
  // The fine snapshot's layers as field_ has them (id, type, coverage and
  // density matter to the map), and which snapshots there were.
  std::vector<weather::CloudLayer> layers_;
  bool built_ = false, hadFine_ = false, hadCoarse_ = false;
  std::array<CellTexels, kWeatherRings> index_;
};

}  // namespace sky::render
