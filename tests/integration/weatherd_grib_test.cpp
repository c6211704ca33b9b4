// GRIB2 forecasts through skyshell-weatherd as a process: --grib at start,
// POST /api/grib (uploads, paths inside --grib-dir, refusals that leave the
// weather as it was), the weather stream's tiles against the grid values
// ecCodes' grib_get_data prints, a forecast evolving between its steps on
// the weather clock, a restart that decodes the stored files again, and a
// stop while a forecast decodes.
#include <signal.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <future>
#include <thread>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "../unit/server/grib_tools.hpp"
#include "../unit/server/stream_test_client.hpp"
#include "sky/server/forecast.hpp"
#include "sky/weather/tiling.hpp"
#include "weatherd_process.hpp"

namespace fs = std::filesystem;
using namespace std::chrono_literals;

namespace sky::test {
namespace {

using server::gribGetData;
using server::kGfs;
using server::kNam;
using server::Point;

// The snapshot of one area from a fresh stream connection.
weather::WeatherSnapshot snapshotOf(unsigned port, double lat, double lon, double radius_m, int level) {
  server::TestClient c(static_cast<std::uint16_t>(port));
  auto hello = c.read();
  EXPECT_TRUE(hello);
  stream::Subscribe s;
  s.area = {lat, lon, radius_m};
  s.tileLevel = level;
  s.altMin_m = 0;
  s.altMax_m = 12000;
  c.send(s);
  for (int k = 0; k < 20; ++k) {
    auto m = c.read(10s);
    if (!m) break;
    if (auto* snap = std::get_if<weather::WeatherSnapshot>(&*m)) return *snap;
  }
  ADD_FAILURE() << "no snapshot";
  return {};
}

// GFS's 2.5 degree grid (lat 90 to -90, lon 0 to 357.5) read by the test
// from grib_get_data's output: the four grid values round a point.
struct LatLonGrid {
  std::vector<Point> points;
  double at(int i, int j) const { return points[static_cast<std::size_t>(j) * 144 + ((i % 144) + 144) % 144].value; }
  std::pair<double, double> range(double lat, double lon) const {
    const double x = std::fmod(lon + 360, 360) / 2.5, y = (90 - lat) / 2.5;
    const int i = static_cast<int>(std::floor(x)), j = std::min(static_cast<int>(std::floor(y)), 71);
    const double v[] = {at(i, j), at(i + 1, j), at(i, j + 1), at(i + 1, j + 1)};
    return {*std::min_element(v, v + 4), *std::max_element(v, v + 4)};
  }
};

TEST(WeatherdGrib, GfsAtStartDrivesTheStreamWithTheGridsCover) {
  Weatherd w("weatherd-grib-gfs", SKY_SCENARIO_CLEAR, false, {"--grib", kGfs});
  ASSERT_GT(w.streamPort, 0u) << w.process->log();
  const auto state = nlohmann::json::parse(w.request("GET", "/api/state").body);
  ASSERT_TRUE(state["forecast"].is_object()) << state.dump();
  EXPECT_EQ(state["forecast"]["first_valid"], "2011-01-15T12:00Z");
  // Central Europe, 300 km round: the low layer's tiles lie within the four
  // grid values round each cell's centre (1/255 for the wire's steps).
  const auto snap = snapshotOf(w.streamPort, 50, 10, 300000, 9);
  const LatLonGrid low{gribGetData(kGfs, 1)};
  ASSERT_EQ(low.points.size(), 144u * 73u);
  std::size_t n = 0, outside = 0;
  double sum = 0;
  for (const auto& t : snap.tiles) {
    if (t.layerId != server::kForecastLowSlot) continue;
    const auto c = weather::cellCentre(t.cellId);
    const auto [lo, hi] = low.range(c.lat_deg, c.lon_deg);
    if (t.coverage < lo / 100 - 1.0 / 255 || t.coverage > hi / 100 + 1.0 / 255) ++outside;
    sum += t.coverage;
    ++n;
  }
  EXPECT_GT(n, 100u) << "low layer tiles";
  EXPECT_EQ(outside, 0u);
  std::printf("[ grib ] %zu low-layer tiles at level %d, mean cover %.2f\n", n, snap.tileLevel, sum / std::max<std::size_t>(n, 1));
  // The renderers' layer table has the five forecast layers.
  int forecastLayers = 0;
  for (const auto& l : snap.layers) forecastLayers += l.id >= 30 && l.id <= 34;
  EXPECT_EQ(forecastLayers, 5);
  EXPECT_EQ(w.process->stop(), 0) << w.process->log();
}

std::string bytesOf(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), {});
}

