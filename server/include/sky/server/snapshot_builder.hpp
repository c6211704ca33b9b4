// Builds the Snapshot a subscriber gets: every layer, plus coverage tiles on
// the S2 cells covering its area of interest at a level whose cell count (and
// so the frame) stays bounded.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <map>
#include <memory>
#include <optional>
#include <tuple>
#include <unordered_map>
#include <span>
#include <vector>

#include "sky/stream/messages.hpp"
#include "sky/weather/air_field.hpp"
#include "sky/weather/model.hpp"
#include "sky/weather/region.hpp"
#include "sky/weather/tiling.hpp"
#include "sky/weather/wind_field.hpp"

namespace sky::server {

// Cells per snapshot. 20000 cells at the ~1 km tiles DESIGN.md asks for cover
// a cap of roughly 80 km radius, more than a renderer sees through cloud, and
// one cloud layer's tiles then take ~480 kB of a frame.
inline constexpr std::size_t kDefaultMaxCells = 20000;

// Bytes one CoverageTile takes on the wire, used to keep a snapshot under
// sky::stream::kMaxFrameBytes (the schema's size, pinned in protocol/).
inline constexpr std::size_t kTileWireBytes = stream::kTileWireBytes;

// Great-circle distance on the mean sphere, m: a cheap bound to skip regions
// far from an area before the exact geodesic measure.
double sphereDistance_m(double lat1, double lon1, double lat2, double lon2);
// Beyond this (sphere distance from its centre, m) a region weighs 0.
double reachOf(const weather::Region& r);

// Cells allowed for `layerCount` layers: maxCells, lowered so that cells ×
// layers tiles still fit one stream frame (with room for the layer table and
// `fieldTiles` wind and air tiles).
std::size_t cellBudget(std::size_t maxCells, std::size_t layerCount, std::size_t fieldTiles = 0);

struct Covering {
  int level = 0;                     // S2 level actually used, <= the wanted one
  std::vector<std::uint64_t> cells;  // S2CellIds of exactly `level`, size <= maxCells
};

// S2 covering of `cap` at `wantedLevel` ([0, 30]) or, when that takes more than
// maxCells (>= 6, one cell per cube face) cells, at the finest coarser level
// that does not.
Covering coverArea(const weather::SphericalCap& cap, int wantedLevel, std::size_t maxCells);

// The layer table of a snapshot: the global layers, then each layer id only
// regions have, with coverage 0, since outside its regions there is none of
// it. Such a layer's other values (base, thickness, type) are those of the
// region that weighs most at `at` (a subscriber's centre: near a METAR
// station, its own report's base), or with none there, or no `at`, of the
// lowest region id that has it. Fog hugs the ground, whose height differs
// from station to station: a fog layer's base and top are instead the lowest
// base and the highest top of that layer in every region that reaches within
// radius_m of `at` (the subscriber's area), so each station's fog covers its
// own ground and the tiles' density gives each its visibility (the fog is
// drawn as deep as the deepest in the area).
std::vector<weather::CloudLayer> snapshotLayers(std::span<const weather::CloudLayer> layers,
                                                std::span<const weather::Region> regions,
                                                const weather::CellCentre* at = nullptr, double radius_m = 0);

// One layer's tiles over a covering (every cell, in the covering's order),
// with what lets two of them be compared without reading them all: the value
// every tile has that no region reaches (the layer's own coverage and
// density), and the indices, ascending, of the tiles regions reach (only
// those can differ from it). Kept sparse where it can be: a storm cell
// reaches a few hundred of an area's thousands of cells, and writing every
// cell's tile for each subscriber at every change was the largest cost of a
// regional storm (a quarter of the server thread's samples at 256
// subscribers).
struct LayerTiles {
  // The covering's cells, shared by every layer and run over it.
  std::shared_ptr<const std::vector<std::uint64_t>> cells;
  std::uint32_t layerId = 0;
  float coverage = 0, density = 0;
  std::vector<std::uint32_t> reached;
  // dense: one tile per cell, in the covering's order (a forecast's field
  // gives every cell its own value). Sparse: the tiles of the `reached`
  // cells, in that order; every other cell's tile is the layer's own value.
  bool dense = false;
  std::vector<weather::CoverageTile> tiles;
  std::uint64_t covering = 0;  // TileCache::Entry::serial of the cells (0: not known)

