// A METAR batch as changes to the live weather: each station whose report
// maps becomes a round region at the station carrying its layers, so the
// weather between stations blends by distance and far from every station
// the global layers stand.
//
// * Layers are put in slots by family, so that the same slot means the same
//   kind of cloud at every station and blends between them: fog (VV) 40, low
//   41, middle 42, high 43, convective (CB/TCU) 44. Several groups in one
//   slot (FEW015 SCT025 BKN040) merge into one layer: the largest coverage
//   (METAR amounts are cumulative), the lowest base and the highest top, the
//   type of the densest group.
// * Every station's region carries every slot any station of the batch has;
//   a slot the station does not report is there at coverage 0 (a CAVOK
//   station clears the sky around it).
// * Region ids are kMetarRegionBase + the station's index in the table, so a
//   newer report of a station replaces its region.
// * The region is a circle of kStationCore_m diameter with a transition
//   perimeter of radius_m: a station's weight falls smoothly from 1 at the
//   station to 0 at radius_m, and where several stations reach, their layers
//   average by weight.
// Reports that do not parse or map are listed with the reason and the
// offending group; the good ones still make changes.
#pragma once

#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "sky/server/change.hpp"
#include "sky/server/metar.hpp"

namespace sky::server {

inline constexpr std::uint32_t kMetarRegionBase = 60000;
inline constexpr std::uint32_t kMetarFogSlot = 40, kMetarLowSlot = 41, kMetarMiddleSlot = 42, kMetarHighSlot = 43,
                               kMetarConvectiveSlot = 44;
inline constexpr double kStationCore_m = 2000;
inline constexpr double kDefaultStationRadius_m = 60000;

struct MetarOptions {
  double radius_m = kDefaultStationRadius_m;  // (0, 2e6]
  Timing timing;
};

struct MetarPlan {
  std::vector<Result<StationWeather>> reports;  // one per input report, same order
  std::vector<WeatherChange> changes;           // SetRegion per station that mapped (the newest report of a station wins)
};

MetarPlan planMetar(std::span<const std::string> reports, std::span<const Station> stations,
                    const MetarOptions& options);

// The slot (layer id) of one METAR-derived cloud layer by its type (a VV fog
// layer is recognised by its place in the report, not here).
std::uint32_t metarSlot(const weather::CloudLayer& layer);

// Reads a station table: CSV with a header line "icao,lat_deg,lon_deg,elevation_m".
// Errors name the line and field.
Result<std::vector<Station>> parseStationTable(std::string_view text, std::string_view sourceName);

}  // namespace sky::server
