// The renderer's answers to Environmental Conditions Requests, from a weather
// view: wind of the layer the point is in, standard-atmosphere temperature
// and pressure, cloud liquid water per CIGI cloud layer, only the parts asked.
#include <cmath>

#include <gtest/gtest.h>

#include "sky/app/cigi_listener.hpp"
#include "sky/weather/tiling.hpp"

namespace sky::app {
namespace {

WeatherView viewWithOneLayer() {
  WeatherView v;
  weather::CloudLayer l;
  l.id = 1;
  l.base_m = 1500;
  l.thickness_m = 1000;
  l.transitionBand_m = 100;
  l.coverage = 0.6;
  l.density = 1;
  l.wind = {12, 250, 0.5};
  v.snapshot.layers = {l};
  v.version = 1;
  return v;
}

TEST(ConditionsAnswer, WeatherAndCloudAtThePoint) {
  const WeatherView v = viewWithOneLayer();
  cigi::EnvironmentalConditionsRequest r;
  r.requestType = cigi::kRequestWeather | cigi::kRequestAerosol;
  r.requestId = 42;
  r.lat_deg = 46;
  r.lon_deg = 8;
  r.alt_m = 2000;  // inside the layer
  const auto replies = answerConditions(r, v, std::chrono::steady_clock::now());
  ASSERT_EQ(replies.size(), 2u);
  const auto& w = std::get<cigi::WeatherConditionsResponse>(replies[0]);
  EXPECT_EQ(w.requestId, 42);
  EXPECT_FLOAT_EQ(w.horizontalWind_mps, 12.0f);
  EXPECT_FLOAT_EQ(w.windDirection_deg, 250.0f);
  EXPECT_FLOAT_EQ(w.verticalWind_mps, 0.5f);
  EXPECT_FLOAT_EQ(w.airTemperature_c, 2.0f);  // 15 - 6.5 x 2
  EXPECT_NEAR(w.pressure_hpa, 795.0f, 0.1f);  // ISA at 2 km: 795.0 hPa
  EXPECT_EQ(w.humidity_pct, 100);
  // In cloud of density 0.6: extinction 0.03 /m, visual range 3.912 / 0.03.
  EXPECT_NEAR(w.visibility_m, 130.4f, 0.1f);
  const auto& a = std::get<cigi::AerosolConcentrationResponse>(replies[1]);
  EXPECT_EQ(a.requestId, 42);
  EXPECT_EQ(a.layerId, cigi::LayerId::CloudLayer1);
  EXPECT_FLOAT_EQ(a.concentration_gpm3, 0.3f);  // 0.5 g/m^3 x 0.6
}

// Rain of 4 mm/h (our layer 62, a station's slot) under the cloud: the
// answer's visibility is the rain's Koschmieder range, 3.912 / (0.25 x
// 4^0.63 /km) = 6.53 km, and CIGI's rain layer (4) answers its water,
// R / (3.6 v) = 4 / (3.6 x 6 m/s) = 0.185 g/m^3; no snow layer, no snow answer.
TEST(ConditionsAnswer, RainBelowTheCloud) {
  WeatherView v = viewWithOneLayer();
  weather::CloudLayer rain;
  rain.id = 62;
  rain.type = weather::CloudType::Rain;
  rain.base_m = 0;
  rain.thickness_m = 2500;
  rain.coverage = 1;
  rain.density = 0.25e-3 * std::pow(4.0, 0.63) / 0.01;  // extinction over 0.01 /m
  v.snapshot.layers.push_back(rain);
  cigi::EnvironmentalConditionsRequest r;
  r.requestType = cigi::kRequestWeather | cigi::kRequestAerosol;
  r.lat_deg = 46;
  r.lon_deg = 8;
  r.alt_m = 500;  // under the cloud, in the rain
  const auto replies = answerConditions(r, v, std::chrono::steady_clock::now());
  ASSERT_EQ(replies.size(), 3u);  // weather, cloud layer 1, rain
  const auto& w = std::get<cigi::WeatherConditionsResponse>(replies[0]);
  EXPECT_NEAR(w.visibility_m, 3912.0 / (0.25 * std::pow(4.0, 0.63)), 1.0);
  EXPECT_FLOAT_EQ(w.horizontalWind_mps, 12.0f) << "the cloud's wind under it, not the rain layer's calm";
  const auto& a = std::get<cigi::AerosolConcentrationResponse>(replies[2]);
  EXPECT_EQ(a.layerId, cigi::LayerId::Rain);
  EXPECT_NEAR(a.concentration_gpm3, 4.0 / (3.6 * 6.0), 1e-4);
}

TEST(ConditionsAnswer, ClearAirBelowAndOnlyWhatIsAsked) {
  const WeatherView v = viewWithOneLayer();
  cigi::EnvironmentalConditionsRequest r;
  r.requestType = cigi::kRequestWeather;
  r.alt_m = 500;  // below the layer and its band
  const auto replies = answerConditions(r, v, std::chrono::steady_clock::now());
  ASSERT_EQ(replies.size(), 1u);
  const auto& w = std::get<cigi::WeatherConditionsResponse>(replies[0]);
  EXPECT_FLOAT_EQ(w.horizontalWind_mps, 12.0f);  // the lowest layer's wind below it
  EXPECT_EQ(w.humidity_pct, kClearAirHumidity_pct);
  EXPECT_FLOAT_EQ(w.visibility_m, float(kClearVisibility_m));
  r.requestType = cigi::kRequestMaritime;  // nothing we model
  EXPECT_TRUE(answerConditions(r, v, std::chrono::steady_clock::now()).empty());
}

// The host's global wind answers where the weather has no layers (clear
// sky, or no server yet); where it has layers their winds win.
TEST(ConditionsAnswer, TheHostsWindWhereTheWeatherHasNoLayers) {
  cigi::AtmosphereControl control;
  control.horizontalWind_mps = 7.5f;
  control.windDirection_deg = 300;
  control.verticalWind_mps = -0.5f;
  const HostAtmosphere air = atmosphereFrom(control);
  cigi::EnvironmentalConditionsRequest r;
  r.requestType = cigi::kRequestWeather;
  r.alt_m = 2000;
  WeatherView clear;
  clear.version = 1;
  auto w = std::get<cigi::WeatherConditionsResponse>(
      answerConditions(r, clear, std::chrono::steady_clock::now(), std::nullopt, air)[0]);
  EXPECT_FLOAT_EQ(w.horizontalWind_mps, 7.5f);
  EXPECT_FLOAT_EQ(w.windDirection_deg, 300.0f);
  EXPECT_FLOAT_EQ(w.verticalWind_mps, -0.5f);
  // Without Atmosphere Control: calm, as before.
  w = std::get<cigi::WeatherConditionsResponse>(
      answerConditions(r, clear, std::chrono::steady_clock::now(), std::nullopt, HostAtmosphere{})[0]);
  EXPECT_FLOAT_EQ(w.horizontalWind_mps, 0.0f);
  // With layers: the layer's wind (12 m/s from 250 in viewWithOneLayer).
  w = std::get<cigi::WeatherConditionsResponse>(
      answerConditions(r, viewWithOneLayer(), std::chrono::steady_clock::now(), std::nullopt, air)[0]);
  EXPECT_FLOAT_EQ(w.horizontalWind_mps, 12.0f);
  EXPECT_FLOAT_EQ(w.windDirection_deg, 250.0f);
}

}  // namespace
}  // namespace sky::app