  std::size_t size() const { return cells ? cells->size() : 0; }
  // The tile of cell index k (< size()).
  weather::CoverageTile at(std::size_t k) const;
  // Appends every tile, in the covering's order.
  void appendTo(std::vector<weather::CoverageTile>& out) const;
};

// A unit vector on the mean sphere (x towards 0 N 0 E, z towards the north
// pole): the cheap "is this cell within reach of that region" test is a dot
// product, with no trigonometry per cell.
struct UnitVector {
  double x = 0, y = 0, z = 1;
};
UnitVector unitVector(double lat_deg, double lon_deg);

// What snapshots of the same areas share from one change to the next: the
// S2 coverings by area, level and budget, with their cells' centres; per
// covering, each region shape's weight at every cell; each shape's weight
// per cell across coverings (renderers' areas overlap); and per covering and
// layer the tiles derived last with the inputs they came from, so a layer no
// change touched in an area gets its tiles back without deriving them (a
// storm cell moving changes its own layer's tiles, and only near it). Bounded: a table that
// grows past its limit starts again. Used on the server's io thread only.
class TileCache {
 public:
  // Coverings kept (renderers re-subscribe as they move) unless told more.
  static constexpr std::size_t kDefaultMaxCoverings = 256;
  // maxCoverings: areas kept before the table starts again. Below the number
  // of areas subscribed, every change would derive every area's tiles anew
  // (at 512 subscribers with 256, the server saturated): a server keeps one
  // per area it may serve.
  explicit TileCache(std::size_t maxCoverings = kDefaultMaxCoverings) : maxCoverings_(maxCoverings) {}

  // A region's shape (centre, sizes, corner radius, rotation, transition) as
  // the bit patterns of its values: equal keys are equal shapes, exactly.
  using ShapeKey = std::array<std::uint64_t, 7>;
  struct ShapeKeyHash {
    std::size_t operator()(const ShapeKey& k) const;
  };
  // One layer's tiles as derived last for a covering, and the bit patterns of
  // what they were derived from (see deriveTiles).
  struct LayerMemo {
    std::vector<std::uint64_t> inputs;
    // Empty: the layer is uniform there. Shared with the snapshots built from
    // it (a snapshot holds them, not a copy), replaced, never changed.
    std::shared_ptr<const LayerTiles> tiles;
    std::uint64_t generation = 0;              // of these tiles (0: none derived yet)
    bool valid = false;
  };
  // A region's weight at the cells of a covering it reaches, by index into
  // the covering's cells; cells left out have weight 0.
  struct Weights {
    std::vector<std::uint32_t> cells;
    std::vector<double> weights;
  };
  struct Entry {
    weather::SphericalCap cap;
    Covering covering;
    std::shared_ptr<const std::vector<std::uint64_t>> cells;  // covering.cells, for the LayerTiles over it
    std::uint64_t serial = 0;  // no other covering this cache made has it
    std::vector<weather::CellCentre> centres;  // of covering.cells
    std::vector<UnitVector> units;             // of centres
    // Runs of cells with one parent kGroupLevels coarser (S2 orders a
    // covering's cells so that a parent's children are consecutive), each
    // with a cap holding their centres: a region's reach is tested against
    // the groups first, then only the cells of those it may reach.
    struct CellGroup {
      std::uint32_t begin = 0, end = 0;  // indices into covering.cells
      UnitVector centre;
      double radius_rad = 0;  // from centre to the farthest cell centre
    };
    std::vector<CellGroup> groups;
    std::unordered_map<ShapeKey, Weights, ShapeKeyHash> shapeWeights;
    std::map<std::uint32_t, LayerMemo> layers;  // by layer id
    // Per layer id, its wind tiles over this covering (wind_tiles.cpp) and
    // the bit patterns of what they came from: a region edit elsewhere, or
    // another subscriber of the same area, does not sample a forecast's
    // winds again.
    struct WindMemo {
      std::vector<std::uint64_t> inputs;
      std::vector<weather::WindTile> tiles;  // empty: the layer's own wind everywhere
    };
    std::map<std::uint32_t, WindMemo> windLayers;
    // Its air tiles (air_tiles.cpp) and the key of the field they came from.
    struct AirMemo {
      bool valid = false;
      std::uint64_t fieldKey = 0;
      std::vector<float> levels_m;
      int level = 0;
      std::vector<weather::AirTile> tiles;
    };
    AirMemo air;
  };
  Entry& covering(const weather::SphericalCap& cap, int wantedLevel, std::size_t maxCells);
  // regionWeight(region, cell centre) of the cells of `entry` where it is
  // not 0, remembered by the region's shape. The reference stays valid until
  // entry.shapeWeights is cleared (deriveTiles bounds it).
  const Weights& weights(Entry& entry, const weather::Region& region);
  std::size_t coverings() const { return coverings_.size(); }
  // Layers of snapshots whose tiles came back from the memo / were derived.
  std::uint64_t tileHits() const { return tileHits_; }
  std::uint64_t tileMisses() const { return tileMisses_; }
  void countTiles(bool hit) { ++(hit ? tileHits_ : tileMisses_); }
  // A number no tiles derived before had: equal generations, equal tiles.
  std::uint64_t nextGeneration() { return ++generations_; }
  // Makes room in entry.shapeWeights for `regions` more shapes (forgetting
  // the ones it holds when they would not fit), so that references weights()
  // returns for them stay valid together.
  static void makeRoomForShapes(Entry& entry, std::size_t regions);
  // A region's shape as the cache keys it.
  static ShapeKey shapeOf(const weather::Region& region);

