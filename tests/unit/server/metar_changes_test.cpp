// METAR batches as station regions: layers land in family slots (and merge
// within one), a CAVOK station carries every slot at coverage 0, the newest
// report of a station wins, bad reports are listed with their group and the
// good ones still plan; the weather between two stations blends by distance
// in the snapshot tiles; the station table and the request body are strict.
#include <gtest/gtest.h>

#include "sky/server/live_weather.hpp"
#include "sky/server/metar_api.hpp"
#include "sky/server/metar_changes.hpp"
#include "sky/server/snapshot_builder.hpp"
#include "sky/weather/tiling.hpp"

namespace sky::server {
namespace {

const std::vector<Station> kStations = {{"LIPQ", 45.8275, 13.4722, 12}, {"LJLJ", 46.2237, 14.4576, 388}};

const weather::Region& regionOf(const MetarPlan& plan, std::size_t i) {
  return std::get<SetRegion>(plan.changes.at(i)).region;
}

const weather::CloudLayer* slot(const weather::Region& r, std::uint32_t id) {
  for (const auto& l : r.layers)
    if (l.id == id) return &l;
  return nullptr;
}

TEST(MetarChanges, StationsBecomeRegionsWithSlottedLayers) {
  const std::vector<std::string> reports = {
      "METAR LIPQ 221150Z 09012KT 9999 FEW015 SCT025 BKN040 15/10 Q1015",
      "METAR LJLJ 221150Z 27005KT CAVOK 12/05 Q1018",
      "METAR LJLJ 221120Z 27005KT 9999 OVC008 12/05 Q1018",  // older? no: later in the batch wins
      "METAR LIPZ 221150Z 09012KT BKN0x5 15/10 Q1015",
  };
  // Newest = last in the batch: LJLJ's OVC008 replaces its CAVOK.
  const MetarPlan plan = planMetar(reports, kStations, {50000, {}});
  ASSERT_EQ(plan.reports.size(), 4u);
  EXPECT_TRUE(plan.reports[0] && plan.reports[1] && plan.reports[2]);
  ASSERT_FALSE(plan.reports[3]);
  EXPECT_NE(plan.reports[3].error().detail.find("report 4: group 5 'BKN0x5'"), std::string::npos)
      << plan.reports[3].error().detail;
  ASSERT_EQ(plan.changes.size(), 2u);
  const weather::Region& lipq = regionOf(plan, 0);
  EXPECT_EQ(lipq.id, kMetarRegionBase + 0);
  EXPECT_EQ(lipq.centerLat_deg, 45.8275);
  EXPECT_EQ(lipq.transition_m, 50000);
  EXPECT_EQ(lipq.sizeX_m, kStationCore_m);
  EXPECT_TRUE(validate(lipq)) << validate(lipq).error().detail;
  // FEW015 SCT025 (cumulus) and BKN040 (stratocumulus) are all low: one
  // layer, coverage of the largest amount (BKN 6/8), base of the lowest
  // (1500 ft = 457.2 m above a 12 m station), top of the highest (the SCT025
  // cumulus, 1000 m deep, tops the BKN040 stratocumulus, 500 m deep).
  ASSERT_EQ(lipq.layers.size(), 1u);
  const weather::CloudLayer* low = slot(lipq, kMetarLowSlot);
  ASSERT_NE(low, nullptr);
  EXPECT_DOUBLE_EQ(low->coverage, 6.0 / 8);
  EXPECT_NEAR(low->base_m, 12 + 1500 * 0.3048, 1e-9);
  EXPECT_NEAR(low->base_m + low->thickness_m,
              std::max(12 + 2500 * 0.3048 + kCumulusThickness_m, 12 + 4000 * 0.3048 + kStratocumulusThickness_m), 1e-9);
  EXPECT_EQ(low->type, weather::CloudType::Stratocumulus);
  EXPECT_NEAR(low->wind.fromDirection_deg, 90, 1e-9);
  const weather::Region& ljlj = regionOf(plan, 1);
  EXPECT_EQ(ljlj.id, kMetarRegionBase + 1);
  ASSERT_NE(slot(ljlj, kMetarLowSlot), nullptr);
  EXPECT_DOUBLE_EQ(slot(ljlj, kMetarLowSlot)->coverage, 1.0) << "OVC008, the newer report";
}

TEST(MetarChanges, AClearStationCarriesEverySlotAtZero) {
  const std::vector<std::string> reports = {"METAR LIPQ 221150Z 24010KT 9999 FEW030CB SCT250 20/15 Q1012",
                                            "METAR LJLJ 221150Z 27005KT CAVOK 12/05 Q1018"};
  const MetarPlan plan = planMetar(reports, kStations, {});
  ASSERT_EQ(plan.changes.size(), 2u);
  const weather::Region& lipq = regionOf(plan, 0);
  ASSERT_NE(slot(lipq, kMetarConvectiveSlot), nullptr);
  EXPECT_EQ(slot(lipq, kMetarConvectiveSlot)->type, weather::CloudType::Cumulonimbus);
  ASSERT_NE(slot(lipq, kMetarHighSlot), nullptr);
  EXPECT_EQ(slot(lipq, kMetarHighSlot)->type, weather::CloudType::Cirrus);
  const weather::Region& ljlj = regionOf(plan, 1);
  ASSERT_EQ(ljlj.layers.size(), 2u) << "both slots the batch uses";
  for (const auto& l : ljlj.layers) EXPECT_EQ(l.coverage, 0.0) << l.id;
}

TEST(MetarChanges, WeatherBetweenStationsBlendsByDistance) {
  const WallClock::time_point t0{std::chrono::hours(1)};
  Scenario scenario;
  LiveWeather weather(scenario, t0, [&] { return t0; }, [] { return std::int64_t{0}; });
  const std::vector<std::string> reports = {"METAR LIPQ 221150Z 09012KT 9999 OVC020 15/10 Q1015",
                                            "METAR LJLJ 221150Z 27005KT CAVOK 12/05 Q1018"};
  // 90 km between the stations; each reaches 100 km.
  const MetarPlan plan = planMetar(reports, kStations, {100000, {}});
  auto applied = weather.submit({plan.changes, "test", "metar"});
  ASSERT_TRUE(applied) << applied.error().detail;
  stream::Subscribe area;
  area.area = {46.0, 14.0, 80000};
  area.tileLevel = 12;
  const auto snapshot = buildSnapshot(area, weather.layersAt(0), 0, kDefaultMaxCells, weather.regionsAt(0));
  auto coverageAt = [&](double lat, double lon) {
    const std::uint64_t cell = weather::cellAt(lat, lon, snapshot.tileLevel);
    for (const auto& t : snapshot.tiles)
      if (t.cellId == cell && t.layerId == kMetarLowSlot) return double(t.coverage);
    return -1.0;
  };
  // At a station the other one, 90 km off, still weighs smoothstep(0.11) =
  // 3.4 % against its 100 %: within 0.05 of the station's own report.
  EXPECT_NEAR(coverageAt(45.8275, 13.4722), 1.0, 0.05) << "at LIPQ: its overcast";
  EXPECT_NEAR(coverageAt(46.2237, 14.4576), 0.0, 0.05) << "at LJLJ: clear";
  const double mid = coverageAt((45.8275 + 46.2237) / 2, (13.4722 + 14.4576) / 2);
  EXPECT_NEAR(mid, 0.5, 0.05) << "half way: equal weights";
  double previous = 1.1;
  for (double f = 0; f <= 1.0; f += 0.1) {  // falls monotonically from LIPQ to LJLJ
    const double c = coverageAt(45.8275 + f * (46.2237 - 45.8275), 13.4722 + f * (14.4576 - 13.4722));
    EXPECT_LE(c, previous + 0.02) << f;
    previous = c;
  }
}

TEST(MetarChanges, StationTableIsStrict) {
  auto ok = parseStationTable("icao,lat_deg,lon_deg,elevation_m\n# comment\nLIPQ,45.8,13.5,12\r\n", "s.csv");
  ASSERT_TRUE(ok) << ok.error().detail;
  ASSERT_EQ(ok->size(), 1u);
  EXPECT_EQ((*ok)[0].elevation_m, 12);
  struct Case {
    const char* text;
    const char* error;
  };
  for (const Case& c : {Case{"icao,lat\n", "s.csv:1: header"},
                        Case{"icao,lat_deg,lon_deg,elevation_m\nLIPQ,95,13,12\n", "s.csv:2: lat_deg 95 outside"},
                        Case{"icao,lat_deg,lon_deg,elevation_m\nLIPQ,45,x,12\n", "s.csv:2: lon_deg 'x' is not a number"},
                        Case{"icao,lat_deg,lon_deg,elevation_m\nLIP,45,13,12\n", "s.csv:2: icao 'LIP'"},
                        Case{"icao,lat_deg,lon_deg,elevation_m\nLIPQ,45,13\n", "s.csv:2: 3 fields"},
                        Case{"icao,lat_deg,lon_deg,elevation_m\nLIPQ,45,13,1\nLIPQ,45,13,1\n", "s.csv:3: station LIPQ listed twice"},
                        Case{"", "s.csv: empty"}}) {
    auto r = parseStationTable(c.text, "s.csv");
    ASSERT_FALSE(r) << c.text;
    EXPECT_EQ(r.error().detail.rfind(c.error, 0), 0u) << r.error().detail;
  }
}

TEST(MetarChanges, RequestBodyIsStrict) {
  auto ok = parseMetarRequest(R"({"reports": ["METAR LIPQ 221150Z 09012KT CAVOK 15/10 Q1015"], "apply": true,
      "radius_m": 40000, "ramp_s": 120, "stations": [{"icao": "LIPQ", "lat_deg": 45.8, "lon_deg": 13.5, "elevation_m": 12}]})");
  ASSERT_TRUE(ok) << ok.error().detail;
  EXPECT_TRUE(ok->apply);
  EXPECT_EQ(ok->options.radius_m, 40000);
  EXPECT_EQ(ok->options.timing.ramp_s, 120);
  ASSERT_TRUE(ok->stations);
  EXPECT_EQ(ok->stations->at(0).icao, "LIPQ");
  struct Case {
    const char* body;
    const char* error;
  };
  for (const Case& c : {Case{R"({"apply": true})", "reports: missing"},
                        Case{R"({"reports": []})", "reports: expected an array of 1 to 64"},
                        Case{R"({"reports": [3]})", "reports[0]: expected a string"},
                        Case{R"({"reports": ["x"], "radius_m": 0})", "radius_m: outside (0, 2000000]"},
                        Case{R"({"reports": ["x"], "stations": [{"icao": "LIPQ", "lat": 4}]})",
                             "stations[0].lat: unknown key"},
                        Case{R"({"reports": ["x"], "aply": true})", "aply: unknown key"},
                        Case{"not json", "body: not JSON"}}) {
    auto r = parseMetarRequest(c.body);
    ASSERT_FALSE(r) << c.body;
    EXPECT_EQ(r.error().detail.rfind(c.error, 0), 0u) << r.error().detail;
  }
}

}  // namespace
}  // namespace sky::server