namespace sky::app {
namespace {

// A point beyond the detailed area's reach from the camera is answered from
// the coarse area's tiles: there a storm the detailed (uniform) snapshot
// knows nothing of. Near the camera, or with no camera known, the detailed
// snapshot answers.
TEST(ConditionsAnswer, FarPointsFromTheCoarseArea) {
  WeatherView v = viewWithOneLayer();  // layer 1 uniform at 0.6 in the detailed area
  weather::WeatherSnapshot coarse = v.snapshot;
  coarse.areaIndex = 1;
  coarse.tileLevel = 9;
  const double farLat = 46.0 + 300000.0 / 111195.0;  // 300 km north
  coarse.tiles.push_back({weather::cellAt(farLat, 8.0, 9), 1, 1.0f, 1.0f});
  v.coarse = coarse;
  // The clock at the snapshots' own (frozen): no advection moves the tile.
  const auto now = std::chrono::steady_clock::now();
  v.clock = weather::WeatherClock(coarse.weatherClock_s, 0.0, now);
  cigi::EnvironmentalConditionsRequest r;
  r.requestType = cigi::kRequestAerosol;
  r.lat_deg = farLat;
  r.lon_deg = 8;
  r.alt_m = 2000;
  const geo::Geodetic camera{46.0, 8.0, 3000};
  const auto concentration = [&](const std::optional<geo::Geodetic>& cam) {
    const auto replies = answerConditions(r, v, now, cam);
    return std::get<cigi::AerosolConcentrationResponse>(replies.at(0)).concentration_gpm3;
  };
  EXPECT_FLOAT_EQ(concentration(camera), 0.5f) << "the coarse tile's coverage 1";
  EXPECT_FLOAT_EQ(concentration(std::nullopt), 0.3f) << "no camera: the detailed snapshot";
  r.lat_deg = 46.5;  // 56 km from the camera: inside the detailed area
  EXPECT_FLOAT_EQ(concentration(camera), 0.3f);
  // A datagram's requests share one ConditionsSource (the listener builds it
  // once per datagram): each answers as it would alone, near and far.
  const ConditionsSource source(v, now);
  for (const double lat : {46.5, farLat, 46.0}) {
    r.lat_deg = lat;
    r.requestType = cigi::kRequestWeather | cigi::kRequestAerosol;
    const auto alone = answerConditions(r, v, now, camera);
    const auto shared = answerConditions(r, source, camera, HostAtmosphere{});
    ASSERT_EQ(alone.size(), shared.size());
    const auto& a = std::get<cigi::WeatherConditionsResponse>(alone[0]);
    const auto& b = std::get<cigi::WeatherConditionsResponse>(shared[0]);
    EXPECT_EQ(a.humidity_pct, b.humidity_pct);
    EXPECT_EQ(a.airTemperature_c, b.airTemperature_c);
    EXPECT_EQ(a.visibility_m, b.visibility_m);
    EXPECT_EQ(a.horizontalWind_mps, b.horizontalWind_mps);
    EXPECT_EQ(std::get<cigi::AerosolConcentrationResponse>(alone[1]).concentration_gpm3,
              std::get<cigi::AerosolConcentrationResponse>(shared[1]).concentration_gpm3);
  }
}

}  // namespace
}  // namespace sky::app

