// METAR reports as changes to the live weather: each station whose report
// reads a sky becomes one round region at the station, kept by ICAO across
// requests, carrying exactly the reported layers, so that at the station the
// weather is its report, between stations it blends by distance, and far from
// every station the weather around stands.
//
// The scheme (what a station's region holds):
// * Slots. A snapshot holds one base and one thickness per layer id, so a
//   layer id must mean clouds at about the same height wherever it is used.
//   Each reported group becomes its own layer in a slot: fog (VV, FG, BR...) 40,
//   cumulonimbus 41, towering cumulus 42, and the other groups by the band of
//   their base above mean sea level, 43 + band (kMetarBandTops_m). Two groups
//   of one station in one band (FEW015 SCT016) merge into one layer: the
//   largest coverage (METAR amounts are cumulative), the lowest base, the
//   highest top, the type of the densest group. The layers keep the station's
//   own base and thickness; where several stations use a slot, the snapshot's
//   table takes one of theirs, so a base drawn is at most one band away.
// * Replacement. Besides its own layers the region carries every global layer
//   id, and every layer id of the other (not METAR) regions that reach the
//   station, at coverage 0: inside the station's core its report replaces
//   every layer (a CAVOK station clears the sky), across the transition it
//   blends into the weather around. A slot a station does not report needs no
//   entry: outside regions a slot has coverage 0.
// * Geometry. The core is a circle of radius min(kStationCoreRadius_m, a
//   quarter of the distance to the nearest other station); the transition is
//   MetarOptions::radius_m, shortened so that it ends before every other
//   station's core. So no station weighs in on another's core, and the point
//   query and the renderer at a station show exactly its report. A new
//   station near earlier ones shortens their transitions: those regions are
//   set again with their layers as they stand.
// * Identity. A station's region id is found again by its position (the
//   region's centre is the station's, bit for bit) among the regions with ids
//   in [kMetarRegionFirst, kMetarRegionLast]; a station without one gets the
//   first free id on a probe sequence from a hash of its ICAO. A newer report
//   of the station replaces its region; other stations' regions stay until
//   removed on purpose (RemoveRegion, or "remove" in POST /api/metar). No
//   other input should use ids in that range (CIGI hosts use their own small
//   ids; the console's regions count up from 1).
// * A report whose sky is not observed (an automatic station's "//////", no
//   sky group) changes nothing: the station's earlier weather, or the weather
//   around, stays.
// Reports that do not parse or map are listed with the reason and the
// offending group; the good ones still make changes.
#pragma once

#include <array>
#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "sky/server/change.hpp"
#include "sky/server/metar.hpp"
#include "sky/weather/region.hpp"

namespace sky::server {

// Region ids of METAR stations: 25536 ids, room for every METAR station in the
// world (about 10000) at a probe load under one half.
inline constexpr std::uint32_t kMetarRegionFirst = 40000;
inline constexpr std::uint32_t kMetarRegionLast = 65535;  // CIGI's 16-bit region id

inline constexpr std::uint32_t kMetarFogSlot = 40;
inline constexpr std::uint32_t kMetarCumulonimbusSlot = 41;
inline constexpr std::uint32_t kMetarToweringCumulusSlot = 42;
inline constexpr std::uint32_t kMetarFirstBandSlot = 43;
// Tops of the base bands, m MSL (the last band is open above). About 150 m
// (500 ft) wide near the ground, where approach minima (200, 500, 1000 ft)
// make the ceiling matter, each band about 20 % wider than the one below it
// up to 9.2 km. With fog, precipitation and the two convective slots METAR
// uses 23 layer ids, leaving 9 of the 32 a snapshot may hold
// (kMaxScenarioLayers) to the global and other regional layers.
inline constexpr std::array<double, 18> kMetarBandTops_m = {150,  300,  450,  600,  800,  1000,
                                                            1250, 1500, 1800, 2100, 2500, 3000,
                                                            3600, 4300, 5200, 6300, 7600, 9200};
inline constexpr std::uint32_t kMetarLastSlot = kMetarFirstBandSlot + kMetarBandTops_m.size();
// A station's precipitation (metar.hpp), after the cloud slots.
inline constexpr std::uint32_t kMetarPrecipitationSlot = kMetarLastSlot + 1;

// Core radius of a station: METAR reports the aerodrome and its vicinity
// ("VC": within 8 km); 5 km also holds the centre of the level 11 S2 cell
// (about 5 km across) the renderers' tiles and the conditions query use at
// the station, so that cell is the station's own.
inline constexpr double kStationCoreRadius_m = 5000;
// Two stations closer than this are taken as one place: their cores do not
// shrink further (a region needs a size above 0).
inline constexpr double kMinStationCoreRadius_m = 50;
inline constexpr double kDefaultStationRadius_m = 60000;

struct MetarOptions {
  double radius_m = kDefaultStationRadius_m;  // how far a station reaches beyond its core, (0, 2e6]
  Timing timing;
};

// The weather the reports are applied to (WeatherView's layers and regions).
struct MetarContext {
  std::span<const weather::CloudLayer> layers;  // global
  std::span<const weather::Region> regions;     // every region, any input
};

struct MetarStationChange {
  std::string icao;
  std::uint32_t regionId = 0;
  bool replaced = false;  // the station had a region: its report replaces it
};

struct MetarPlan {
  std::vector<Result<StationWeather>> reports;  // one per input report, same order
  // One per station set, in the order of `changes`' first entries (the
  // newest report of a station in the batch wins).
  std::vector<MetarStationChange> stations;
  // SetRegion per station set, then SetRegion per earlier station whose
  // geometry changes (neighboursReshaped of them), then RemoveRegion per
  // station removed.
  std::vector<WeatherChange> changes;
  std::size_t neighboursReshaped = 0;
  // Stations removed on purpose ("remove"), and the codes that could not be
  // (not in the table, or no region), with the reason.
  std::vector<MetarStationChange> removed;
  std::vector<std::string> removeErrors;
};

// Plans the reports against `stations` (the table their positions come from)
// and the weather now. A report that maps but cannot be placed (no free
// region id, more than kMaxRegionLayers layers with the ones it clears) is
// turned into an error in `reports`. `remove`: ICAO codes whose station
// regions go.
MetarPlan planMetar(std::span<const std::string> reports, std::span<const Station> stations,
                    const MetarOptions& options, const MetarContext& now = {},
                    std::span<const std::string> remove = {});

// The slot (layer id) of one METAR-derived cloud layer (a VV fog layer is
// recognised by its place in the report, not here).
std::uint32_t metarSlot(const weather::CloudLayer& layer);

// Whether a region id is one METAR stations use.
constexpr bool isMetarRegion(std::uint32_t id) { return id >= kMetarRegionFirst && id <= kMetarRegionLast; }

// Reads a station table: CSV with a header line "icao,lat_deg,lon_deg,elevation_m".
// Errors name the line and field.
Result<std::vector<Station>> parseStationTable(std::string_view text, std::string_view sourceName);

}  // namespace sky::server
