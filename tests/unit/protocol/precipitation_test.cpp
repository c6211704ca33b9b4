// Precipitation's numbers (precipitation.hpp) against the laws they state,
// computed here from the published forms (not from the code's own
// functions), and the point query's precipitation: rate, type, visibility,
// and that a precipitation layer neither counts as cloud nor replaces the
// air's wind under its cloud.
#include <cmath>

#include <gtest/gtest.h>

#include "sky/weather/precipitation.hpp"
#include "sky/weather/query.hpp"

namespace sky::weather {
namespace {

TEST(Precipitation, ExtinctionFollowsTheStatedLaws) {
  // Rain: sigma = 0.25 R^0.63 /km; the Koschmieder visibility 3.912 / sigma.
  EXPECT_NEAR(precipitationExtinction_perm(CloudType::Rain, 1.0), 0.25e-3, 1e-12);
  EXPECT_NEAR(koschmiederVisibility_m(precipitationExtinction_perm(CloudType::Rain, 1.0)), 15648, 1);
  EXPECT_NEAR(koschmiederVisibility_m(precipitationExtinction_perm(CloudType::Rain, 50.0)), 3912 / (0.25 * std::pow(50.0, 0.63)), 1);
  // Snow: 3.5 R^0.7 /km: light, moderate and heavy snow give 1.8 km, 840 m
  // and 430 m (over 800 m, between, under 400-ish: the visibility bands
  // that define snow's intensity).
  EXPECT_NEAR(koschmiederVisibility_m(precipitationExtinction_perm(CloudType::Snow, kLightSnow_mmph)), 1820, 10);
  EXPECT_NEAR(koschmiederVisibility_m(precipitationExtinction_perm(CloudType::Snow, kModerateSnow_mmph)), 840, 10);
  EXPECT_NEAR(koschmiederVisibility_m(precipitationExtinction_perm(CloudType::Snow, kHeavySnow_mmph)), 423, 10);
  // Sleet between the two; hail as rain.
  const double r = 2.0;
  EXPECT_NEAR(precipitationExtinction_perm(CloudType::Sleet, r),
              0.5 * (0.25e-3 * std::pow(r, 0.63) + 3.5e-3 * std::pow(r, 0.7)), 1e-12);
  EXPECT_EQ(precipitationExtinction_perm(CloudType::Hail, r), precipitationExtinction_perm(CloudType::Rain, r));
  // Not precipitation, or no rate: none.
  EXPECT_EQ(precipitationExtinction_perm(CloudType::Cumulus, 5), 0);
  EXPECT_EQ(precipitationExtinction_perm(CloudType::Rain, 0), 0);
  EXPECT_EQ(precipitationExtinction_perm(CloudType::Rain, -3), 0);
  EXPECT_EQ(precipitationExtinction_perm(CloudType::Rain, std::nan("")), 0);
}

TEST(Precipitation, RateDensityAndExtinctionRoundTrip) {
  for (CloudType t : {CloudType::Rain, CloudType::Snow, CloudType::Sleet, CloudType::Hail})
    for (double rate : {0.1, 1.0, 4.0, 15.0}) {
      SCOPED_TRACE(std::string(toString(t)) + " " + std::to_string(rate));
      const double sigma = precipitationExtinction_perm(t, rate);
      EXPECT_NEAR(precipitationRate_mmph(t, sigma), rate, 1e-9 * rate);
      const double d = precipitationDensityForRate(t, rate);
      if (d < 1) {
        EXPECT_NEAR(precipitationRateForDensity(t, d), rate, 1e-9 * rate);
      }
      EXPECT_NEAR(d, std::min(1.0, sigma / kPrecipitationExtinctionPerDensity_perm), 1e-12);
    }
  // The stream's 8 bits keep light rain's rate within 12 % (the header's claim).
  const double d = precipitationDensityForRate(CloudType::Rain, kLightRain_mmph);
  const double q = std::round(d * 255) / 255;
  EXPECT_NEAR(precipitationRateForDensity(CloudType::Rain, q), kLightRain_mmph, 0.12 * kLightRain_mmph);
  // A visibility's density gives that visibility back.
  for (double v : {500.0, 2000.0, 8000.0})
    EXPECT_NEAR(koschmiederVisibility_m(kPrecipitationExtinctionPerDensity_perm * precipitationDensityForVisibility(v)), v,
                1e-9 * v);
}

TEST(Precipitation, ReflectivityIsMarshallPalmerForRainAndGunnMarshallForSnow) {
  // Z = 200 R^1.6: 1 mm/h is 23.0 dBZ, 10 mm/h 39.0, 100 mm/h 55.0.
  EXPECT_NEAR(reflectivity_dBZ(CloudType::Rain, 1), 10 * std::log10(200.0), 1e-9);
  EXPECT_NEAR(reflectivity_dBZ(CloudType::Rain, 10), 10 * std::log10(200.0) + 16, 1e-9);
  EXPECT_NEAR(reflectivity_dBZ(CloudType::Rain, 100), 10 * std::log10(200.0) + 32, 1e-9);
  // Z = 2000 R^2: 1 mm/h water is 33.0 dBZ.
  EXPECT_NEAR(reflectivity_dBZ(CloudType::Snow, 1), 10 * std::log10(2000.0), 1e-9);
  EXPECT_NEAR(reflectivity_dBZ(CloudType::Sleet, 1), 10 * std::log10(1100.0), 1e-9);
  EXPECT_EQ(reflectivity_dBZ(CloudType::Rain, 0), kNoEcho_dBZ);
  EXPECT_EQ(reflectivity_dBZ(CloudType::Stratus, 5), kNoEcho_dBZ);
  // Water content: flux over fall speed, R / (3.6 v) g/m^3.
  EXPECT_NEAR(precipitationWater_gpm3(CloudType::Rain, 3.6), 1.0 / fallSpeed_mps(CloudType::Rain), 1e-12);
}

CloudLayer layer(std::uint32_t id, CloudType type, double base, double thickness, double coverage, double density,
                 LayerWind wind = {}) {
  CloudLayer l;
  l.id = id;
  l.type = type;
  l.base_m = base;
  l.thickness_m = thickness;
  l.coverage = coverage;
  l.density = density;
  l.wind = wind;
  return l;
}

TEST(Precipitation, ThePointQueryAnswersRateTypeAndVisibility) {
  // Moderate rain from the ground (200 m) into a nimbostratus at 1200 m.
  const double d = precipitationDensityForRate(CloudType::Rain, kModerateRain_mmph);
  const CloudLayer layers[] = {layer(1, CloudType::Nimbostratus, 1200, 2000, 1.0, 1.0, {15, 250, 0}),
                               layer(62, CloudType::Rain, 200, 1500, 1.0, d, {0, 0, 0})};
  const PointWeather under = weatherAt(layers, nullptr, 46, 14, 500);
  EXPECT_EQ(under.precipitationType, CloudType::Rain);
  EXPECT_NEAR(under.precipitationRate_mmph, kModerateRain_mmph, 1e-9);
  EXPECT_EQ(under.cloudDensity, 0) << "rain is not cloud";
  EXPECT_FALSE(under.layerId);
  EXPECT_NEAR(visibilityAt_m(under), 3.912 / (0.25e-3 * std::pow(kModerateRain_mmph, 0.63)), 1);
  // The rain layer's calm is not the air's wind: under the cloud the wind is
  // the nimbostratus's (the lowest layer's, below it).
  EXPECT_DOUBLE_EQ(under.wind.speed_mps, 15);
  // In the cloud's base: both, their extinctions added.
  const PointWeather in = weatherAt(layers, nullptr, 46, 14, 1500);
  EXPECT_EQ(in.layerId, 1u);
  EXPECT_NEAR(in.extinction_perm,
              kCloudExtinctionPerDensity_perm * 1.0 + precipitationExtinction_perm(CloudType::Rain, kModerateRain_mmph),
              1e-12);
  // Above the rain's top: none.
  const PointWeather above = weatherAt(layers, nullptr, 46, 14, 3000);
  EXPECT_EQ(above.precipitationType, CloudType::None);
  EXPECT_EQ(above.precipitationRate_mmph, 0);
  // Half the area raining: the mean extinction, a lower rate.
  const CloudLayer half[] = {layer(62, CloudType::Rain, 0, 1000, 0.5, d)};
  const PointWeather h = weatherAt(half, nullptr, 46, 14, 500);
  EXPECT_NEAR(h.extinction_perm, 0.5 * precipitationExtinction_perm(CloudType::Rain, kModerateRain_mmph), 1e-12);
  // Nothing at all: unlimited.
  EXPECT_EQ(visibilityAt_m(weatherAt({}, nullptr, 0, 0, 0)), kUnlimitedVisibility_m);
}

}  // namespace
}  // namespace sky::weather
