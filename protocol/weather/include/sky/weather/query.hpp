// The weather at a point, as a flight model needs it (CIGI Weather Conditions
// Response): wind, and whether and how dense cloud is there. One function for
// every process: the renderer answers its host's Environmental Conditions
// Requests with it from the weather it holds, so the flight model flies in
// the wind that moves the clouds it sees.
#pragma once

#include <cstdint>
#include <functional>
#include <optional>
#include <span>

#include "sky/weather/model.hpp"

namespace sky::weather {

struct PointWeather {
  LayerWind wind;                       // see weatherAt for the interpolation
  double cloudDensity = 0;              // [0, 1]: coverage x density x vertical presence, densest cloud or fog layer
  std::optional<std::uint32_t> layerId; // the layer whose cloud that is (none: clear air)
  // The heaviest precipitation at the point (precipitation.hpp): its type
  // (None: none) and rate from coverage x density x vertical presence.
  CloudType precipitationType = CloudType::None;
  double precipitationRate_mmph = 0;
  // Extinction at 550 nm, 1/m: the cloud's (kCloudExtinctionPerDensity_perm
  // x cloudDensity) plus the precipitation's, as the renderer draws them.
  double extinction_perm = 0;
};

// Coverage (and density, type blend) of one layer at a surface point, when it
// varies regionally; nullopt: the layer's own uniform values apply.
using CoverageLookup = std::function<std::optional<CoverageTile>(const CloudLayer& layer, double lat_deg, double lon_deg)>;

// A layer's wind at a surface point, when it varies over the area (see
// wind_field.hpp); none: each layer's own wind applies everywhere.
using WindLookup = std::function<LayerWind(const CloudLayer& layer, double lat_deg, double lon_deg)>;

// Wind: each layer's at the point (windLookup), then: inside a layer (base to top) that layer's; between two layers linear
// in altitude (by components) from the top of the one below to the base of
// the one above; below the lowest or above the highest, the nearest layer's;
// no layers: calm. Cloud: each layer is fully present from base to top and
// fades linearly to nothing over its transition band above and below; the
// densest layer at the point wins. Precipitation layers the same way, apart
// from the cloud: the heaviest wins.
PointWeather weatherAt(std::span<const CloudLayer> layers, const CoverageLookup& lookup, double lat_deg,
                       double lon_deg, double alt_m, const WindLookup& windLookup = {});

// A lookup over a snapshot's tiles at weather clock clock_s: the tile of the
// point's S2 cell at the snapshot's level; for a layer whose tiles drift
// (CloudLayer::tilesDrift), the point first carried back by the layer's
// wind at the point (its wind field's, upwindOf) from clock_s to the
// snapshot's clock. A layer with tiles is empty where it has none; a
// layer without tiles is uniform. The lookup keeps no reference to the
// snapshot.
CoverageLookup snapshotLookup(const WeatherSnapshot& snapshot, double clock_s);
// Each layer's wind at a point from the snapshot's wind tiles (WindField).
WindLookup snapshotWindLookup(const WeatherSnapshot& snapshot);

// Visibility in cloud and fog. A point's cloud density d (PointWeather::
// cloudDensity) stands for an extinction of kCloudExtinctionPerDensity_perm
// x d at 550 nm: the renderer's fog type draws exactly that
// (renderer/core/src/cloud_types.cpp), and the CIGI answer and the
// conditions API give its Koschmieder range as the visibility there.
inline constexpr double kCloudExtinctionPerDensity_perm = 0.05;
// Koschmieder: a black object's contrast falls to the 2 % threshold after an
// optical depth of -ln 0.02 = 3.912 (WMO-No. 8's meteorological visibility);
// the renderer's atmosphere_core.glsl holds the same number for its haze.
inline constexpr double kKoschmiederDepth = 3.912;
// What "no obscuration" answers as a range, m (past the atmosphere).
inline constexpr double kUnlimitedVisibility_m = 1.0e9;
// 3.912 / extinction_perm; kUnlimitedVisibility_m for no extinction.
double koschmiederVisibility_m(double extinction_perm);
// The visibility inside cloud of density d (a PointWeather::cloudDensity).
double cloudVisibility_m(double cloudDensity);
// The visibility at a point: the Koschmieder range of its extinction.
double visibilityAt_m(const PointWeather& point);
// The fog density whose visibility is visibility_m: 3.912 / (0.05 V),
// at most 1 (so the thickest fog the model draws has V = 78 m; a shorter
// visibility is drawn as that).
double fogDensityForVisibility(double visibility_m);
inline constexpr double kMinFogVisibility_m = kKoschmiederDepth / kCloudExtinctionPerDensity_perm;

// ICAO standard atmosphere below 20 km (altitude MSL, m): 15 C and 1013.25 hPa
// at sea level, -6.5 K/km to the tropopause at 11 km (-56.5 C, 226.32 hPa),
// isothermal above. For the parts of a Weather Conditions Response the
// weather model has no field for.
double isaTemperature_c(double alt_m);
double isaPressure_hpa(double alt_m);
// The altitude (m) at which the standard atmosphere has this pressure: the
// inverse of isaPressure_hpa, clamped to its -1 to 20 km.
double isaAltitude_m(double pressure_hpa);

}  // namespace sky::weather
