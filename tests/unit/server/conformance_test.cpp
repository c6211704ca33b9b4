// GET /api/conformance's check (conformance.hpp) on a live weather with METAR
// stations and a GFS forecast: what the tiles draw at each station is its
// report, whichever came first; a station region that does not replace
// every layer (as a hand-made one) is caught; grid points match the grid;
// the server's query and skyshell-conformance's reader share the clock's
// bound.
#include <algorithm>
#include <cstdio>
#include <map>

#include <gtest/gtest.h>

#include "grib_tools.hpp"
#include "sky/server/conformance.hpp"
#include "sky/server/forecast.hpp"
#include "sky/server/live_weather.hpp"
#include "sky/server/metar_changes.hpp"
#include "sky/server/snapshot_builder.hpp"
#include "sky/sim/conformance_track.hpp"
#include "sky/weather/clock.hpp"

namespace sky::server {
namespace {

const WallClock::time_point kT0{std::chrono::seconds(1000)};
const std::vector<Station> kStations = {{"LJLJ", 46.2237, 14.4576, 388}, {"LIPQ", 45.8275, 13.4722, 12},
                                         {"LOWK", 46.6425, 14.3377, 450},   {"LIPA", 46.0319, 12.5965, 125},
                                         {"LIPH", 45.6484, 12.1944, 18}};

struct Fixture {
  WallClock::time_point now = kT0;
  LiveWeather weather{Scenario{}, kT0, [this] { return now; }, [] { return std::int64_t{1700000000000}; }};