 private:
  double cellWeight(const ShapeKey& shape, const weather::Region& region, std::uint64_t cell,
                    const weather::CellCentre& centre);

  std::size_t maxCoverings_;
  std::map<std::tuple<double, double, double, int, std::size_t>, Entry> coverings_;
  // Shape -> cell -> weight, shared by coverings; cellWeightCount_ entries in all.
  std::unordered_map<ShapeKey, std::unordered_map<std::uint64_t, double>, ShapeKeyHash> cellWeights_;
  std::size_t cellWeightCount_ = 0;
  std::uint64_t tileHits_ = 0, tileMisses_ = 0;
  std::uint64_t generations_ = 0;
  std::uint64_t coveringSerials_ = 0;
};

// Cover that varies over the Earth from outside the layers and regions (a
// loaded forecast, forecast.hpp): the tile of some layers at any point. A
// region's weight then blends from this tile instead of the layer's own
// values.
class LayerField {
 public:
  virtual ~LayerField() = default;
  // Whether this field gives layer `id`'s cover.
  virtual bool gives(std::uint32_t layerId) const = 0;
  // The tile (coverage, density, type blend) of the layer at each point;
  // coverage NaN where the field has none (the layer's own values hold there).
  virtual void sample(std::uint32_t layerId, std::span<const weather::CellCentre> at,
                      std::span<weather::CoverageTile> out) const = 0;
  // Equal keys, equal tiles everywhere: what the tile cache compares.
  virtual std::uint64_t key() const = 0;
  // Whether this field gives layer `id`'s wind, and that wind at each point
  // (components NaN where the field has none: the layer's own wind there).
  virtual bool givesWind(std::uint32_t layerId) const {
    (void)layerId;
    return false;
  }
  virtual void sampleWind(std::uint32_t layerId, std::span<const weather::CellCentre> at,
                          std::span<weather::WindVector> out) const {
    (void)layerId;
    (void)at;
    (void)out;
  }
  // The heights (m MSL, ascending) this field gives the air's temperature
  // and humidity at (none: the standard atmosphere), and the air at level
  // `level` at each point (temperature NaN where it has none, humidity NaN
  // where it has no humidity).
  virtual std::vector<double> airLevels() const { return {}; }
  virtual void sampleAir(std::size_t level, std::span<const weather::CellCentre> at,
                         std::span<weather::AirValues> out) const {
    (void)level;
    (void)at;
    (void)out;
  }
};

// One tile per (cell, table layer) for each layer that varies over the
// cells; a layer that is the same everywhere there gets none (a renderer then
// takes the layer's own values: the snapshot of uniform weather is just its
// layer table, and a change to it costs a few hundred bytes). At the cell's
// centre every region weighs in by weather::regionWeight (1 inside, smooth to 0 across its transition
// perimeter) for the layers it has: the tile is the global value blended
// towards the weighted mean of the regions' values by the summed weight
// (capped at 1); the type blend is the heaviest region's type when it differs
// from the layer's. `regions` must be as they stand at the snapshot's clock
// (weather::regionAt), and `layers` the table from snapshotLayers.
std::vector<weather::CoverageTile> deriveTiles(std::span<const std::uint64_t> cells,
                                               std::span<const weather::CloudLayer> layers,
                                               std::span<const weather::Region> regions = {},
                                               const LayerField* field = nullptr);
// One layer's tiles in a snapshot, as the TileCache that derived them holds
// them, and their generation there: two runs from one cache with the same
// non-zero generation are the very same tiles (0: not known).
struct LayerRun {
  std::uint64_t generation = 0;
  std::shared_ptr<const LayerTiles> tiles;  // null: none
  std::size_t size() const { return tiles ? tiles->size() : 0; }
};

// Each layer's run of tiles (by index of `layers`) for the cells of a cached
// covering, their weights from the cache: what deriveTiles gives, by layer,
// without copying a tile the cache already holds.
std::vector<LayerRun> deriveRuns(TileCache& cache, TileCache::Entry& entry,
                                 std::span<const weather::CloudLayer> layers,
                                 std::span<const weather::Region> regions, const LayerField* field = nullptr);

// A snapshot as the server keeps it for a subscriber. With a cache its tiles
// stay in `runs` (one per layer of snapshot.layers, shared with the cache:
// sixty-four subscribers' snapshots of one change hold no copy of a tile) and
// snapshot.tiles is empty; without one, runs is empty and the tiles are in
// snapshot.tiles.
struct BuiltSnapshot {
  weather::WeatherSnapshot snapshot;
  std::vector<LayerRun> runs;
};

// The snapshot with all its tiles (the layers' runs one after the other), as
// it goes on the wire; and how many tiles that is.
weather::WeatherSnapshot wholeSnapshot(const BuiltSnapshot& built);
std::size_t tileCount(const BuiltSnapshot& built);

// weather::diffSnapshots(wholeSnapshot(before), wholeSnapshot(after)),
// comparing tiles layer by layer and never reading the tiles of layers whose
// generation both share (a delta leaves those out anyway): what a change
// costs a subscriber grows with the tiles it changed, not with the tiles of
// its area.
std::optional<weather::WeatherDelta> diffBuilt(const BuiltSnapshot& before, const BuiltSnapshot& after);

// The snapshot answering `request` at weather clock clock_s.
weather::WeatherSnapshot buildSnapshot(const stream::Subscribe& request,
                                       std::span<const weather::CloudLayer> layers,
                                       double clock_s, std::size_t maxCells,
                                       std::span<const weather::Region> regions = {},
                                       TileCache* cache = nullptr, const LayerField* field = nullptr);
// The same, as the server keeps it (see BuiltSnapshot).
BuiltSnapshot buildSnapshotWithGenerations(const stream::Subscribe& request,
                                           std::span<const weather::CloudLayer> layers, double clock_s,
                                           std::size_t maxCells, std::span<const weather::Region> regions,
                                           TileCache* cache, const LayerField* field = nullptr);

}  // namespace sky::server