namespace sky::app {
namespace {

// With the host's Atmosphere Control (issue 19): clear air has its
// humidity and visibility, temperature and pressure lapse from its sea-level
// values by the ISA; in cloud humidity is 100 % and the visibility the
// cloud's Koschmieder range, never longer than the host's clear air.
TEST(ConditionsAnswer, TheHostsAtmosphereInClearAirAndInCloud) {
  const WeatherView v = viewWithOneLayer();
  cigi::AtmosphereControl control;
  control.humidity_pct = 85;
  control.airTemperature_c = 25;
  control.visibility_m = 3000;
  control.pressure_hpa = 1000;
  const HostAtmosphere air = atmosphereFrom(control);
  cigi::EnvironmentalConditionsRequest r;
  r.requestType = cigi::kRequestWeather;
  r.alt_m = 500;  // clear air under the layer
  auto replies = answerConditions(r, v, std::chrono::steady_clock::now(), std::nullopt, air);
  ASSERT_EQ(replies.size(), 1u);
  auto w = std::get<cigi::WeatherConditionsResponse>(replies[0]);
  EXPECT_EQ(w.humidity_pct, 85);
  EXPECT_FLOAT_EQ(w.visibility_m, 3000.0f);
  EXPECT_FLOAT_EQ(w.airTemperature_c, 21.75f);  // 25 - 6.5 x 0.5
  // ISA at 500 m is 954.61 hPa; x 1000 / 1013.25.
  EXPECT_NEAR(w.pressure_hpa, 954.61f * 1000.0f / 1013.25f, 0.05f);
  r.alt_m = 2000;  // inside the layer, density 0.6: 130.4 m, shorter than 3 km
  replies = answerConditions(r, v, std::chrono::steady_clock::now(), std::nullopt, air);
  w = std::get<cigi::WeatherConditionsResponse>(replies[0]);
  EXPECT_EQ(w.humidity_pct, 100);
  EXPECT_NEAR(w.visibility_m, 130.4f, 0.1f);
  // A host visibility shorter than the cloud's (fog of 100 m) wins in cloud too.
  control.visibility_m = 100;
  replies = answerConditions(r, v, std::chrono::steady_clock::now(), std::nullopt, atmosphereFrom(control));
  EXPECT_FLOAT_EQ(std::get<cigi::WeatherConditionsResponse>(replies[0]).visibility_m, 100.0f);
}

}  // namespace
}  // namespace sky::app