  void metar(const std::vector<std::string>& reports) {
    const auto layers = weather.layersAt(weather.clockNow());
    const auto regions = weather.regionsAt(weather.clockNow());
    MetarContext ctx{layers, regions};
    MetarPlan plan = planMetar(reports, kStations, MetarOptions{}, ctx);
    for (const auto& r : plan.reports) ASSERT_TRUE(r) << r.error().detail;
    ASSERT_TRUE(weather.submit({plan.changes, "test", "metar"}));
  }
  void gfs() {
    auto file = readGrib(readBytes(kGfs), "gfs", forecastWants);
    ASSERT_TRUE(file);
    auto fc = Forecast::fromGrib({&*file}, "gfs.grib2");
    ASSERT_TRUE(fc);
    LoadedForecast loaded;
    loaded.placement = {weather.clockNow(), fc->firstValid_unix()};
    loaded.forecast = std::make_shared<const Forecast>(std::move(*fc));
    loaded.files = {{"key", "gfs.grib2"}};
    ASSERT_TRUE(weather.loadForecast(std::move(loaded), "test", "grib"));
  }
  nlohmann::json check(std::size_t gridPoints = 200) {
    ConformanceQuery q;
    q.gridPoints = gridPoints;
    return conformanceJson(weather, kStations, q);
  }
};

const std::vector<std::string> kReports = {"METAR LJLJ 221150Z 24008KT 9999 FEW025 SCT045 BKN080 12/06 Q1018",
                                           "METAR LIPQ 221150Z 24008KT CAVOK 12/06 Q1018",
                                           "METAR LOWK 221150Z 24008KT 9999 OVC012 12/06 Q1018"};

void expectStationsAsReported(const nlohmann::json& j) {
  ASSERT_EQ(j["stations"].size(), 3u) << j.dump();
  for (const auto& s : j["stations"]) {
    EXPECT_TRUE(s["ok"]) << s.dump();
    EXPECT_EQ(s["oktas_off"], 0) << s.dump();
    EXPECT_EQ(s["drawn"]["layers"], s["reported"]["layers"]) << s.dump();
  }
  const auto row = [&](const std::string& icao) {
    for (const auto& s : j["stations"])
      if (s["icao"] == icao) return s;
    ADD_FAILURE() << "no row for " << icao;
    return nlohmann::json{};
  };
  EXPECT_EQ(row("LJLJ")["reported"]["layers"].size(), 3u);
  EXPECT_TRUE(row("LIPQ")["drawn"]["layers"].empty());  // CAVOK: the forecast's clouds cleared there
  // OVC012 at 450 m elevation: the ceiling at 450 + 1200 ft.
  EXPECT_NEAR(row("LOWK")["drawn"]["ceiling_m"].get<double>(), 450 + 1200 * 0.3048, 1);
}

TEST(Conformance, StationsDrawTheirReportsWhenTheForecastCameFirst) {
  Fixture f;
  f.gfs();
  f.metar(kReports);
  expectStationsAsReported(f.check());
}

TEST(Conformance, StationsDrawTheirReportsWhenTheForecastCameAfter) {
  Fixture f;
  f.metar(kReports);
  f.gfs();
  const auto j = f.check();
  expectStationsAsReported(j);
  // Grid points: every one checked matches the grid, or lies in a station's reach.
  ASSERT_GT(j["grid"].size(), 150u);
  std::size_t nearStation = 0;
  for (const auto& g : j["grid"]) {
    EXPECT_TRUE(g["ok"]) << g.dump();
    if (g["oktas_off"] > 1) {
      EXPECT_GT(g["station_weight"].get<double>(), 0) << g.dump();
    }
    nearStation += g["station_weight"].get<double>() > 0;
  }
  EXPECT_EQ(j["summary"]["grid_ok"], j["grid"].size());
  std::printf("[ conformance ] %zu grid points, %zu within a station's reach\n", j["grid"].size(), nearStation);
}

TEST(Conformance, AStationRegionThatLeavesOtherLayersStandingIsCaught) {
  Fixture f;
  f.metar(kReports);
  // LIPQ's region as a hand-made one would be: its layers, not the whole sky.
  auto regions = f.weather.regionsAt(f.weather.clockNow());
  for (auto& r : regions)
    if (std::abs(r.centerLat_deg - 45.8275) < 1e-9) {
      r.replacesAllLayers = false;
      r.layers.clear();
      ASSERT_TRUE(f.weather.submit({{SetRegion{r, {}}}, "test", "api"}));
    }
  f.gfs();
  const auto j = f.check(0);
  bool caught = false;
  for (const auto& s : j["stations"])
    if (s["icao"] == "LIPQ") {
      EXPECT_FALSE(s["ok"]) << s.dump();
      EXPECT_GT(s["oktas_off"], 1);
      caught = true;
    }
  EXPECT_TRUE(caught);
  EXPECT_EQ(j["summary"]["stations_ok"], 2);
}

// Two stations 53 km apart whose broken layers fall in one base band (one
// layer id): each is drawn at its own base where a renderer round it looks
// (the table made round its centre), not at the other's.
TEST(Conformance, StationsSharingASlotKeepTheirOwnBases) {
  Fixture f;
  f.metar({"METAR LIPA 221150Z 24008KT 9999 BKN020 12/06 Q1018", "METAR LIPH 221150Z 24008KT 9999 BKN022 12/06 Q1018"});
  const auto j = f.check(0);
  ASSERT_EQ(j["stations"].size(), 2u);
  for (const auto& s : j["stations"]) EXPECT_TRUE(s["ok"]) << s.dump();
  // The same through a snapshot a subscriber round each station gets.
  const auto layers = f.weather.layersAt(f.weather.clockNow());
  const auto regions = f.weather.regionsAt(f.weather.clockNow());
  for (const auto& [lat, lon, base] : {std::tuple{46.0319, 12.5965, 125 + 2000 * 0.3048},
                                       std::tuple{45.6484, 12.1944, 18 + 2200 * 0.3048}}) {
    stream::Subscribe s;
    s.area = {lat, lon, 20000};
    s.tileLevel = 11;
    const auto snap = buildSnapshot(s, layers, f.weather.clockNow(), kDefaultMaxCells, regions);
    // Both bases lie in the band from 600 to 800 m MSL: slot 43 + 4.
    const auto it = std::find_if(snap.layers.begin(), snap.layers.end(),
                                 [](const auto& l) { return l.id == kMetarFirstBandSlot + 4; });
    ASSERT_NE(it, snap.layers.end());
    EXPECT_NEAR(it->base_m, base, 1) << "round " << lat << ", " << lon;
  }
}

// Fog and mist at three stations, clear air at two: each draws its reported
// visibility at a pilot's eye over its ground (within WMO-No. 8's
// uncertainty, which also covers the stream's 8-bit density), the clear ones
// none; a station whose fog is taken away (a hand-made region) is caught.
TEST(Conformance, StationsDrawTheirReportedVisibility) {
  Fixture f;
  f.gfs();
  f.metar({"METAR LJLJ 221150Z 00000KT 0200 FG VV001 05/05 Q1025", "METAR LIPQ 221150Z 24008KT 3000 BR NSC 12/11 Q1018",
           "METAR LOWK 221150Z 00000KT 0800 BCFG SCT004 04/04 Q1027", "METAR LIPA 221150Z 24008KT CAVOK 12/06 Q1018",
           "METAR LIPH 221150Z 24008KT 9999 FEW030 12/06 Q1018"});
  const auto j = f.check(0);
  ASSERT_EQ(j["stations"].size(), 5u) << j.dump();
  std::map<std::string, nlohmann::json> rows;
  for (const auto& s : j["stations"]) rows[s["icao"].get<std::string>()] = s;
  for (const auto& [icao, want] : std::map<std::string, double>{{"LJLJ", 200}, {"LIPQ", 3000}, {"LOWK", 800}}) {
    const auto& s = rows[icao];
    EXPECT_TRUE(s["ok"]) << s.dump();
    EXPECT_NEAR(s["reported"]["visibility_m"].get<double>(), want, 1e-6 * want) << icao;
    const double drawn = s["drawn"]["visibility_m"].get<double>();
    EXPECT_NEAR(drawn, want, visibilityTolerance_m(want)) << icao;
    std::printf("[ conformance ] %s visibility reported %.0f m, drawn %.0f m\n", icao.c_str(), want, drawn);
  }
  for (const char* icao : {"LIPA", "LIPH"}) {
    EXPECT_TRUE(rows[icao]["ok"]) << rows[icao].dump();
    EXPECT_TRUE(rows[icao]["reported"]["visibility_m"].is_null());
    EXPECT_TRUE(rows[icao]["drawn"]["visibility_m"].is_null());
  }
  // LJLJ's fog lifted 300 m off its ground (a hand-made region): reported
  // fog, clear air drawn at the eye over the station: caught.
  auto regions = f.weather.regionsAt(f.weather.clockNow());
  for (auto& r : regions)
    if (std::abs(r.centerLat_deg - 46.2237) < 1e-9) {
      for (auto& l : r.layers)
        if (l.id == kMetarFogSlot) l.base_m += 300;
      ASSERT_TRUE(f.weather.submit({{SetRegion{r, {}}}, "test", "api"}));
    }
  const auto after = f.check(0);
  for (const auto& s : after["stations"])
    if (s["icao"] == "LJLJ") {
      EXPECT_FALSE(s["visibility_ok"]) << s.dump();
      EXPECT_FALSE(s["ok"]);
      EXPECT_NEAR(s["reported"]["visibility_m"].get<double>(), 200, 1e-6);
      EXPECT_TRUE(s["drawn"]["visibility_m"].is_null()) << s.dump();
    }
}

// A replay's frame drew the weather at its own clock: the check is made at
// the clock asked, with the regions as they stand then. LJLJ's region gets
// an overcast scheduled an hour ahead: before it the check reads the
// report's three layers, after it the one overcast layer.
TEST(Conformance, TheCheckIsMadeAtTheClockAsked) {
  Fixture f;
  f.metar(kReports);
  const double now = f.weather.clockNow();
  auto regions = f.weather.regionsAt(now);
  const auto ljlj = std::find_if(regions.begin(), regions.end(),
                                 [](const weather::Region& r) { return std::abs(r.centerLat_deg - 46.2237) < 1e-9; });
  ASSERT_NE(ljlj, regions.end());
  weather::Region later = *ljlj;
  ASSERT_FALSE(later.layers.empty());
  weather::CloudLayer overcast = later.layers.front();
  overcast.coverage = 1;
  later.layers = {overcast};
  ASSERT_TRUE(f.weather.submit({{SetRegion{later, Timing{now + 3600, 0}}}, "test", "api"}));
  ConformanceQuery q;
  q.gridPoints = 0;
  q.lat_deg = 46.2237;  // LJLJ; LOWK is 47 km away, LIPQ farther
  q.lon_deg = 14.4576;
  q.radius_m = 30000;
  std::vector<std::size_t> reportedLayers;
  for (const double at : {now + 60, now + 7200}) {
    q.clock_s = at;
    const auto j = conformanceJson(f.weather, kStations, q);
    EXPECT_DOUBLE_EQ(j["clock_s"].get<double>(), at);
    ASSERT_EQ(j["stations"].size(), 1u) << j.dump();
    EXPECT_EQ(j["stations"][0]["icao"], "LJLJ");
    EXPECT_TRUE(j["stations"][0]["ok"]) << j.dump();
    reportedLayers.push_back(j["stations"][0]["reported"]["layers"].size());
    if (at > now + 3600) {
      EXPECT_EQ(j["stations"][0]["drawn"]["layers"][0]["oktas"], 8) << j.dump();
    }
  }
  EXPECT_EQ(reportedLayers, (std::vector<std::size_t>{3, 1}));
}

TEST(Conformance, QueryKeysAreChecked) {
  EXPECT_TRUE(parseConformanceQuery(""));
  EXPECT_TRUE(parseConformanceQuery("clock_s=-12.5"));
  EXPECT_EQ(*parseConformanceQuery("clock_s=86400")->clock_s, 86400);
  EXPECT_FALSE(parseConformanceQuery("clock_s=1e300"));
  EXPECT_FALSE(parseConformanceQuery("clock_s=nan"));
  EXPECT_TRUE(parseConformanceQuery("stations=10&grid_points=5&lat_deg=46&lon_deg=14&radius_m=100000"));
  EXPECT_FALSE(parseConformanceQuery("lat_deg=46"));
  EXPECT_FALSE(parseConformanceQuery("stations=-1"));
  EXPECT_FALSE(parseConformanceQuery("grid_points=1e9"));
  EXPECT_FALSE(parseConformanceQuery("bogus=1"));
  EXPECT_FALSE(parseConformanceQuery("stations=1&stations=2"));
  EXPECT_EQ(oktas(0), 0);
  EXPECT_EQ(oktas(0.01), 1);
  EXPECT_EQ(oktas(0.5), 4);
  EXPECT_EQ(oktas(0.99), 7);
  EXPECT_EQ(oktas(1), 8);
}

// The bound on the clock a check may be asked at is written once
// (weather::kMaxAskedClock_s) and applied by the server's query parser and
// by skyshell-conformance's frames reader: a frame at the bound is read and
// the query the tool makes of it is answered; one second past it, either
// way, both refuse.
TEST(Conformance, TheServerAndTheToolAgreeOnTheClocksBound) {
  auto frame = [](double clock_s) {
    char line[256];
    std::snprintf(line, sizeof line,
                  R"({"frame":1,"host_time_s":0,"lat_deg":46,"lon_deg":14,"alt_m":1500,"weather_clock_s":%.3f})",
                  clock_s);
    return std::string(line);
  };
  auto query = [](double clock_s) {
    char q[64];
    std::snprintf(q, sizeof q, "clock_s=%.3f", clock_s);
    return std::string(q);
  };
  for (const double side : {1.0, -1.0}) {
    SCOPED_TRACE(side > 0 ? "ahead" : "behind");
    const double bound_s = side * weather::kMaxAskedClock_s, past_s = side * (weather::kMaxAskedClock_s + 1);
    const auto point = sim::parseTrackLine(frame(bound_s));
    ASSERT_TRUE(point) << point.error().detail;
    const std::string target = sim::conformanceTarget(*point, {});
    const auto asked = parseConformanceQuery(target.substr(target.find('?') + 1));
    ASSERT_TRUE(asked) << target << ": " << asked.error().detail;
    EXPECT_EQ(*asked->clock_s, bound_s);
    EXPECT_FALSE(sim::parseTrackLine(frame(past_s)));
    EXPECT_FALSE(parseConformanceQuery(query(past_s)));
  }
}

}  // namespace
}  // namespace sky::server
