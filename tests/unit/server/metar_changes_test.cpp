// METAR reports as station regions: each reported group its own layer in a
// height-band slot; a station's region clears every global layer in its core
// (the issue's CAVOK at Ljubljana under the bundled cumulus), so the point
// query at a station shows exactly its report, and between stations the
// weather blends by distance; stations accumulate across requests by ICAO,
// are replaced by a newer report and removed on purpose; 5000 stations
// applied in batches all survive (timings printed); the station table and
// the request body are strict.
#include <gtest/gtest.h>

#include <chrono>
#include <cstdio>
#include <fstream>
#include <set>
#include <sstream>

#include "sky/server/conditions_api.hpp"
#include "sky/server/live_weather.hpp"
#include "sky/server/metar_api.hpp"
#include "sky/server/metar_changes.hpp"
#include "sky/server/snapshot_builder.hpp"
#include "sky/server/weather_store.hpp"
#include "sky/stream/messages.hpp"
#include "store_files.hpp"
#include "sky/weather/tiling.hpp"

namespace sky::server {
namespace {

constexpr double kFt = 0.3048;
const Station kLipq{"LIPQ", 45.8275, 13.4722, 12};
const Station kLjlj{"LJLJ", 46.2237, 14.4576, 388};
const std::vector<Station> kStations = {kLipq, kLjlj};

const weather::Region& regionOf(const MetarPlan& plan, std::size_t i) {
  return std::get<SetRegion>(plan.changes.at(i)).region;
}

const weather::CloudLayer* slot(const weather::Region& r, std::uint32_t id) {
  for (const auto& l : r.layers)
    if (l.id == id) return &l;
  return nullptr;
}

std::uint32_t bandSlot(double base_m) {
  weather::CloudLayer l;
  l.base_m = base_m;
  return metarSlot(l);
}

// A live weather on the bundled cumulus scenario (one global layer: id 1,
// cumulus 1500-3000 m, coverage 0.6), its clock frozen at 0.
struct Live {
  WallClock::time_point t0{std::chrono::hours(1)};
  LiveWeather weather;
  explicit Live(const weather::Scenario& scenario)
      : weather(scenario, t0, [this] { return t0; }, [] { return std::int64_t{0}; }) {}
};

weather::Scenario cumulus() {
  auto scenario = loadScenario(SKY_SOURCE_DIR "/deploy/scenarios/skeleton-cumulus.toml");
  EXPECT_TRUE(scenario) << scenario.error().detail;
  return *scenario;
}

MetarReply apply(LiveWeather& weather, std::vector<std::string> reports, std::span<const Station> stations,
                 double radius_m = kDefaultStationRadius_m) {
  MetarRequest request;
  request.reports = std::move(reports);
  request.options.radius_m = radius_m;
  request.apply = true;
  return handleMetar(request, stations, weather);
}

// The point query of GET /api/conditions: layer id (0: clear air) and density.
std::pair<std::uint32_t, double> pointAt(const LiveWeather& weather, const Station& s, double alt_m) {
  const auto j = conditionsJson(weather, {s.lat_deg, s.lon_deg, alt_m});
  return {j["layer_id"].is_null() ? 0u : j["layer_id"].get<std::uint32_t>(), j["cloud_density"].get<double>()};
}

std::vector<weather::Region> metarRegions(const LiveWeather& weather) {
  std::vector<weather::Region> out;
  for (const auto& r : weather.regionsAt(weather.clockNow()))
    if (isMetarRegion(r.id)) out.push_back(r);
  return out;
}

TEST(MetarChanges, EachGroupIsItsOwnLayerInItsBandSlot) {
  const std::vector<std::string> reports = {
      "METAR LIPQ 221150Z 09012KT 9999 FEW015 SCT025 BKN040 15/10 Q1015",
      "METAR LJLJ 221150Z 27005KT CAVOK 12/05 Q1018",
      "METAR LJLJ 221120Z 27005KT 9999 OVC008 12/05 Q1018",  // older: the CAVOK of 11:50 stands
      "METAR LIPZ 221150Z 09012KT BKN015 15/10 Q1015",       // not in the table
  };
  const MetarPlan plan = planMetar(reports, kStations, {50000, {}});
  ASSERT_EQ(plan.reports.size(), 4u);
  EXPECT_TRUE(plan.reports[0] && plan.reports[1] && plan.reports[2]);
  ASSERT_FALSE(plan.reports[3]);
  EXPECT_EQ(plan.reports[3].error().detail, "report 4: station LIPZ is not in the station table");
  ASSERT_EQ(plan.changes.size(), 2u);
  ASSERT_EQ(plan.stations.size(), 2u);
  const weather::Region& lipq = regionOf(plan, 0);
  EXPECT_EQ(lipq.id, plan.stations[0].regionId);
  EXPECT_TRUE(isMetarRegion(lipq.id));
  EXPECT_EQ(lipq.centerLat_deg, kLipq.lat_deg);
  EXPECT_EQ(lipq.sizeX_m, 2 * kStationCoreRadius_m) << "90 km from LJLJ: the full core";
  EXPECT_EQ(lipq.transition_m, 50000) << "LJLJ's core is further than 50 km";
  EXPECT_TRUE(validate(lipq)) << validate(lipq).error().detail;
  // Three groups, three layers, each with its own base above the 12 m station.
  ASSERT_EQ(lipq.layers.size(), 3u);
  const double bases[] = {12 + 1500 * kFt, 12 + 2500 * kFt, 12 + 4000 * kFt};
  const double coverage[] = {1.5 / 8, 3.5 / 8, 6.0 / 8};
  std::set<std::uint32_t> slots;
  for (int i = 0; i < 3; ++i) {
    const weather::CloudLayer* l = slot(lipq, bandSlot(bases[i]));
    ASSERT_NE(l, nullptr) << i;
    EXPECT_NEAR(l->base_m, bases[i], 1e-9);
    EXPECT_EQ(l->coverage, coverage[i]);
    EXPECT_NEAR(l->wind.fromDirection_deg, 90, 1e-9);
    slots.insert(l->id);
  }
  EXPECT_EQ(slots.size(), 3u);
  EXPECT_EQ(regionOf(plan, 1).id, plan.stations[1].regionId);
  EXPECT_TRUE(regionOf(plan, 1).layers.empty()) << "CAVOK, with no global layer to clear";
  EXPECT_NE(lipq.id, regionOf(plan, 1).id);
}

TEST(MetarChanges, SlotsAreHeightBandsAndConvectiveKinds) {
  EXPECT_EQ(bandSlot(0), kMetarFirstBandSlot);
  EXPECT_EQ(bandSlot(149.9), kMetarFirstBandSlot);
  EXPECT_EQ(bandSlot(150), kMetarFirstBandSlot + 1);
  EXPECT_EQ(bandSlot(15000), kMetarLastSlot);
  weather::CloudLayer cb;
  cb.type = weather::CloudType::Cumulonimbus;
  EXPECT_EQ(metarSlot(cb), kMetarCumulonimbusSlot);
  weather::CloudLayer tcu;
  tcu.thickness_m = kToweringCumulusThickness_m;
  EXPECT_EQ(metarSlot(tcu), kMetarToweringCumulusSlot);
  // Every METAR id with the global ones stays within what a snapshot holds.
  EXPECT_LE(kMetarLastSlot - kMetarFogSlot + 1, weather::kMaxScenarioLayers - 8);
  // Two groups in one band merge: the larger cover, the lower base.
  const MetarPlan plan = planMetar({{"METAR LIPQ 221150Z 09012KT 9999 FEW030 BKN032 15/10 Q1015"}}, kStations, {});
  ASSERT_EQ(plan.changes.size(), 1u);
  ASSERT_EQ(regionOf(plan, 0).layers.size(), 1u);
  EXPECT_EQ(regionOf(plan, 0).layers[0].coverage, 6.0 / 8);
  EXPECT_NEAR(regionOf(plan, 0).layers[0].base_m, 12 + 3000 * kFt, 1e-9);
}

// The issue's first try: the bundled cumulus scenario, then a CAVOK report
// of Ljubljana. Its 60 % cumulus stood over the station; a CAVOK station
// clears it there, and far away it stands.
TEST(MetarChanges, ACavokStationClearsTheGlobalLayerAtTheStation) {
  Live live(cumulus());
  ASSERT_EQ(pointAt(live.weather, kLjlj, 1700), (std::pair<std::uint32_t, double>{1, 0.6}));
  const MetarReply reply = apply(live.weather, {"METAR LJLJ 221150Z 24008KT CAVOK 12/06 Q1018"}, kStations);
  ASSERT_EQ(reply.status, 200) << reply.body.dump();
  const auto regions = metarRegions(live.weather);
  ASSERT_EQ(regions.size(), 1u);
  ASSERT_EQ(regions[0].layers.size(), 1u);
  EXPECT_EQ(regions[0].layers[0].id, 1u) << "the global layer, at coverage 0";
  EXPECT_EQ(regions[0].layers[0].coverage, 0);
  for (double alt_m : {1600.0, 1700.0, 2500.0})
    EXPECT_EQ(pointAt(live.weather, kLjlj, alt_m), (std::pair<std::uint32_t, double>{0, 0.0})) << alt_m;
  const Station far{"FAR1", 48.0, 14.4576, 388};  // 200 km north
  EXPECT_EQ(pointAt(live.weather, far, 1700), (std::pair<std::uint32_t, double>{1, 0.6}));
}

// At a station the point query answers exactly the reported layers (to the
// stream's 8-bit fractions), whatever the global layer and a neighbour say.
TEST(MetarChanges, ThePointQueryAtAStationShowsExactlyItsReport) {
  Live live(cumulus());
  // A neighbour 12 km from LJLJ with an overcast: it must not weigh in at LJLJ.
  const Station near{"LJNR", 46.33, 14.4576, 400};
  const std::vector<Station> stations = {kLipq, kLjlj, near};
  const MetarReply reply = apply(live.weather,
                                 {"METAR LJLJ 221150Z 24008KT 9999 FEW025 SCT045 12/06 Q1018",
                                  "METAR LJNR 221150Z 24008KT 9999 OVC010 12/06 Q1018",
                                  "METAR LIPQ 221150Z 24008KT 9999 BKN030 12/06 Q1018"},
                                 stations);
  ASSERT_EQ(reply.status, 200) << reply.body.dump();
  const double few_m = kLjlj.elevation_m + 2500 * kFt, sct_m = kLjlj.elevation_m + 4500 * kFt;
  const double quantum = 0.5 / 255;
  // Inside each reported layer (a cumulus 1000 m deep): that layer, its cover.
  auto [fewId, fewDensity] = pointAt(live.weather, kLjlj, few_m + 500);
  EXPECT_EQ(fewId, bandSlot(few_m));
  EXPECT_NEAR(fewDensity, kFewCoverage, quantum);
  auto [sctId, sctDensity] = pointAt(live.weather, kLjlj, sct_m + 500);
  EXPECT_EQ(sctId, bandSlot(sct_m));
  EXPECT_NEAR(sctDensity, kScatteredCoverage, quantum);
  EXPECT_NE(fewId, sctId) << "FEW025 and SCT045: two layers";
  // Below the lowest and between: clear air (the global cumulus is gone).
  EXPECT_EQ(pointAt(live.weather, kLjlj, few_m - 200).first, 0u);
  EXPECT_EQ(pointAt(live.weather, kLjlj, 1700).first, bandSlot(few_m)) << "1700 m is inside FEW025's layer";
  // The neighbour shows its own overcast, not LJLJ's.
  auto [ovcId, ovcDensity] = pointAt(live.weather, near, near.elevation_m + 1000 * kFt + 100);
  EXPECT_EQ(ovcId, bandSlot(near.elevation_m + 1000 * kFt));
  EXPECT_NEAR(ovcDensity, 1.0, quantum);
  // Its region was shaped by LJLJ: core a quarter of the distance, transition
  // ending before LJLJ's core.
  for (const auto& r : metarRegions(live.weather))
    if (r.centerLat_deg == near.lat_deg) {
      EXPECT_LT(r.sizeX_m, 2 * kStationCoreRadius_m);
      EXPECT_LT(r.transition_m, 12000);
    }
}

TEST(MetarChanges, WeatherBetweenStationsBlendsByDistance) {
  Live live(weather::Scenario{});
  const std::vector<std::string> reports = {"METAR LIPQ 221150Z 09012KT 9999 OVC020 15/10 Q1015",
                                            "METAR LJLJ 221150Z 27005KT 9999 OVC020 12/05 Q1018"};
  // 90 km between the stations; each reaches 100 km, shortened to end before
  // the other's core.
  const MetarPlan plan = planMetar(reports, kStations, {100000, {}});
  auto applied = live.weather.submit({plan.changes, "test", "metar"});
  ASSERT_TRUE(applied) << applied.error().detail;
  // OVC020 is 622 m MSL at LIPQ and 998 m at LJLJ: two band slots.
  const std::uint32_t lipqSlot = bandSlot(12 + 2000 * kFt), ljljSlot = bandSlot(388 + 2000 * kFt);
  ASSERT_NE(lipqSlot, ljljSlot);
  stream::Subscribe area;
  area.area = {46.0, 14.0, 80000};
  area.tileLevel = 12;
  const auto snapshot = buildSnapshot(area, live.weather.layersAt(0), 0, kDefaultMaxCells, live.weather.regionsAt(0));
  auto coverageAt = [&](double lat, double lon, std::uint32_t id) {
    const std::uint64_t cell = weather::cellAt(lat, lon, snapshot.tileLevel);
    for (const auto& t : snapshot.tiles)
      if (t.cellId == cell && t.layerId == id) return double(t.coverage);
    return -1.0;
  };
  EXPECT_EQ(coverageAt(kLipq.lat_deg, kLipq.lon_deg, lipqSlot), 1.0) << "at LIPQ: its overcast";
  EXPECT_EQ(coverageAt(kLipq.lat_deg, kLipq.lon_deg, ljljSlot), 0.0) << "LJLJ does not reach LIPQ's core";
  EXPECT_EQ(coverageAt(kLjlj.lat_deg, kLjlj.lon_deg, ljljSlot), 1.0);
  EXPECT_EQ(coverageAt(kLjlj.lat_deg, kLjlj.lon_deg, lipqSlot), 0.0);
  // Half way: each at half weight.
  const double midLat = (kLipq.lat_deg + kLjlj.lat_deg) / 2, midLon = (kLipq.lon_deg + kLjlj.lon_deg) / 2;
  EXPECT_NEAR(coverageAt(midLat, midLon, lipqSlot), 0.5, 0.05);
  EXPECT_NEAR(coverageAt(midLat, midLon, ljljSlot), 0.5, 0.05);
  double previous = 1.1;
  for (double f = 0; f <= 1.0; f += 0.1) {  // LIPQ's layer falls monotonically towards LJLJ
    const double c = coverageAt(kLipq.lat_deg + f * (kLjlj.lat_deg - kLipq.lat_deg),
                                kLipq.lon_deg + f * (kLjlj.lon_deg - kLipq.lon_deg), lipqSlot);
    EXPECT_LE(c, previous + 0.02) << f;
    previous = c;
  }
}

// The issue's second try: 20 batches left only the last batch's stations.
// Each station keeps its region (by ICAO) across requests; a newer report of
// it replaces it; "remove" takes it away; a report without a sky changes
// nothing.
TEST(MetarChanges, StationsAccumulateAcrossRequests) {
  Live live(cumulus());
  const Station khaf{"KHAF", 37.5136, -122.5011, 20}, ksfo{"KSFO", 37.6190, -122.3750, 3},
      koak{"KOAK", 37.7213, -122.2208, 3};
  const std::vector<Station> stations = {khaf, ksfo, koak};
  auto first = apply(live.weather, {"METAR KHAF 221156Z AUTO 00000KT 10SM OVC003 12/11 A3002"}, stations);
  ASSERT_EQ(first.status, 200) << first.body.dump();
  const std::uint32_t khafId = first.body["reports"][0]["region_id"].get<std::uint32_t>();
  auto second = apply(live.weather,
                      {"METAR KSFO 221156Z 28012KT 10SM FEW008 14/11 A3001",
                       "METAR KOAK 221153Z 27008KT 10SM CLR 13/10 A3002"},
                      stations);
  ASSERT_EQ(second.status, 200) << second.body.dump();
  auto regions = metarRegions(live.weather);
  ASSERT_EQ(regions.size(), 3u) << "the first batch's KHAF is still there";
  const auto khafRegion = std::find_if(regions.begin(), regions.end(), [&](const auto& r) { return r.id == khafId; });
  ASSERT_NE(khafRegion, regions.end());
  const auto ovc = slot(*khafRegion, bandSlot(20 + 300 * kFt));
  ASSERT_NE(ovc, nullptr);
  EXPECT_EQ(ovc->coverage, 1.0);
  EXPECT_EQ(second.body["stations"]["reshaped"].get<int>(), 1) << "KSFO is 15 km from KHAF: KHAF's transition shortens";
  // A newer report of KHAF replaces its region, same id.
  auto third = apply(live.weather, {"METAR KHAF 221256Z AUTO 00000KT 10SM SCT020 12/11 A3002"}, stations);
  ASSERT_EQ(third.status, 200) << third.body.dump();
  EXPECT_EQ(third.body["reports"][0]["region_id"].get<std::uint32_t>(), khafId);
  EXPECT_EQ(third.body["stations"]["replaced"].get<int>(), 1);
  regions = metarRegions(live.weather);
  ASSERT_EQ(regions.size(), 3u);
  // A sky not observed changes nothing.
  auto blind = apply(live.weather, {"METAR KHAF 221356Z AUTO 00000KT 10SM ////// 12/11 A3002"}, stations);
  EXPECT_EQ(blind.status, 400) << "nothing to apply";
  EXPECT_EQ(blind.body["reports"][0]["sky"], "not_observed");
  EXPECT_EQ(metarRegions(live.weather).size(), 3u);
  // Removed on purpose.
  MetarRequest remove;
  remove.remove = {"KHAF", "KJFK"};
  remove.apply = true;
  auto removed = handleMetar(remove, stations, live.weather);
  ASSERT_EQ(removed.status, 200) << removed.body.dump();
  EXPECT_EQ(removed.body["stations"]["removed"].get<int>(), 1);
  ASSERT_EQ(removed.body["remove_errors"].size(), 1u);
  EXPECT_EQ(removed.body["remove_errors"][0], "remove KJFK: not in the station table");
  regions = metarRegions(live.weather);
  EXPECT_EQ(regions.size(), 2u);
  EXPECT_TRUE(std::none_of(regions.begin(), regions.end(), [&](const auto& r) { return r.id == khafId; }));
}

// LJLJ's longitude 14.4576 comes back from the weather as 14.457600000000014
// (normalised by GeographicLib): its newer report still replaces its region
// instead of adding a second one at the station.
TEST(MetarChanges, ANewerReportReplacesItsStationWhateverItsLongitudeBecame) {
  Live live(cumulus());
  auto first = apply(live.weather, {"METAR LJLJ 221150Z 24008KT 9999 FEW025 12/06 Q1018"}, kStations);
  ASSERT_EQ(first.status, 200) << first.body.dump();
  const auto regions = metarRegions(live.weather);
  ASSERT_EQ(regions.size(), 1u);
  std::printf("LJLJ's region centre as the weather holds it: %.17g\n", regions[0].centerLon_deg);
  auto second = apply(live.weather, {"METAR LJLJ 221220Z 24010KT 9999 BKN030 12/06 Q1018"}, kStations);
  ASSERT_EQ(second.status, 200) << second.body.dump();
  EXPECT_EQ(second.body["stations"]["replaced"].get<int>(), 1);
  EXPECT_EQ(metarRegions(live.weather).size(), 1u);
  EXPECT_EQ(second.body["reports"][0]["region_id"], first.body["reports"][0]["region_id"]);
}

// A region another input put in the METAR id range (a CIGI host may use any
// 16-bit id) is neither reshaped nor taken for a station; a station inside it
// clears its layers like the global ones.
TEST(MetarChanges, OtherRegionsInTheRangeAreLeftAlone) {
  Live live(weather::Scenario{});
  weather::Region square;
  square.id = 50000;
  square.centerLat_deg = kLjlj.lat_deg + 0.05;
  square.centerLon_deg = kLjlj.lon_deg;
  square.sizeX_m = square.sizeY_m = 40000;
  square.transition_m = 5000;
  weather::CloudLayer storm;
  storm.id = 7;
  storm.type = weather::CloudType::Cumulonimbus;
  storm.base_m = 1000;
  storm.thickness_m = 8000;
  storm.coverage = 0.8;
  square.layers = {storm};
  ASSERT_TRUE(live.weather.submit({{SetRegion{square, {}}}, "cigi", "cigi"}));
  const auto view = live.weather.view();
  const MetarPlan plan = planMetar({{"METAR LJLJ 221150Z 24008KT 9999 FEW025 12/06 Q1018"}}, kStations, {},
                                   {view.layers, view.regions});
  ASSERT_EQ(plan.changes.size(), 1u) << "the square is not reshaped";
  EXPECT_EQ(plan.neighboursReshaped, 0u);
  const weather::Region& ljlj = regionOf(plan, 0);
  EXPECT_NE(ljlj.id, square.id);
  const weather::CloudLayer* cleared = slot(ljlj, 7);
  ASSERT_NE(cleared, nullptr) << "the storm's layer, cleared at the station";
  EXPECT_EQ(cleared->coverage, 0);
}

// The preview lists the groups skipped and joined, by position and text.
TEST(MetarChanges, ThePreviewListsSkippedGroups) {
  Live live(cumulus());
  MetarRequest request;
  request.reports = {"METAR LJLJ 221150Z 24008KT 9999 -VCTSRA FEW050 CB 12/06 Q1018"};
  const MetarReply reply = handleMetar(request, kStations, live.weather);
  ASSERT_EQ(reply.status, 200);
  const auto& r = reply.body["reports"][0];
  EXPECT_EQ(r["ok"], true);
  EXPECT_EQ(r["sky"], "read");
  ASSERT_EQ(r["skipped"].size(), 1u);
  EXPECT_EQ(r["skipped"][0]["group"], 6);
  EXPECT_EQ(r["skipped"][0]["text"], "-VCTSRA");
  EXPECT_EQ(r["skipped"][0]["reason"], "unrecognised group");
  ASSERT_EQ(r["joined"].size(), 1u);
  EXPECT_EQ(r["joined"][0]["text"], "CB");
  EXPECT_EQ(r["layers"][0]["type"], "cumulonimbus");
  EXPECT_TRUE(reply.body["applied"].is_null()) << "a preview applies nothing";
  EXPECT_TRUE(metarRegions(live.weather).empty());
}

// ---- a continent ------------------------------------------------------------

struct Row {
  std::string icao, report;
};

std::vector<Row> realReports() {
  std::ifstream in(std::string(SKY_METAR_DATA_DIR) + "/metar-coverage-selection.tsv");
  std::vector<Row> rows;
  std::string line;
  std::getline(in, line);
  while (std::getline(in, line)) {
    std::vector<std::string> cols;
    std::stringstream ss(line);
    std::string col;
    while (std::getline(ss, col, '\t')) cols.push_back(col);
    if (cols.size() == 5) rows.push_back({cols[2], cols[4]});
  }
  return rows;
}

// 5000 stations over North America (a jittered grid 25-55 N, 125-65 W, about
// 50-67 km apart, as the US network), each with a real report of the selection (its ICAO put in),
// applied through POST /api/metar's handler in 20 requests of 250, every
// change committed to a SQLite store as the server does. Every station whose
// sky is read keeps its region, the first request's stations survive the
// last, and after a restart from the store a newer report of a first-batch
// station finds and replaces its region. The apply time, a 300 km area's
// snapshot (size on the wire and build time) are printed, not asserted.
TEST(MetarContinent, FiveThousandStationsAccumulate) {
  const std::vector<Row> rows = realReports();
  ASSERT_EQ(rows.size(), 157u);
  constexpr int kStationCount = 5000, kBatch = 250;
  std::vector<Station> stations;
  std::vector<std::string> reports;
  std::uint32_t jitter = 12345;
  auto next = [&] {  // a small LCG: the same stations every run
    jitter = jitter * 1664525u + 1013904223u;
    return double(jitter >> 8) / double(1u << 24) - 0.5;
  };
  const char* digits = "ABCDEFGHIJKLMNOPQRSTUVWXYZ0123456789";
  for (int i = 0; i < kStationCount; ++i) {
    const int row = i / 100, col = i % 100;  // 50 rows of 100
    std::string icao = "K";
    for (int k = i, n = 0; n < 3; ++n, k /= 36) icao += digits[k % 36];
    stations.push_back({icao, 25 + 0.6 * (row + 0.5 + 0.6 * next()), -125 + 0.6 * (col + 0.5 + 0.6 * next()),
                        100 + 10.0 * (i % 50)});
    const Row& r = rows[i % rows.size()];
    std::string text = r.report;
    text.replace(text.find(r.icao), 4, icao);
    reports.push_back(text);
  }
  Live live(cumulus());
  auto store = WeatherStore::open(test::freshDatabase("sky-metar-continent", "weather.db"));
  ASSERT_TRUE(store) << store.error().detail;
  live.weather.attachStore(&*store);
  std::size_t read = 0;
  double applyTotal_s = 0, applyMax_s = 0;
  std::set<std::uint32_t> firstBatch;
  std::string firstIcao;  // the first station of the first request with a region, and its id
  std::uint32_t firstId = 0;
  for (int b = 0; b < kStationCount / kBatch; ++b) {
    const std::vector<std::string> batch(reports.begin() + b * kBatch, reports.begin() + (b + 1) * kBatch);
    const auto started = std::chrono::steady_clock::now();
    const MetarReply reply = apply(live.weather, batch, stations);
    const double took_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
    applyTotal_s += took_s;
    applyMax_s = std::max(applyMax_s, took_s);
    ASSERT_EQ(reply.status, 200) << b << ": " << reply.body.value("error", "");
    for (const auto& r : reply.body["reports"])
      if (r.contains("region_id")) {
        ++read;
        if (b == 0) firstBatch.insert(r["region_id"].get<std::uint32_t>());
        if (firstIcao.empty()) {
          firstIcao = r["icao"].get<std::string>();
          firstId = r["region_id"].get<std::uint32_t>();
        }
      }
  }
  const auto regions = metarRegions(live.weather);
  EXPECT_EQ(regions.size(), read) << "every station whose sky was read keeps its region";
  EXPECT_GT(read, 4700u) << "149 of the selection's 157 reports read a sky";
  std::set<std::uint32_t> ids;
  for (const auto& r : regions) ids.insert(r.id);
  EXPECT_EQ(ids.size(), regions.size());
  for (std::uint32_t id : firstBatch) EXPECT_TRUE(ids.count(id)) << "first batch's region " << id << " is gone";
  const auto& commits = live.weather.commitStats();
  std::printf("[ METAR    ] %d stations in %d requests: %zu regions; apply %.2f s in all, %.3f s a request at most; "
              "%llu commits to the store, %.2f s in all\n",
              kStationCount, kStationCount / kBatch, regions.size(), applyTotal_s, applyMax_s,
              static_cast<unsigned long long>(commits.count), commits.total_s);

  // A restart: the weather from the store, then a newer report of the first
  // station with a region.
  {
    Live restarted(cumulus());
    auto saved = store->load();
    ASSERT_TRUE(saved && *saved);
    ASSERT_TRUE(restarted.weather.restore((*saved)->state, (*saved)->events));
    EXPECT_EQ(metarRegions(restarted.weather).size(), regions.size());
    ASSERT_FALSE(firstIcao.empty());
    const MetarReply newer =
        apply(restarted.weather, {"METAR " + firstIcao + " 231200Z 00000KT 9999 OVC010 10/05 Q1010"}, stations);
    ASSERT_EQ(newer.status, 200) << newer.body.value("error", "");
    EXPECT_EQ(newer.body["reports"][0]["region_id"], firstId);
    EXPECT_EQ(newer.body["stations"]["replaced"], 1);
    EXPECT_EQ(metarRegions(restarted.weather).size(), regions.size());
  }

  // A renderer's 300 km area in the middle of the continent, with and
  // without the server's tile cache.
  stream::Subscribe area;
  area.area = {40.0, -95.0, 300000};
  area.tileLevel = 11;
  const double clock_s = live.weather.clockNow();
  const auto layers = live.weather.layersAt(clock_s);
  const auto all = live.weather.regionsAt(clock_s);
  TileCache cache;
  for (int run = 0; run < 2; ++run) {
    const auto started = std::chrono::steady_clock::now();
    const weather::WeatherSnapshot snapshot =
        buildSnapshot(area, layers, clock_s, kDefaultMaxCells, all, run == 0 ? nullptr : &cache);
    const double took_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
    const std::size_t bytes = stream::encodeMessage(snapshot).size();
    std::size_t varying = 0;
    std::set<std::uint32_t> tiled;
    for (const auto& t : snapshot.tiles) tiled.insert(t.layerId);
    varying = tiled.size();
    std::printf("[ METAR    ] 300 km snapshot (%s): level %d, %zu layers (%zu with tiles), %zu tiles, %zu bytes, built in %.3f s\n",
                run == 0 ? "no cache" : "tile cache", snapshot.tileLevel, snapshot.layers.size(), varying,
                snapshot.tiles.size(), bytes, took_s);
    EXPECT_LE(bytes, std::size_t{4} << 20) << "fits one stream frame";
    EXPECT_GT(snapshot.tiles.size(), 0u);
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
                        Case{R"({"reports": []})", "reports: missing"},
                        Case{R"({"reports": ["x"], "remove": ["K1"]})", "remove[0]: expected a four-character ICAO"},
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