TEST(WeatherdGrib, ApiLoadsFilesAndRefusesWhatItMust) {
  const fs::path out = fs::path(SKY_TEST_OUTPUT_DIR) / "weatherd-grib-api-files";
  fs::remove_all(out);
  fs::create_directories(out / "grib");
  fs::copy_file(kNam, out / "grib" / "nam.grib2");
  Weatherd w("weatherd-grib-api", SKY_SCENARIO_CLOUDY, false,
             {"--grib-dir", (out / "grib").string(), "--db", (out / "weather.db").string()});
  ASSERT_GT(w.httpPort, 0u) << w.process->log();
  const std::string before = w.request("GET", "/api/state").body;
  // Refused, the weather as it was.
  EXPECT_EQ(w.request("POST", "/api/grib", R"({"path": "nam.grib2"})", "").status, 401);
  EXPECT_EQ(w.request("POST", "/api/grib", "not grib, not json").status, 400);
  EXPECT_EQ(w.request("POST", "/api/grib", R"({"path": "../weather.db"})").status, 400);
  EXPECT_EQ(w.request("POST", "/api/grib", R"({"path": "/etc/passwd"})").status, 400);
  EXPECT_EQ(w.request("POST", "/api/grib", R"({"path": "absent.grib2"})").status, 404);
  EXPECT_EQ(w.request("POST", "/api/grib", "GRIB and then nothing").status, 400);
  EXPECT_EQ(w.request("POST", "/api/grib", R"({"remove": true})").status, 400);  // none loaded
  auto same = nlohmann::json::parse(w.request("GET", "/api/state").body);
  auto was = nlohmann::json::parse(before);
  EXPECT_EQ(same["layers"], was["layers"]);
  EXPECT_TRUE(same["forecast"].is_null());

  // A path inside --grib-dir: NAM's Lambert grid over North America.
  auto nam = w.request("POST", "/api/grib", R"({"path": "nam.grib2"})");
  ASSERT_EQ(nam.status, 200) << nam.body;
  EXPECT_EQ(nlohmann::json::parse(nam.body)["forecast"]["name"], "nam.grib2");
  // Kansas: the stream has the derived low layer's tiles; Europe has none of it.
  const auto kansas = snapshotOf(w.streamPort, 38.5, -97.5, 300000, 8);
  const auto lowTiles = std::count_if(kansas.tiles.begin(), kansas.tiles.end(), [](const auto& t) {
    return t.layerId == server::kForecastLowSlot && t.coverage > 0;
  });
  EXPECT_GT(lowTiles, 10);
  // And NAM's winds as wind tiles of its three layers, varying over Kansas
  // (the forecast's layers have no wind of their own).
  std::map<std::uint32_t, std::pair<double, double>> eastRange;  // layer -> (min, max) east wind
  for (const auto& t : kansas.windTiles) {
    auto [it, added] = eastRange.try_emplace(t.layerId, t.east_mps, t.east_mps);
    it->second = {std::min<double>(it->second.first, t.east_mps), std::max<double>(it->second.second, t.east_mps)};
  }
  EXPECT_EQ(eastRange.size(), 3u) << kansas.windTiles.size() << " wind tiles";
  for (const auto& [layer, range] : eastRange) {
    std::printf("[ grib ] NAM layer %u: %zu wind tiles at level %d, east wind %.1f to %.1f m/s\n", layer,
                std::size_t(std::count_if(kansas.windTiles.begin(), kansas.windTiles.end(),
                                          [&](const auto& t) { return t.layerId == layer; })),
                kansas.windTileLevel, range.first, range.second);
    EXPECT_GT(range.second - range.first, 2.0) << "layer " << layer;
  }
  const auto europe = snapshotOf(w.streamPort, 48, 11, 100000, 8);
  EXPECT_EQ(std::count_if(europe.tiles.begin(), europe.tiles.end(),
                          [](const auto& t) { return t.layerId == server::kForecastLowSlot && t.coverage > 0; }),
            0);
  // The point query names the source of the cover.
  const auto cond = nlohmann::json::parse(w.request("GET", "/api/conditions?lat_deg=38.5&lon_deg=-97.5&alt_m=1000").body);
  EXPECT_NE(cond["forecast_sources"]["31"].get<std::string>().find("nam.grib2: Sundqvist on r"), std::string::npos)
      << cond.dump();

  // An upload, damaged where ecCodes reads out of bounds: the decoder dies
  // on that field, the server skips it and loads the rest.
  std::string gfs = bytesOf(kGfs);
  gfs[198] = static_cast<char>(0xff);
  auto up = w.request("POST", "/api/grib?name=gfs-damaged.grib2", gfs);
  ASSERT_EQ(up.status, 200) << up.body;
  const auto upj = nlohmann::json::parse(up.body);
  EXPECT_EQ(upj["forecast"]["name"], "gfs-damaged.grib2");
  ASSERT_GE(upj["skipped"].size(), 1u) << up.body;
  EXPECT_NE(upj["skipped"][0].get<std::string>().find("message 1"), std::string::npos) << up.body;
  EXPECT_EQ(upj["forecast"]["layers"].size(), 4u) << "the low layer's field was the damaged one";

  // A restart decodes the stored file again.
  EXPECT_EQ(w.process->stop(), 0) << w.process->log();
  Weatherd again("weatherd-grib-api-2", SKY_SCENARIO_CLOUDY, false, {"--db", (out / "weather.db").string()});
  const auto restored = nlohmann::json::parse(again.request("GET", "/api/state").body);
  EXPECT_EQ(restored["forecast"]["name"], "gfs-damaged.grib2") << again.process->log();
  auto removed = again.request("POST", "/api/grib", R"({"remove": true})");
  ASSERT_EQ(removed.status, 200) << removed.body;
  const auto after = nlohmann::json::parse(again.request("GET", "/api/state").body);
  EXPECT_TRUE(after["forecast"].is_null());
  for (const auto& l : after["layers"]) EXPECT_FALSE(l["id"] >= 30 && l["id"] <= 34) << l.dump();
  EXPECT_EQ(again.process->stop(), 0) << again.process->log();
}

