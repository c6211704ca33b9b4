// METAR/SPECI reports become weather layers.
//
// parseMetar is a pure, tolerant decoder of one report (no I/O, no logging),
// written for reports as they really arrive from many countries. It reads the
// header (METAR/SPECI, COR, station, DDHHMMZ, NIL, AUTO/COR, wind, variable
// sector), then the body groups in any order (visibility incl. statute miles
// "1 1/2SM", RVR, present and recent weather, CAVOK, clouds, VV,
// NSC/NCD/SKC/CLR, temperature/dewpoint), up to the first trend or remarks
// keyword (NOSIG, BECMG, TEMPO, INTER, FMhhmm, PROBnn, RMK) or the first QNH
// group: what follows the pressure (recent weather RE.., wind shear WS, runway
// state, sea state W../S.., colour states BLU/GRN/...) is supplementary and
// not decoded. Letters are read as capitals ("metar ljlj ..." is a report).
//
// A group that fits no pattern (`-VCTSRA`, a stray `M`, `BKN0x5`, a second
// wind group) is skipped and listed in MetarReport::skipped with its position
// and the reason; a group read together with its neighbour (`1/4 SM`, a lone
// `CB` after `FEW050`) is listed in MetarReport::joined. Only a report whose
// station cannot be read is refused, naming the group ("group 2 'K1': station
// is not a four-character ICAO code"). Group numbers count every
// whitespace-separated group from 1, including a leading METAR/SPECI.
//
// skyFromMetar maps a decoded report to CloudLayers (see the rules at the
// function). layersFromMetarBatch does a set of reports against a station
// table, each report on its own. coverageAt interpolates total cloud cover
// between stations by inverse-distance weighting on geodesic distance.
#pragma once

#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "sky/core/result.hpp"
#include "sky/weather/model.hpp"

