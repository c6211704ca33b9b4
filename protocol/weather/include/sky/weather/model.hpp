// The weather model both processes agree on: cloud types (CIGI's enum values),
// a cloud layer's fields with their units and ranges, and coverage tiles on S2
// cells. The server owns the state; renderers receive it over the stream.
#pragma once

#include <cstdint>
#include <optional>
#include <string_view>
#include <vector>

#include "sky/core/result.hpp"

namespace sky::weather {

// CIGI 3.3 Weather Control cloud type (4-bit field), values as on the wire.
enum class CloudType : std::uint8_t {
  None = 0,
  Altocumulus = 1,
  Altostratus = 2,
  Cirrocumulus = 3,
  Cirrostratus = 4,
  Cirrus = 5,
  Cumulonimbus = 6,
  Cumulus = 7,
  Nimbostratus = 8,
  Stratocumulus = 9,
  Stratus = 10,
  // CIGI leaves 11-15 to the IG. Ours: fog or mist at the ground (CIGI's
  // ground-fog layer, METAR FG/BR/HZ), a uniform sheet whose density is its
  // visibility (query.hpp, fogDensityForVisibility).
  Fog = 11,
  // Precipitation below (and in) the cloud that drops it, whose density is
  // its extinction (precipitation.hpp): CIGI's precipitation layers 4-7 and
  // METAR's RA/DZ, SN/SG, PL and GR/GS.
  Rain = 12,
  Snow = 13,
  Sleet = 14,
  Hail = 15,
};
inline constexpr std::uint8_t kMaxCloudType = 15;

std::string_view toString(CloudType type);  // "cumulus"
std::optional<CloudType> cloudTypeFromString(std::string_view name);

struct LayerWind {
  double speed_mps = 0;         // horizontal, parallel to the ellipsoid, [0, 150]
  double fromDirection_deg = 0; // true, the direction the wind blows FROM, [0, 360)
  double vertical_mps = 0;      // + up, [-50, 50]
};

struct CloudLayer {
  std::uint32_t id = 0;
  CloudType type = CloudType::Cumulus;
  double base_m = 0;            // MSL, [-500, 20000]
  double thickness_m = 0;       // (0, 20000]
  double transitionBand_m = 0;  // [0, 5000]
  double coverage = 0;          // fraction of area covered, [0, 1]
  double density = 1;           // multiplier of the type's extinction, [0, 1]
  LayerWind wind;
  // Set by the server in a snapshot's or delta's layer table, not by an
  // operator: whether this layer's coverage tiles move with the wind after
  // the message's weather clock (they come from regions that drift) or stay
  // where they are (regions that do not drift, METAR stations, a forecast's
  // grid), the server sending them again when they change. Readers of the
  // tiles (snapshotLookup, the renderers' weather map) place them by it.
  bool tilesDrift = false;
};

// Checks every field against its range; the error names the first bad field,
// its value and the allowed range ("layer 3: coverage 1.4 outside [0, 1]").
Result<void> validate(const CloudLayer& layer);

// Regional value of one layer on one S2 cell. On the wire the fractions are
// quantised to 1/255 (see quantizeUnit).
struct CoverageTile {
  std::uint64_t cellId = 0;  // S2CellId, at the snapshot's tile level
  std::uint32_t layerId = 0; // [0, 65535] on the wire
  float coverage = 0;  // [0, 1]
  float density = 1;   // [0, 1]
  CloudType blendType = CloudType::None;  // type mixed into the layer's own type
  float blend = 0;     // [0, 1], weight of blendType
  bool operator==(const CoverageTile&) const = default;
};

// The wind of one layer on one S2 cell, where it differs over the area (a
// forecast's field, a region's own wind): components of the air's motion,
// east and north parallel to the ellipsoid and up. A layer without wind
// tiles has its own wind (CloudLayer::wind) everywhere; between the tiles of
// a layer that has them, see sky/weather/wind_field.hpp. On the wire each
// component is quantised to 1 cm/s (quantizeWind).
struct WindTile {
  std::uint64_t cellId = 0;  // S2CellId, at the snapshot's wind tile level
  std::uint32_t layerId = 0; // [0, 65535] on the wire
  float east_mps = 0;        // [-150, 150]
  float north_mps = 0;       // [-150, 150]
  float up_mps = 0;          // [-50, 50]
  bool operator==(const WindTile&) const = default;
};

// Wind components on the wire: metres per second to whole cm/s, clamped to
// the model's ranges (+-150 horizontal, +-50 vertical); NaN -> 0.
std::int16_t quantizeWind(double mps, double limit_mps);
inline float dequantizeWind(std::int16_t cmps) { return static_cast<float>(cmps) / 100.0f; }
// A tile as it arrives: every component rounded as on the wire.
WindTile quantized(const WindTile& tile);

// The air's temperature and humidity on one S2 cell at one of the
// snapshot's air levels (heights), where a forecast gives them. Between
// cells and levels, see sky/weather/air_field.hpp; where there is none the
// standard atmosphere holds. On the wire the temperature is quantised to
// 0.1 C and the humidity to 0.5 % (quantizedAir).
struct AirTile {
  std::uint64_t cellId = 0;  // S2CellId, at the snapshot's air tile level
  std::uint32_t level = 0;   // index into the snapshot's airLevels_m, [0, kMaxAirLevels)
  float temperature_c = 0;   // [-100, 60]
  float humidity_pct = 0;    // relative to water, [0, 100]; kNoHumidity where the source gives none
  bool operator==(const AirTile&) const = default;
};
inline constexpr std::size_t kMaxAirLevels = 32;
inline constexpr float kNoHumidity = -1;
inline constexpr double kMinAirTemperature_c = -100, kMaxAirTemperature_c = 60;
// A tile as it arrives: temperature and humidity clamped to their ranges
// and rounded as on the wire (a NaN temperature -> 0; a humidity that is
// NaN or negative -> kNoHumidity).
AirTile quantizedAir(const AirTile& tile);

struct WeatherSnapshot {
  double weatherClock_s = 0;  // seconds on the weather clock
  std::vector<CloudLayer> layers;
  int tileLevel = 0;  // S2 level of every tile, [0, 30]
  std::vector<CoverageTile> tiles;
  // Which of a subscriber's areas (sky::stream::Subscribe::areaIndex) this
  // answers: each area has its own snapshot, kept up to date by its own deltas.
  std::uint8_t areaIndex = 0;
  // Wind tiles are coarser than coverage tiles (wind varies over tens of
  // kilometres): their own S2 level.
  int windTileLevel = 0;
  std::vector<WindTile> windTiles;
  // The air's temperature and humidity: the heights they are given at (m
  // MSL, ascending, at most kMaxAirLevels) and tiles at their own S2 level.
  std::vector<float> airLevels_m;
  int airTileLevel = 0;
  std::vector<AirTile> airTiles;
};

// A change to a snapshot: layers upserted by id, layers removed (with their
// tiles and wind tiles), tiles and wind tiles upserted by (cell, layer), air
// tiles by (cell, level) at the snapshot's air levels.
struct WeatherDelta {
  double weatherClock_s = 0;
  std::vector<CloudLayer> layers;
  std::vector<std::uint32_t> removedLayerIds;
  int tileLevel = 0;  // must equal the snapshot's when tiles are present
  std::vector<CoverageTile> tiles;
  std::uint8_t areaIndex = 0;  // must equal the snapshot's
  int windTileLevel = 0;  // must equal the snapshot's when wind tiles are present
  std::vector<WindTile> windTiles;
  int airTileLevel = 0;  // must equal the snapshot's when air tiles are present
  std::vector<AirTile> airTiles;
};

// The most tiles of all kinds (cover, wind, air) a snapshot holds: as many
// as one stream frame carries (sky/stream/messages.hpp's kMaxMessageTiles),
// so that deltas of new cells cannot grow a receiver's snapshot without end.
inline constexpr std::size_t kMaxSnapshotTiles = std::size_t(1) << 18;

// Applies a delta; on error (another area's delta, a tile, wind or air tile
// level that differs from the snapshot's, a tile or wind tile of a layer that
// does not exist afterwards, an air tile past the snapshot's air levels,
// removal of an unknown layer, more than kMaxSnapshotTiles tiles afterwards)
// the snapshot is left exactly as it was.
Result<void> applyDelta(WeatherSnapshot& snapshot, const WeatherDelta& delta);

// The delta that takes `before` to `after` (applyDelta(before, delta) gives
// after exactly: same layers in the same order, same tiles by (cell, layer)):
// changed and new layers, removed layers, and the tiles and wind tiles that
// differ. None when a delta cannot say it: another area, a different tile,
// wind or air tile level, other air levels, a layer losing tiles or wind
// tiles it had or an air tile going (a delta only upserts them), or layers
// reordered; the caller then sends a snapshot.
std::optional<WeatherDelta> diffSnapshots(const WeatherSnapshot& before, const WeatherSnapshot& after);

// Fractions on the wire: [0, 1] -> 0..255, rounding to nearest; NaN -> 0.
std::uint8_t quantizeUnit(double v);
inline float dequantizeUnit(std::uint8_t q) { return static_cast<float>(q) / 255.0f; }

}  // namespace sky::weather