TEST(WeatherdGrib, AForecastEvolvesBetweenItsStepsOnTheWeatherClock) {
  // Two steps six hours apart: the real +120 h file, and the same at +126 h
  // with every value halved (ecCodes' grib_set).
  const fs::path dir = fs::path(SKY_TEST_OUTPUT_DIR) / "weatherd-grib-steps";
  fs::remove_all(dir);
  fs::create_directories(dir);
  fs::copy_file(kGfs, dir / "gfs-f120.grib2");
  const std::string cmd = std::string(SKY_GRIB_SET) + " -s endStep=126,scaleValuesBy=0.5 '" + kGfs + "' '" +
                          (dir / "gfs-f126.grib2").string() + "'";
  ASSERT_EQ(std::system(cmd.c_str()), 0) << cmd;
  Weatherd w("weatherd-grib-evolve", SKY_SCENARIO_CLEAR, false, {"--grib", dir.string()});
  const auto state = nlohmann::json::parse(w.request("GET", "/api/state").body);
  ASSERT_EQ(state["forecast"]["steps"], 2) << state.dump();
  const double anchor = state["forecast"]["anchor_clock_s"];
  // Six forecast hours in six seconds.
  ASSERT_EQ(w.request("POST", "/api/changes", R"({"changes": [{"op": "set_clock", "rate": 3600}]})").status, 200);
  // The low layer's tile at a grid point (50 N 10 E) as a subscriber gets
  // it: its cover falls from c0 to c0 / 2 over the six hours.
  const LatLonGrid low{gribGetData(kGfs, 1)};
  const double c0 = low.at(4, 16) / 100;  // 10 E, 50 N
  ASSERT_GT(c0, 0.3);
  const std::uint64_t cell = weather::cellAt(50, 10, 11);
  int samples = 0;
  for (int k = 0; k < 8; ++k) {
    const double clock = nlohmann::json::parse(w.request("GET", "/api/state").body)["clock_s"];
    const auto snap = snapshotOf(w.streamPort, 50, 10, 3000, 11);
    const auto t = std::find_if(snap.tiles.begin(), snap.tiles.end(), [&](const auto& t) {
      return t.layerId == server::kForecastLowSlot && t.cellId == cell;
    });
    ASSERT_NE(t, snap.tiles.end()) << "no low-layer tile at 50 N 10 E, level " << snap.tileLevel;
    const double f = std::clamp((snap.weatherClock_s - anchor) / (6 * 3600), 0.0, 1.0);
    // 1/255 on the wire, a minute of forecast time per quantum, and the
    // cell's centre within a kilometre of the grid point: 0.01.
    EXPECT_NEAR(t->coverage, c0 * (1 - 0.5 * f), 0.01) << "at clock " << snap.weatherClock_s << " (f " << f << ")";
    samples += clock >= 0;
    std::this_thread::sleep_for(900ms);
  }
  EXPECT_EQ(samples, 8);
  EXPECT_EQ(w.process->stop(), 0) << w.process->log();
}

