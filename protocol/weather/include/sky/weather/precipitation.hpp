// Precipitation: rain, snow, sleet and hail are layers of their own types
// (CloudType 12-15; CIGI leaves 11-15 to the IG), each spanning from where
// the precipitation ends (the ground, or the height its virga evaporates
// at) up into the cloud that drops it. As with fog, a precipitation layer's
// density (per layer and per tile) is its extinction: one number on the
// stream from which every reader derives the same rate, visibility and
// radar reflectivity, and which the renderer draws as the shaft's extinction
// (renderer/core/src/cloud_types.cpp holds the same constant).
//
// The laws (rates are liquid water equivalent, mm/h; extinction at 550 nm):
// * rain and hail: sigma = 0.25 R^0.63 /km, an empirical power law of the
//   form disdrometer studies fit (sigma = a R^b): 1 mm/h gives a visibility
//   of 16 km, 4 mm/h 6 km, 50 mm/h 1.3 km;
// * snow: sigma = 3.5 R^0.7 /km, so the rates of light, moderate and heavy
//   snow (kLightSnow_mmph ...) give the visibilities that define those
//   intensities where snow is reported by visibility (light over 800 m,
//   heavy under 400 m: 1.8 km, 840 m and 430 m here);
// * sleet (ice pellets, rain and snow mixed): the mean of the two;
// * radar reflectivity: Marshall-Palmer Z = 200 R^1.6 for rain and hail,
//   Gunn-Marshall Z = 2000 R^2 for snow, the mean Z for sleet (mm^6/m^3).
// The coefficients are round values of published fits, not measurements of
// ours; what matters here is that the renderer, the answers and the radar
// use the same ones.
#pragma once

#include "sky/weather/model.hpp"

namespace sky::weather {

// Rain, snow, sleet or hail.
bool isPrecipitation(CloudType type);

// A precipitation layer's density d stands for an extinction of
// kPrecipitationExtinctionPerDensity_perm x d (density 1: a visibility of
// 390 m, heavy snow; rain of 100 mm/h is density 0.45). On the stream the
// density is quantised to 1/255: light rain (1 mm/h, d = 0.025) keeps its
// extinction within 8 % and its rate within 12 %.
inline constexpr double kPrecipitationExtinctionPerDensity_perm = 0.01;

// Extinction (1/m) of precipitation of this type at this rate; 0 for a type
// that is not precipitation or a rate <= 0.
double precipitationExtinction_perm(CloudType type, double rate_mmph);
// The inverse: the rate whose extinction this is.
double precipitationRate_mmph(CloudType type, double extinction_perm);
// The layer density for a rate (clamped to [0, 1]) and the rate a density
// stands for.
double precipitationDensityForRate(CloudType type, double rate_mmph);
double precipitationRateForDensity(CloudType type, double density);
// The density whose Koschmieder visibility is visibility_m (a report's
// visibility in rain or snow), clamped to [0, 1].
double precipitationDensityForVisibility(double visibility_m);

// Radar reflectivity factor, dBZ (10 log10 Z); kNoEcho_dBZ for no
// precipitation.
inline constexpr double kNoEcho_dBZ = -99;
double reflectivity_dBZ(CloudType type, double rate_mmph);

// Typical fall speed, m/s (rain of 1-2 mm drops, aggregated snowflakes, ice
// pellets, small hail): how fast streaks fall past the camera.
double fallSpeed_mps(CloudType type);

// Water the precipitation holds in the air, g/m^3: its flux over its fall
// speed (R / (3.6 v)); what CIGI's aerosol concentration of a precipitation
// layer gives.
double precipitationWater_gpm3(CloudType type, double rate_mmph);

// Rates for the intensities a METAR gives (-RA, RA, +RA): the middle of
// light (under 2.5 mm/h), moderate (2.5-7.6) and heavy (over 7.6) rain
// (WMO-No. 8's and the US Federal Meteorological Handbook's bounds), the
// same for showers; drizzle a tenth of rain; snow in water equivalent.
inline constexpr double kLightRain_mmph = 1.0, kModerateRain_mmph = 4.0, kHeavyRain_mmph = 15.0;
inline constexpr double kLightSnow_mmph = 0.5, kModerateSnow_mmph = 1.5, kHeavySnow_mmph = 4.0;
inline constexpr double kDrizzleFactor = 0.1;

}  // namespace sky::weather
