// CIGI Weather Control / Environmental Region Control -> change requests.
// Datagrams are built with the protocol encoder in both byte orders and
// decoded by the protocol decoder, as the listener will; expected values are
// worked out by hand from the packet fields.
#include "sky/server/cigi_weather.hpp"
#include "sky/weather/precipitation.hpp"
#include "sky/weather/query.hpp"

#include <gtest/gtest.h>

#include <variant>

namespace sky::server {
namespace {

cigi::Datagram roundTrip(const std::vector<cigi::Packet>& packets, cigi::ByteOrder order) {
  cigi::DatagramWriter w(order);
  w.add(cigi::IgControl{});
  for (const auto& p : packets) w.add(p);
  auto d = cigi::decodeDatagram(w.bytes());
  EXPECT_TRUE(d) << (d ? "" : d.error().detail);
  return *d;
}

cigi::WeatherControl layer2() {
  cigi::WeatherControl wc;
  wc.layerId = cigi::LayerId::CloudLayer2;
  wc.cloudType = weather::CloudType::Stratocumulus;
  wc.coverage_pct = 62.5f;
  wc.baseElevation_m = 1500;
  wc.thickness_m = 800;
  wc.transitionBand_m = 100;
  wc.horizontalWind_mps = 12.5f;
  wc.verticalWind_mps = -0.5f;
  wc.windDirection_deg = -90;  // from the west: 270 in [0, 360)
  return wc;
}

class CigiWeather : public ::testing::TestWithParam<cigi::ByteOrder> {};

TEST_P(CigiWeather, GlobalLayerMapsEveryField) {
  CigiWeatherMapper m;
  auto changes = m.map(roundTrip({layer2()}, GetParam()));
  ASSERT_TRUE(changes) << changes.error().detail;
  ASSERT_EQ(changes->size(), 1u);
  const auto& set = std::get<SetLayer>((*changes)[0]);
  EXPECT_EQ(set.layer.id, 2u);
  EXPECT_EQ(set.layer.type, weather::CloudType::Stratocumulus);
  EXPECT_DOUBLE_EQ(set.layer.coverage, 0.625);
  EXPECT_DOUBLE_EQ(set.layer.base_m, 1500);
  EXPECT_DOUBLE_EQ(set.layer.thickness_m, 800);
  EXPECT_DOUBLE_EQ(set.layer.transitionBand_m, 100);
  EXPECT_DOUBLE_EQ(set.layer.wind.speed_mps, 12.5);
  EXPECT_DOUBLE_EQ(set.layer.wind.fromDirection_deg, 270);
  EXPECT_DOUBLE_EQ(set.layer.wind.vertical_mps, -0.5);
  EXPECT_FALSE(set.timing.at_s);
  EXPECT_EQ(set.timing.ramp_s, 0);
}

TEST_P(CigiWeather, RepeatedIdenticalPacketsProduceNoChange) {
  CigiWeatherMapper m;
  ASSERT_EQ(m.map(roundTrip({layer2()}, GetParam()))->size(), 1u);
  for (int frame = 0; frame < 60; ++frame) {
    auto again = m.map(roundTrip({layer2()}, GetParam()));
    ASSERT_TRUE(again);
    EXPECT_TRUE(again->empty());
  }
  auto moved = layer2();
  moved.coverage_pct = 70;
  auto changed = m.map(roundTrip({moved}, GetParam()));
  ASSERT_EQ(changed->size(), 1u);
  EXPECT_DOUBLE_EQ(std::get<SetLayer>((*changed)[0]).layer.coverage, 0.70);
}

TEST_P(CigiWeather, DisableRemovesOnlyALayerItEnabled) {
  CigiWeatherMapper m;
  auto off = layer2();
  off.weatherEnable = false;
  EXPECT_TRUE(m.map(roundTrip({off}, GetParam()))->empty());  // never enabled: left alone
  ASSERT_EQ(m.map(roundTrip({layer2()}, GetParam()))->size(), 1u);
  auto removed = m.map(roundTrip({off}, GetParam()));
  ASSERT_EQ(removed->size(), 1u);
  EXPECT_EQ(std::get<RemoveLayer>((*removed)[0]).layerId, 2u);
  EXPECT_TRUE(m.map(roundTrip({off}, GetParam()))->empty());
}

TEST_P(CigiWeather, SandAndDustIgnoredIgDefinedKept) {
  CigiWeatherMapper m;
  auto sand = layer2();
  sand.layerId = cigi::LayerId::Sand;
  sand.cloudType = weather::CloudType::None;
  auto ig = layer2();
  ig.layerId = cigi::LayerId{12};
  auto changes = m.map(roundTrip({sand, ig}, GetParam()));
  ASSERT_TRUE(changes);
  ASSERT_EQ(changes->size(), 1u);
  EXPECT_EQ(std::get<SetLayer>((*changes)[0]).layer.id, 12u);
  EXPECT_EQ(m.ignoredLayers(), 1u);
}

// Rain, snow, sleet and hail (4-7) are our precipitation layers of those
// ids: the rate from the visibility range, or from the severity without one.
TEST_P(CigiWeather, PrecipitationLayersTakeTheirRateFromVisibilityOrSeverity) {
  CigiWeatherMapper m;
  cigi::WeatherControl rain = layer2();
  rain.layerId = cigi::LayerId::Rain;
  rain.cloudType = weather::CloudType::None;  // not used
  rain.baseElevation_m = 0;
  rain.thickness_m = 1500;
  rain.coverage_pct = 100;
  rain.visibility_m = 2500;
  cigi::WeatherControl snow = rain;
  snow.layerId = cigi::LayerId::Snow;
  snow.visibility_m = 0;
  snow.severity = 4;  // heavy
  auto changes = m.map(roundTrip({rain, snow}, GetParam()));
  ASSERT_TRUE(changes) << changes.error().detail;
  ASSERT_EQ(changes->size(), 2u);
  const auto& r = std::get<SetLayer>((*changes)[0]).layer;
  const auto& s = std::get<SetLayer>((*changes)[1]).layer;
  EXPECT_EQ(r.id, 4u);
  EXPECT_EQ(r.type, weather::CloudType::Rain);
  EXPECT_NEAR(weather::koschmiederVisibility_m(weather::kPrecipitationExtinctionPerDensity_perm * r.density), 2500, 1e-3);
  EXPECT_EQ(s.id, 5u);
  EXPECT_EQ(s.type, weather::CloudType::Snow);
  EXPECT_NEAR(weather::precipitationRateForDensity(weather::CloudType::Snow, s.density), weather::kHeavySnow_mmph, 1e-9);
  EXPECT_EQ(m.ignoredLayers(), 0u);
  // A visibility range the codec would not pass (negative, not finite) is
  // refused by the mapping too, naming the field.
  rain.visibility_m = -1;
  auto refused = cloudLayerFrom(rain);
  ASSERT_FALSE(refused);
  EXPECT_NE(refused.error().detail.find("visibility range"), std::string::npos) << refused.error().detail;
}

TEST_P(CigiWeather, GroundFogIsAFogLayerOfItsVisibilityRange) {
  CigiWeatherMapper m;
  cigi::WeatherControl fog;
  fog.layerId = cigi::LayerId::GroundFog;
  fog.cloudType = weather::CloudType::Stratus;  // not used: ground fog is fog
  fog.coverage_pct = 100;
  fog.baseElevation_m = 120;
  fog.thickness_m = 90;
  fog.visibility_m = 400;
  auto changes = m.map(roundTrip({fog}, GetParam()));
  ASSERT_TRUE(changes) << changes.error().detail;
  ASSERT_EQ(changes->size(), 1u);
  const auto& set = std::get<SetLayer>((*changes)[0]);
  EXPECT_EQ(set.layer.id, 0u);
  EXPECT_EQ(set.layer.type, weather::CloudType::Fog);
  EXPECT_DOUBLE_EQ(set.layer.base_m, 120);
  EXPECT_DOUBLE_EQ(set.layer.thickness_m, 90);
  EXPECT_NEAR(weather::cloudVisibility_m(set.layer.density), 400, 1e-3);  // the float's 400 exactly
  // No visibility range: refused, naming the field; nothing changes.
  fog.visibility_m = 0;
  auto refused = m.map(roundTrip({fog}, GetParam()));
  ASSERT_FALSE(refused);
  EXPECT_NE(refused.error().detail.find("visibility range"), std::string::npos) << refused.error().detail;
}

TEST_P(CigiWeather, RegionWithItsLayers) {
  CigiWeatherMapper m;
  cigi::EnvironmentalRegionControl erc;
  erc.regionId = 7;
  erc.lat_deg = 47.5;
  erc.lon_deg = 8.25;
  erc.sizeX_m = 20000;
  erc.sizeY_m = 10000;
  erc.cornerRadius_m = 2000;
  erc.rotation_deg = 30;
  erc.transitionPerimeter_m = 5000;
  erc.mergeWeather = true;  // ignored
  auto wc = layer2();
  wc.scope = cigi::WeatherScope::Regional;
  wc.entityOrRegionId = 7;
  auto changes = m.map(roundTrip({erc, wc}, GetParam()));
  ASSERT_TRUE(changes) << changes.error().detail;
  ASSERT_EQ(changes->size(), 1u);
  const auto& r = std::get<SetRegion>((*changes)[0]).region;
  EXPECT_EQ(r.id, 7u);
  EXPECT_DOUBLE_EQ(r.centerLat_deg, 47.5);
  EXPECT_DOUBLE_EQ(r.centerLon_deg, 8.25);
  EXPECT_DOUBLE_EQ(r.sizeX_m, 20000);
  EXPECT_DOUBLE_EQ(r.sizeY_m, 10000);
  EXPECT_DOUBLE_EQ(r.cornerRadius_m, 2000);
  EXPECT_DOUBLE_EQ(r.rotation_deg, 30);
  EXPECT_DOUBLE_EQ(r.transition_m, 5000);
  ASSERT_EQ(r.layers.size(), 1u);
  EXPECT_DOUBLE_EQ(r.layers[0].coverage, 0.625);
  EXPECT_TRUE(m.map(roundTrip({erc, wc}, GetParam()))->empty());

  erc.state = cigi::RegionState::Inactive;
  auto off = m.map(roundTrip({erc}, GetParam()));
  ASSERT_EQ(off->size(), 1u);
  EXPECT_EQ(std::get<RemoveRegion>((*off)[0]).regionId, 7u);
  erc.state = cigi::RegionState::Active;  // back with its remembered layer
  auto on = m.map(roundTrip({erc}, GetParam()));
  ASSERT_EQ(on->size(), 1u);
  EXPECT_EQ(std::get<SetRegion>((*on)[0]).region.layers.size(), 1u);
  erc.state = cigi::RegionState::Destroyed;
  EXPECT_EQ(m.map(roundTrip({erc}, GetParam()))->size(), 1u);
}

TEST_P(CigiWeather, RejectsNameThePacketAndFieldAndKeepState) {
  CigiWeatherMapper m;
  auto thick = layer2();
  thick.thickness_m = 0;  // our layers need thickness > 0
  auto bad = m.map(roundTrip({layer2(), thick}, GetParam()));
  ASSERT_FALSE(bad);
  EXPECT_EQ(bad.error().code, ErrorCode::InvalidArgument);
  EXPECT_NE(bad.error().detail.find("packet 2 (Weather Control)"), std::string::npos) << bad.error().detail;
  EXPECT_NE(bad.error().detail.find("thickness_m"), std::string::npos) << bad.error().detail;
  // Nothing remembered from the rejected datagram: layer 2 is still new.
  EXPECT_EQ(m.map(roundTrip({layer2()}, GetParam()))->size(), 1u);

  auto entity = layer2();
  entity.scope = cigi::WeatherScope::Entity;
  auto e = m.map(roundTrip({entity}, GetParam()));
  ASSERT_FALSE(e);
  EXPECT_NE(e.error().detail.find("scope entity"), std::string::npos);

  cigi::EnvironmentalRegionControl erc;
  erc.regionId = 3;
  erc.sizeX_m = 0;  // our regions need a size > 0
  erc.sizeY_m = 1000;
  auto r = m.map(roundTrip({erc}, GetParam()));
  ASSERT_FALSE(r);
  EXPECT_NE(r.error().detail.find("Environmental Region Control"), std::string::npos) << r.error().detail;
  EXPECT_NE(r.error().detail.find("size_x_m"), std::string::npos) << r.error().detail;
}

// Found by fuzz_cigi_weather: a datagram that enables and then disables the
// same layer (or activates and deactivates a region) must have one net
// effect, so resending it changes nothing.
TEST_P(CigiWeather, OneDatagramHasOneNetEffectPerLayerAndRegion) {
  CigiWeatherMapper m;
  auto off = layer2();
  off.weatherEnable = false;
  auto onThenOff = m.map(roundTrip({layer2(), off}, GetParam()));
  ASSERT_TRUE(onThenOff);
  EXPECT_TRUE(onThenOff->empty()) << "never enabled before, disabled at the end: nothing";
  auto offThenOn = m.map(roundTrip({off, layer2()}, GetParam()));
  ASSERT_EQ(offThenOn->size(), 1u);
  EXPECT_TRUE(std::holds_alternative<SetLayer>((*offThenOn)[0]));
  for (int frame = 0; frame < 3; ++frame) EXPECT_TRUE(m.map(roundTrip({off, layer2()}, GetParam()))->empty());

  cigi::EnvironmentalRegionControl active;
  active.regionId = 4;
  active.lat_deg = 10;
  active.lon_deg = 20;
  active.sizeX_m = 5000;
  active.sizeY_m = 5000;
  auto inactive = active;
  inactive.state = cigi::RegionState::Inactive;
  auto wc = layer2();
  wc.scope = cigi::WeatherScope::Regional;
  wc.entityOrRegionId = 4;
  auto placed = m.map(roundTrip({inactive, active, wc}, GetParam()));
  ASSERT_EQ(placed->size(), 1u);
  EXPECT_TRUE(std::holds_alternative<SetRegion>((*placed)[0]));
  for (int frame = 0; frame < 3; ++frame)
    EXPECT_TRUE(m.map(roundTrip({inactive, active, wc}, GetParam()))->empty());
  auto gone = m.map(roundTrip({active, wc, inactive}, GetParam()));
  ASSERT_EQ(gone->size(), 1u);
  EXPECT_TRUE(std::holds_alternative<RemoveRegion>((*gone)[0]));
  EXPECT_TRUE(m.map(roundTrip({active, wc, inactive}, GetParam()))->empty());
}

INSTANTIATE_TEST_SUITE_P(ByteOrders, CigiWeather,
                         ::testing::Values(cigi::ByteOrder::Big, cigi::ByteOrder::Little));

}  // namespace
}  // namespace sky::server