// SIGTERM while a forecast decodes off the io thread: the decoder is killed,
// the process exits cleanly (not after the decoder's timeout, nor killed by
// the test's SIGKILL), and the request is let go without an answer.
TEST(WeatherdGrib, ATermDuringADecodeStopsTheDecoderAndExitsCleanly) {
  const fs::path out = fs::path(SKY_TEST_OUTPUT_DIR) / "weatherd-grib-term-files";
  fs::remove_all(out);
  fs::create_directories(out / "grib");
  fs::copy_file(kNam, out / "grib" / "nam.grib2");
  const server::GatedDecoder gate(out / "gate",
                                  (fs::path(SKY_WEATHERD).parent_path() / "skyshell-grib-decode").string());
  Weatherd w("weatherd-grib-term", SKY_SCENARIO_CLEAR, false,
             {"--grib-dir", (out / "grib").string(), "--grib-decoder", gate.executable().string()});
  ASSERT_GT(w.httpPort, 0u) << w.process->log();
  auto post = std::async(std::launch::async, [port = w.httpPort] {
    sim::HttpRequest r;
    r.method = "POST";
    r.port = static_cast<unsigned short>(port);
    r.target = "/api/grib";
    r.body = R"({"path": "nam.grib2"})";
    r.bearerToken = kToken;
    r.timeout = 60s;
    return sim::httpRequest(r);
  });
  const pid_t decoder = gate.waitUntilStarted(60s);
  ASSERT_GT(decoder, 0) << w.process->log();
  EXPECT_EQ(w.request("GET", "/healthz").status, 200) << "served while the forecast decodes";
  EXPECT_EQ(w.process->stop(), 0) << w.process->log();
  EXPECT_EQ(::kill(decoder, 0), -1) << "the decoder outlived the server";
  const auto answer = post.get();
  EXPECT_FALSE(answer) << "answered " << answer->status << " " << answer->body;
}

}  // namespace
}  // namespace sky::test
