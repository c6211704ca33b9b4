// GET /api/conformance: how far the weather the renderers draw is from the
// reports it was made from. For each METAR station (its region) and for
// points of a loaded forecast's grid, the tiles at the weather clock (the
// ones a renderer's snapshot carries, in the 8 bits the stream has) are read
// at the point through the shared lookup (weather::snapshotLookup) and
// compared with what the report or the grid says: cover in oktas per layer,
// the ceiling (the lowest base with 5 oktas or more, fog not counted), and the visibility at
// a pilot's eye over the station (the report's as mapped to its fog layer:
// metar.hpp; null for 10 km or more) against the point query's there (what
// the CIGI answer gives and the fog drawn has). At the weather clock now, or
// at a clock the query gives (`clock_s`: what a replay's frame drew).
// Tolerances: kOktaTolerance, kCeilingTolerance_m, visibilityTolerance_m.
#pragma once

#include <cstddef>
#include <optional>
#include <span>
#include <string_view>

#include <nlohmann/json.hpp>

#include "sky/core/result.hpp"
#include "sky/server/metar.hpp"

namespace sky::server {

class LiveWeather;

// A station's or grid point's layer passes within one okta (a report's
// amounts are ranges of oktas: FEW 1-2, SCT 3-4, BKN 5-7), its ceiling
// within 100 ft.
inline constexpr int kOktaTolerance = 1;
inline constexpr double kCeilingTolerance_m = 30.48;
// A visibility passes within WMO-No. 8's required measurement uncertainty
// for meteorological optical range: 50 m up to 600 m, 10 % up to 1500 m,
// 20 % above (it also covers the 8 bits the stream gives a tile's density).
double visibilityTolerance_m(double visibility_m);
// The tile level the renderers' detailed area gets (skyshell-render's 120 km
// subscription), so the check reads the tiles they read.
inline constexpr int kConformanceLevel = 11;

struct ConformanceQuery {
  std::size_t maxStations = 1000;  // [0, 10000]
  std::size_t gridPoints = 100;    // [0, 2000], spread over the grid (or the area)
  // An area to look in (stations and grid points within radius of the centre).
  std::optional<double> lat_deg, lon_deg;
  double radius_m = 0;  // (0, 2e7] with a centre
  // The weather clock to check at (a replay's frame drew its own): the
  // layers, regions and forecast as they stand then. Default: now.
  std::optional<double> clock_s;
};

Result<ConformanceQuery> parseConformanceQuery(std::string_view query);

// Oktas of a cover fraction: round(8 c), 1 for any cover below 1/16 and 7
// for any short of full (as observers report: a trace is FEW, a gap is not
// OVC).
int oktas(double cover);

// `stations` names the station regions (matched by their centre); regions
// of unknown stations are listed by id.
nlohmann::json conformanceJson(const LiveWeather& weather, std::span<const Station> stations,
                               const ConformanceQuery& q);

}  // namespace sky::server