namespace sky::server {

enum class WindUnit : std::uint8_t { Knots, MetresPerSecond, KilometresPerHour };

struct MetarWind {
  std::optional<int> direction_deg;  // true, wind FROM, [0, 360]; empty for VRB
  bool variable = false;             // VRB: direction varies (light or convective)
  double speed_kt = 0;               // converted from the reported unit
  std::optional<double> gust_kt;     // Gff: kept, not used by the mapping
  WindUnit reportedUnit = WindUnit::Knots;
  // dddVddd: the direction varies clockwise from .. to, deg
  std::optional<int> variableFrom_deg;
  std::optional<int> variableTo_deg;
};

enum class CloudAmount : std::uint8_t { Few, Scattered, Broken, Overcast, Unknown };  // "///"
enum class ConvectiveCloud : std::uint8_t { None, Cumulonimbus, ToweringCumulus, Unknown };  // "///"

struct MetarCloud {
  CloudAmount amount = CloudAmount::Unknown;
  std::optional<int> height_ft;  // base above the station, ft; empty for "///"
  ConvectiveCloud convective = ConvectiveCloud::None;
};

// Codes meaning "no cloud to report" (CAVOK is its own flag).
enum class NoCloud : std::uint8_t { None, NSC, NCD, SKC, CLR };

struct MetarTime {
  int day = 0;     // [1, 31]
  int hour = 0;    // [0, 23]
  int minute = 0;  // [0, 59]
};

// A group the decoder skipped (not used) or read together with the group
// before it.
struct MetarGroupNote {
  std::size_t position = 0;  // 1-based group number in the report
  std::string text;          // the group as written, capitals, at most kMaxNotedGroupBytes
  std::string reason;        // "unrecognised group", "height is not three digits", ...
};

// Bounds of what a report's notes hold, whatever the input: the first
// kMaxNotedGroups notes of each kind, each group cut to kMaxNotedGroupBytes
// (a real group is at most ~20 characters: "R19R/1600V2000FT"); the rest are
// counted in MetarReport::skippedCount.
inline constexpr std::size_t kMaxNotedGroups = 32;
inline constexpr std::size_t kMaxNotedGroupBytes = 32;

// Present-weather descriptors (WMO FM 15): shallow, partial, patches, low
// drifting, blowing, showers, thunderstorm, freezing. The decoder's and the
// mapping's one list.
inline constexpr std::string_view kWeatherDescriptors[] = {"MI", "PR", "BC", "DR", "BL", "SH", "TS", "FZ"};

struct MetarReport {
  std::string icao;
  bool speci = false;
  bool nil = false;        // "NIL": the report is missing; nothing else is decoded
  bool automatic = false;  // AUTO
  bool corrected = false;  // COR
  std::optional<MetarTime> time;
  std::optional<MetarWind> wind;  // empty when absent or "/////KT"
  bool cavok = false;
  NoCloud noCloud = NoCloud::None;
  std::vector<MetarCloud> clouds;  // in report order (ascending height by rule)
  bool verticalVisibility = false;                // a VV group is present
  std::optional<int> verticalVisibility_ft;       // empty for "VV///"
  // Prevailing visibility, m (statute miles converted; the first visibility
  // group; a later one is a sector's minimum and is not kept). 9999 and
  // CAVOK are "10 km or more", P6SM "more than 6 miles" (visibilityAbove);
  // M1/4SM "less than a quarter mile" (visibilityBelow). Empty for "////"
  // or no group.
  std::optional<double> visibility_m;
  bool visibilityAbove = false;
  bool visibilityBelow = false;
  // Present weather groups as reported ("-SHRA", "BCFG", "VCTS"), in order,
  // at most kMaxNotedGroups; recent weather (RE..) and "//" not kept.
  std::vector<std::string> weather;
  std::optional<int> temperature_degC;
  std::optional<int> dewpoint_degC;
  std::optional<double> qnh_hPa;  // Q in hPa, or A (hundredths of inHg) converted
  std::vector<MetarGroupNote> skipped;  // groups not decoded, in report order (at most kMaxNotedGroups)
  std::size_t skippedCount = 0;         // every skipped group, noted or not
  std::vector<MetarGroupNote> joined;   // groups read with the one before ("SM" of "1/4 SM", "CB" of "FEW050 CB")
};

// Errors (Malformed): an empty report, no station, or a station group that is
// not four letters or digits. Everything after the station is tolerated.
Result<MetarReport> parseMetar(std::string_view report);

struct Station {
  std::string icao;
  double lat_deg = 0;
  double lon_deg = 0;
  double elevation_m = 0;  // MSL
};

// Layer thickness per cloud type, m. Not in formulas.md (which gives only the
// WMO heights and the cumulonimbus tops): typical depths from the WMO
// International Cloud Atlas descriptions, chosen as round mid values.
inline constexpr double kStratusThickness_m = 300;        // thin grey sheet, few hundred m
inline constexpr double kStratocumulusThickness_m = 500;  // rolls/patches, 200-800 m
inline constexpr double kCumulusThickness_m = 1000;       // fair-weather cumulus humilis/mediocris
inline constexpr double kToweringCumulusThickness_m = 3000;  // cumulus congestus (TCU)
inline constexpr double kAltocumulusThickness_m = 500;
inline constexpr double kAltostratusThickness_m = 1500;   // 1-2 km deep sheet
inline constexpr double kCirrusThickness_m = 1000;
// formulas.md: cumulonimbus tops reach 12-15 km; the low end, MSL.
inline constexpr double kCumulonimbusTop_m = 12000;
inline constexpr double kCumulonimbusMinThickness_m = 3000;  // a CB is at least a congestus
// VV000 means "less than 100 ft": the fog layer is at least this deep.
inline constexpr double kMinFogThickness_m = 30;
// Transition band at a layer's base and top as a fraction of its thickness: a
// soft edge for the renderer, not a METAR quantity.
inline constexpr double kTransitionFraction = 0.1;

// WMO étages by base above the station (formulas.md, mid-latitudes): low below
// 2 km, middle 2-7 km, high above. Below kStratusMaxBase_m an OVC layer is stratus.
inline constexpr double kLowCloudTop_m = 2000;
inline constexpr double kMiddleCloudTop_m = 7000;
inline constexpr double kStratusMaxBase_m = 300;

// Coverage per METAR amount: the middle of the okta range, so that the error is
// at most half the range either way (FEW 1-2 -> 1.5/8, SCT 3-4 -> 3.5/8,
// BKN 5-7 -> 6/8, OVC 8/8).
inline constexpr double kFewCoverage = 1.5 / 8;
inline constexpr double kScatteredCoverage = 3.5 / 8;
inline constexpr double kBrokenCoverage = 6.0 / 8;
inline constexpr double kOvercastCoverage = 1.0;

// Obscuration (fog, mist, haze, or the rain or snow that cuts the
// visibility) becomes a fog-type layer from the station up, whose density
// gives the reported visibility (weather::fogDensityForVisibility). Its
// depth when no VV group gives it: typical radiation fog 100-300 m deep, mist
// a little deeper, haze and smoke the boundary layer's 1-2 km, shallow fog
// (MIFG) under the eye's height of a tower, precipitation down from the
// lowest cloud base (or kPrecipitationObscurationTop_m without one). Round
// mid values, not measurements.
inline constexpr double kFogThickness_m = 150;
inline constexpr double kShallowFogThickness_m = 30;
inline constexpr double kMistThickness_m = 300;
inline constexpr double kHazeThickness_m = 1500;
inline constexpr double kPrecipitationObscurationTop_m = 1000;
// The visibility an obscuration group implies when the report gives none
// (FG: below 1 km, BR: 1-5 km, HZ and the others: at most 5 km; WMO-No. 306).
inline constexpr double kFogDefaultVisibility_m = 500;
inline constexpr double kMistDefaultVisibility_m = 3000;
inline constexpr double kHazeDefaultVisibility_m = 5000;
// Visibility from which nothing is drawn: 9999 (10 km or more) is the
// report's clear air.
inline constexpr double kClearVisibility_m = 10000;
// Patches (BC) and partial (PR) fog cover part of the area.
inline constexpr double kFogPatchesCoverage = 0.5;
inline constexpr double kPartialFogCoverage = 0.75;

// Precipitation at the station (the heaviest present-weather group with RA,
// DZ, SN, SG, PL, GR, GS or UP; not in the vicinity, not snow blowing or
// drifting) becomes a precipitation layer (precipitation.hpp) from the
// station up into the cloud that drops it: for showers and thunderstorms
// (SH, TS) the cumulonimbus or towering cumulus group, else the lowest
// broken or overcast group, else the lowest group; kPrecipitationInCloud_m
// into it (at most its depth), with its coverage. Without a cloud group
// (VV, NSC) up to kPrecipitationObscurationTop_m, coverage 1. Its rate is
// the intensity's (precipitation.hpp: kLightRain_mmph ...; drizzle a tenth;
// rain and snow together, and PL, are sleet; GR and GS hail at rain's
// rates), at most the rate whose extinction gives the reported visibility
// (a 9999 caps it at 10 km), so that the visibility drawn at the station is
// the reported one; what the precipitation leaves of the reported
// visibility's extinction is drawn as the fog layer's (below).
inline constexpr double kPrecipitationInCloud_m = 1000;
// A broken or overcast deck of stratocumulus or altostratus that steady
// rain, snow or sleet falls from (not drizzle, which falls from stratus) is
// the rain cloud, nimbostratus, and as deep as one: darker than the deck
// the same groups give without precipitation.
inline constexpr double kNimbostratusThickness_m = 2500;

// VV/// (sky obscured, vertical visibility not measured, as automatic
// stations send in fog): the fog is taken as deep as VV001, the smallest
// vertical visibility above "less than 100 ft" a report can give.
inline constexpr int kUnknownVerticalVisibility_ft = 100;

// What one report says about the sky at its station.
struct MetarSky {
  // false: the report carries no sky that can be read (an automatic station's
  // "//////", or no sky group at all): it says nothing about cloud, and the
  // weather around the station stays as it is. true: `layers` is the sky
  // (empty: reported clear).
  bool observed = false;
  std::vector<weather::CloudLayer> layers;
};

// Maps one report at its station to layers, ids 1..n in report order (VV
// first). Rules:
// * cloud base MSL = station elevation + height above the station;
// * CB -> cumulonimbus up to kCumulonimbusTop_m; TCU (towering cumulus) ->
//   cumulus, kToweringCumulusThickness_m deep; otherwise by base above the
//   station: low FEW/SCT cumulus, BKN stratocumulus, OVC stratus below
//   kStratusMaxBase_m else stratocumulus; middle FEW/SCT altocumulus, BKN/OVC
//   altostratus; high cirrus;
// * precipitation -> a precipitation layer (above), after the cloud layers;
//   a steady one's deck becomes nimbostratus (kNimbostratusThickness_m);
// * obscuration -> a fog-type layer first (id 1) from the station elevation,
//   density for the prevailing visibility (or the group's default) less the
//   precipitation's extinction (none left: no fog layer, but under VV), when a
//   report has VV, a fog/mist/haze group (FG, BR, HZ, FU, DU, SA, VA; not in
//   the vicinity, VC) or a visibility under 5 km with precipitation; top at
//   the vertical visibility (VV/// at kUnknownVerticalVisibility_ft, at
//   least kMinFogThickness_m), else at the depth its group implies (above);
//   BC patches and PR partial fog cover part of the area, denser by as much
//   (so coverage x density, what a sight line through patches and gaps
//   meets, is the reported visibility's); a visibility of 10 km or more
//   draws no layer, except under a VV group (the sky is obscured whatever
//   the visibility says: kFogDefaultVisibility_m);
// * a cloud group with a height and unknown amount ("///074///", a ceilometer
//   that saw a base but no amount) is taken as FEW: cloud is there, and FEW is
//   the least the report can mean; a group with no height ("FEW///",
//   "//////") cannot be placed and gives no layer; an unknown type is chosen
//   from the height;
// * every layer gets the surface wind (VRB -> direction 0; calm or missing
//   wind -> 0 m/s; gusts ignored);
// * CAVOK/NSC/NCD/SKC/CLR with no cloud group -> observed, no layers;
// * nothing of the above -> not observed (MetarSky::observed false), also
//   when the report has fog but no sky ("1200 BR //////": the station's
//   weather replaces every layer or none, so its fog is not drawn).
// Errors (InvalidArgument): a NIL report, a station of another ICAO or with
// non-finite position, a layer weather::validate rejects (BKN999: a base
// above 20 km).
Result<MetarSky> skyFromMetar(const MetarReport& report, const Station& station);

struct StationWeather {
  Station station;
  MetarReport report;
  bool skyObserved = false;                 // MetarSky::observed
  std::vector<weather::CloudLayer> layers;  // MetarSky::layers
};

// One result per input report, same order. A report that does not parse, whose
// station is not in the table, or that does not map, is an error ("report 3:
// group 2 'K1': station is not a four-character ICAO code") and the others
// still apply. Several reports of one station give several results; the
// caller picks.
std::vector<Result<StationWeather>> layersFromMetarBatch(std::span<const std::string> reports,
                                                         std::span<const Station> stations);

// Total cloud cover of a station's layers: the largest layer coverage (METAR
// amounts are cumulative, each one counts the layers below it too).
double totalCoverage(std::span<const weather::CloudLayer> layers);

// Total cloud cover at a point: inverse-distance weighting (power 2) of the
// stations' total cover on geodesic distance; a station within 1 m gives its
// own value. Empty when there are no stations.
std::optional<double> coverageAt(double lat_deg, double lon_deg,
                                 std::span<const StationWeather> stations);

}  // namespace sky::server
