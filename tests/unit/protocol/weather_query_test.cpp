// The point query every process shares: wind inside, between, below and above
// layers (hand-computed components), cloud presence through the transition
// band, and coverage from a snapshot's tiles carried by the layer's wind.
#include <cmath>

#include <gtest/gtest.h>

#include "sky/weather/advection.hpp"
#include "sky/weather/query.hpp"
#include "sky/weather/tiling.hpp"

namespace sky::weather {
namespace {

CloudLayer layer(std::uint32_t id, double base, double thickness, double band, double coverage, LayerWind wind) {
  CloudLayer l;
  l.id = id;
  l.base_m = base;
  l.thickness_m = thickness;
  l.transitionBand_m = band;
  l.coverage = coverage;
  l.density = 1;
  l.wind = wind;
  return l;
}

TEST(WeatherQuery, CalmAndClearWithoutLayers) {
  const PointWeather w = weatherAt({}, nullptr, 10, 20, 3000);
  EXPECT_EQ(w.wind.speed_mps, 0);
  EXPECT_EQ(w.cloudDensity, 0);
  EXPECT_FALSE(w.layerId);
}

TEST(WeatherQuery, WindInsideBetweenBelowAndAboveLayers) {
  // A westerly 10 m/s from 1000-2000 m (air moving east), a northerly 20 m/s
  // from 5000-6000 m (air moving south), vertical 1 and -3 m/s.
  const CloudLayer layers[] = {layer(2, 5000, 1000, 0, 0.5, {20, 0, -3}), layer(1, 1000, 1000, 200, 0.6, {10, 270, 1})};
  auto at = [&](double alt) { return weatherAt(layers, nullptr, 47, 8, alt); };
  EXPECT_DOUBLE_EQ(at(1500).wind.speed_mps, 10);
  EXPECT_DOUBLE_EQ(at(1500).wind.fromDirection_deg, 270);
  EXPECT_DOUBLE_EQ(at(300).wind.speed_mps, 10);    // below the lowest: its wind
  EXPECT_DOUBLE_EQ(at(9000).wind.speed_mps, 20);   // above the highest: its wind
  EXPECT_DOUBLE_EQ(at(9000).wind.vertical_mps, -3);
  // Halfway from 2000 to 5000 m: east 5, north -10 m/s: 11.18 m/s going to
  // bearing 153.43, so from 333.43 deg; vertical (1 - 3) / 2 = -1.
  const PointWeather mid = at(3500);
  EXPECT_NEAR(mid.wind.speed_mps, std::sqrt(125.0), 1e-9);
  EXPECT_NEAR(mid.wind.fromDirection_deg, 333.434948822922, 1e-6);
  EXPECT_NEAR(mid.wind.vertical_mps, -1.0, 1e-12);
  // A quarter of the way: east 7.5, north -5: from atan2(-7.5, 5) = 303.69 deg.
  EXPECT_NEAR(at(2750).wind.fromDirection_deg, 303.690067525979, 1e-6);
}

TEST(WeatherQuery, CloudPresenceThroughTheTransitionBand) {
  const CloudLayer layers[] = {layer(1, 1000, 1000, 200, 0.6, {10, 270, 0})};
  auto density = [&](double alt) { return weatherAt(layers, nullptr, 47, 8, alt).cloudDensity; };
  EXPECT_DOUBLE_EQ(density(1500), 0.6);
  EXPECT_DOUBLE_EQ(density(1000), 0.6);
  EXPECT_DOUBLE_EQ(density(2000), 0.6);
  EXPECT_DOUBLE_EQ(density(900), 0.3);   // half way through the band below
  EXPECT_DOUBLE_EQ(density(2150), 0.15); // three quarters through the band above
  EXPECT_DOUBLE_EQ(density(799), 0.0);
  EXPECT_EQ(weatherAt(layers, nullptr, 47, 8, 1500).layerId, std::optional<std::uint32_t>(1));
  EXPECT_FALSE(weatherAt(layers, nullptr, 47, 8, 3000).layerId);
}

TEST(WeatherQuery, SnapshotTilesAreCarriedByTheWind) {
  constexpr int kLevel = 12;  // cells ~2.4 km across
  WeatherSnapshot s;
  s.weatherClock_s = 100;
  s.tileLevel = kLevel;
  s.layers = {layer(1, 1000, 1000, 0, 0.0, {10, 270, 0}), layer(2, 3000, 500, 0, 0.4, {0, 0, 0})};
  s.layers[0].tilesDrift = true;  // a drifting region's tiles
  const SurfacePoint p{47.0, 8.0};
  s.tiles.push_back({cellAt(p.lat_deg, p.lon_deg, kLevel), 1, 1.0f, 0.5f});
  // At the snapshot's clock: the tile is there, its neighbour cell is empty.
  auto now = snapshotLookup(s, 100);
  EXPECT_DOUBLE_EQ(weatherAt(s.layers, now, p.lat_deg, p.lon_deg, 1500).cloudDensity, 0.5);
  EXPECT_DOUBLE_EQ(weatherAt(s.layers, now, 47.1, 8.0, 1500).cloudDensity, 0.0);
  // Layer 2 has no tiles: uniform at its own coverage.
  EXPECT_DOUBLE_EQ(weatherAt(s.layers, now, 47.1, 8.0, 3200).cloudDensity, 0.4);
  // 1000 s later the westerly has carried that air 10 km east: the cloud is
  // found there, and no longer over p.
  auto later = snapshotLookup(s, 1100);
  const SurfacePoint east = advect(p, s.layers[0].wind, 1000);
  EXPECT_GT(east.lon_deg, p.lon_deg + 0.1);
  EXPECT_DOUBLE_EQ(weatherAt(s.layers, later, east.lat_deg, east.lon_deg, 1500).cloudDensity, 0.5);
  EXPECT_DOUBLE_EQ(weatherAt(s.layers, later, p.lat_deg, p.lon_deg, 1500).cloudDensity, 0.0);
  // Tiles the server holds in place (a still region's, a station's, a
  // forecast's) are where they were, however old the snapshot.
  s.layers[0].tilesDrift = false;
  auto held = snapshotLookup(s, 1100);
  EXPECT_DOUBLE_EQ(weatherAt(s.layers, held, p.lat_deg, p.lon_deg, 1500).cloudDensity, 0.5);
  EXPECT_DOUBLE_EQ(weatherAt(s.layers, held, east.lat_deg, east.lon_deg, 1500).cloudDensity, 0.0);
}

TEST(WeatherQuery, StandardAtmosphere) {
  // ICAO: 15 C, 1013.25 hPa at sea level; -56.5 C, 226.32 hPa at 11 km;
  // 5 km: -17.5 C, 540.2 hPa (published ISA table).
  EXPECT_DOUBLE_EQ(isaTemperature_c(0), 15.0);
  EXPECT_NEAR(isaPressure_hpa(0), 1013.25, 1e-9);
  EXPECT_NEAR(isaTemperature_c(5000), -17.5, 1e-9);
  EXPECT_NEAR(isaPressure_hpa(5000), 540.2, 0.1);
  EXPECT_NEAR(isaTemperature_c(11000), -56.5, 1e-9);
  EXPECT_NEAR(isaPressure_hpa(11000), 226.32, 0.05);
  EXPECT_NEAR(isaTemperature_c(15000), -56.5, 1e-9);
  EXPECT_NEAR(isaPressure_hpa(15000), 120.4, 0.1);
}

}  // namespace
}  // namespace sky::weather
