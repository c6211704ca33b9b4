// The renderer's answers to Environmental Conditions Requests, from a weather
// view: wind of the layer the point is in, standard-atmosphere temperature
// and pressure, cloud liquid water per CIGI cloud layer, only the parts asked.
#include <gtest/gtest.h>

#include "sky/app/cigi_listener.hpp"

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

}  // namespace
}  // namespace sky::app
