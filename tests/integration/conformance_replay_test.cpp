// The conformance check along a replayed flight (issue 22): a weather server
// with the GFS forecast and three METAR stations round the bundled glider
// flight (NE Italy, one of them in mist), a headless replay of a minute of it, and
// skyshell-conformance asking the server's check at the replay's frames,
// each at the weather clock the frame drew. Every station in reach draws its
// report, the forecast's grid points their cover, and the table says so.
#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "child_process.hpp"
#include "weatherd_process.hpp"

namespace fs = std::filesystem;
using namespace std::chrono_literals;

namespace sky::test {
namespace {

constexpr const char* kMetar = R"({"apply": true, "reports": [
    "METAR LIPA 221150Z 24008KT 9999 BKN020 12/06 Q1018",
    "METAR LIPH 221150Z 24008KT 2500 BR FEW015 OVC040 12/06 Q1018",
    "METAR LIPQ 221150Z 24008KT CAVOK 12/06 Q1018"],
  "stations": [{"icao": "LIPA", "lat_deg": 46.0319, "lon_deg": 12.5965, "elevation_m": 125},
               {"icao": "LIPH", "lat_deg": 45.6484, "lon_deg": 12.1944, "elevation_m": 18},
               {"icao": "LIPQ", "lat_deg": 45.8275, "lon_deg": 13.4722, "elevation_m": 12}]})";

TEST(ConformanceAlongAReplay, EveryStationInReachDrawsItsReport) {
  const fs::path dir = fs::path(SKY_TEST_OUTPUT_DIR) / "conformance-replay";
  Weatherd w("conformance-replay-weatherd", SKY_SCENARIO_CLEAR, false,
             {"--grib", std::string(SKY_TEST_DATA_DIR) + "/grib/gfs-2p5deg-2011011012-f120-cloud-layers-10m-wind.grib2"});
  ASSERT_GT(w.httpPort, 0u) << w.process->log();
  const auto applied = w.request("POST", "/api/metar", kMetar);
  ASSERT_EQ(applied.status, 200) << applied.body;

  fs::remove_all(dir);
  fs::create_directories(dir);
  // A minute of the glider's thermal circles, a frame every 20 s.
  ChildProcess render({SKY_RENDER, "--headless", "--server", "127.0.0.1:" + std::to_string(w.streamPort), "--replay",
                       SKY_GLIDER_FLIGHT, "--replay-start", "1000", "--replay-end", "1060", "--step", "20", "--out",
                       dir.string(), "--width", "96", "--height", "54"},
                      (dir / "render.log").string(), {"ASAN_OPTIONS=detect_leaks=0:abort_on_error=1"});
  ASSERT_EQ(render.wait(300s), 0) << render.log();

  ChildProcess check({SKY_CONFORMANCE, "--api", "http://127.0.0.1:" + std::to_string(w.httpPort), "--frames",
                      (dir / "frames" / "frames.jsonl").string(), "--every", "20", "--radius-km", "150"},
                     (dir / "conformance.log").string());
  ASSERT_EQ(check.wait(120s), 0) << check.log();

  std::ifstream in(dir / "conformance.json");
  const auto j = nlohmann::json::parse(in, nullptr, false);
  ASSERT_TRUE(j.is_object()) << check.log();
  const auto& points = j["points"];
  ASSERT_EQ(points.size(), 4u) << j.dump(1);
  std::set<std::string> met;
  for (std::size_t i = 0; i < points.size(); ++i) {
    const auto& p = points[i];
    SCOPED_TRACE(p.dump());
    if (i > 0) {
      // A point per 20 s of flight, each at the clock its frame drew (the
      // server's rate: 1).
      EXPECT_NEAR(p["flight_s"].get<double>() - points[i - 1]["flight_s"].get<double>(), 20, 1e-6);
      EXPECT_NEAR(p["weather_clock_s"].get<double>() - points[i - 1]["weather_clock_s"].get<double>(), 20, 1e-3);
    }
    EXPECT_NEAR(p["lat_deg"].get<double>(), 46.2, 0.1);
    EXPECT_NEAR(p["lon_deg"].get<double>(), 12.8, 0.1);
    // The three stations the request brought, named as it named them.
    ASSERT_EQ(p["stations"].size(), 3u);
    for (const auto& s : p["stations"]) {
      met.insert(s["name"].get<std::string>());
      EXPECT_TRUE(s["ok"]);
      EXPECT_LE(s["oktas_off"].get<int>(), 1);
      EXPECT_LE(s["distance_km"].get<double>(), 150);
      if (s["name"] == "LIPA") {
        // BKN020 at 125 m: the ceiling reported and drawn.
        EXPECT_NEAR(s["ceiling_reported_m"].get<double>(), 125 + 2000 * 0.3048, 1);
        EXPECT_NEAR(s["ceiling_drawn_m"].get<double>(), s["ceiling_reported_m"].get<double>(), 30.48);
      }
      if (s["name"] == "LIPQ") {
        EXPECT_TRUE(s["ceiling_reported_m"].is_null());  // CAVOK
        EXPECT_TRUE(s["ceiling_drawn_m"].is_null());
        EXPECT_TRUE(s["visibility_drawn_m"].is_null());
      }
      if (s["name"] == "LIPH") {
        // 2500 BR: mist of that visibility; the ceiling is the overcast's, not the mist's.
        EXPECT_NEAR(s["visibility_reported_m"].get<double>(), 2500, 1e-6);
        EXPECT_NEAR(s["visibility_drawn_m"].get<double>(), 2500, 0.2 * 2500);
        EXPECT_NEAR(s["ceiling_reported_m"].get<double>(), 18 + 4000 * 0.3048, 1);
      }
    }
    // The forecast's grid (2.5 degrees) has two points within 150 km (45 N
    // and 47.5 N at 12.5 E); each draws its cover or lies in a station's reach.
    EXPECT_GE(p["grid_points"].get<int>(), 1);
    EXPECT_EQ(p["grid_ok"], p["grid_points"]);
  }
  EXPECT_EQ(met, (std::set<std::string>{"LIPA", "LIPH", "LIPQ"}));
  EXPECT_EQ(j["summary"]["station_checks_ok"], j["summary"]["station_checks"]);
  EXPECT_TRUE(j["summary"]["stations_failed"].empty());

  std::ifstream mdIn(dir / "conformance.md");
  std::stringstream md;
  md << mdIn.rdbuf();
  EXPECT_NE(md.str().find("| 1000 |"), std::string::npos) << md.str();
  EXPECT_NE(md.str().find("LIPA ("), std::string::npos) << md.str();
  EXPECT_EQ(md.str().find("FAILS"), std::string::npos) << md.str();
  std::printf("[conformance] %s\n", j["summary"].dump().c_str());
}

}  // namespace
}  // namespace sky::test
