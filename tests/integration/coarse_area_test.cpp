// The renderer's two areas of interest against a real skyshell-weatherd: the
// detailed area (120 km at ~4.9 km tiles) and the wide coarse one (900 km at
// ~18 km tiles) for the weather map's coarse ring. A storm region 300 km
// from the flight is outside the detailed area, so its tiles can reach the
// renderer only through the coarse one: the frames' metadata must show the
// coarse area holding tiles while the detailed area, uniform there, holds none,
// and a change to the storm while the replay runs must reach the weather map
// tile by tile, not as a rebuild.
#include <filesystem>
#include <fstream>
#include <chrono>
#include <string>
#include <thread>
#include <vector>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "child_process.hpp"
#include "weatherd_process.hpp"

namespace fs = std::filesystem;
using namespace std::chrono_literals;

namespace sky::test {
namespace {

std::vector<nlohmann::json> readFrames(const fs::path& jsonl) {
  std::vector<nlohmann::json> out;
  std::ifstream in(jsonl);
  for (std::string line; std::getline(in, line);)
    if (!line.empty()) out.push_back(nlohmann::json::parse(line));
  return out;
}

// A 40 km storm region of layer 1 at this coverage, 300 km north of the test
// flight (46.2 N 12.8 E: 2.7 degrees of latitude), not drifting.
std::string farStorm(double coverage) {
  return R"({"changes": [{"op": "set_region", "region": {
      "id": 3, "center_lat_deg": 48.9, "center_lon_deg": 12.8, "size_x_m": 40000, "size_y_m": 40000,
      "corner_radius_m": 5000, "transition_m": 5000, "drifts_with_wind": false,
      "layers": [{"id": 1, "type": "cumulus", "base_m": 1500, "thickness_m": 1500, "transition_band_m": 100,
                  "coverage": )" +
         std::to_string(coverage) + R"(, "density": 1,
                  "wind": {"speed_mps": 10, "from_deg": 270, "vertical_mps": 0}}]}}]})";
}

TEST(CoarseArea, FarWeatherReachesTheRendererThroughTheCoarseArea) {
  Weatherd w("coarse-area");
  ASSERT_GT(w.streamPort, 0u) << w.process->log();
  const auto posted = w.request("POST", "/api/changes", farStorm(1.0));
  ASSERT_EQ(posted.status, 200) << posted.body;

  const fs::path out = w.dir / "out";
  const fs::path jsonl = out / "frames" / "frames.jsonl";
  // Paced as flown (13 frames over 6 s), so that a change made while it runs
  // arrives between frames.
  ChildProcess render({SKY_RENDER, "--headless", "--server", "127.0.0.1:" + std::to_string(w.streamPort), "--replay",
                       SKY_TEST_FLIGHT, "--step", "0.5", "--replay-pace", "1", "--no-exr", "--no-video", "--out",
                       out.string(), "--width", "160", "--height", "90"},
                      (w.dir / "render.log").string(), {"ASAN_OPTIONS=detect_leaks=0:abort_on_error=1"});
  // Once a few frames are out, the storm thins: only the tiles it reaches
  // change, and they arrive as a Delta of the coarse area.
  const auto until = std::chrono::steady_clock::now() + 180s;
  while (readFrames(jsonl).size() < 3 && std::chrono::steady_clock::now() < until)
    std::this_thread::sleep_for(50ms);
  ASSERT_GE(readFrames(jsonl).size(), 3u) << render.log();
  const auto thinned = w.request("POST", "/api/changes", farStorm(0.3));
  ASSERT_EQ(thinned.status, 200) << thinned.body;
  ASSERT_EQ(render.wait(300s).value_or(-1), 0) << render.log();

  const auto frames = readFrames(jsonl);
  ASSERT_EQ(frames.size(), 13u) << render.log();
  for (const auto& f : frames) {
    const auto& areas = f.at("weather_areas");
    ASSERT_EQ(areas.size(), 2u) << f.dump();
    EXPECT_EQ(areas[0]["tiles"], 0) << "the region is 180 km beyond the detailed area: uniform there";
    EXPECT_EQ(areas[0]["tile_level"], 11);
    EXPECT_EQ(areas[1]["tile_level"], 9) << "the coarse area's ~18 km tiles";
    // Every cell of the 900 km cap for the one layer the region varies.
    EXPECT_GT(areas[1]["tiles"].get<int>(), 5000) << f.dump();
  }
  EXPECT_NE(render.log().find("snapshot of area 1"), std::string::npos) << render.log();

  // The map is built on the first frame with both areas' weather in it.
  // The thinning reaches it tile by tile: a frame that rewrote texels
  // without a rebuild, uploading a small part of what the first frame did.
  EXPECT_TRUE(frames[0]["weather_map"]["rebuilt"]) << frames[0].dump();
  const auto whole = frames[0]["weather_map"]["bytes_uploaded"].get<std::uint64_t>();
  EXPECT_GT(whole, 0u);
  std::size_t perTile = 0;
  for (std::size_t i = 1; i < frames.size(); ++i) {
    const auto& m = frames[i]["weather_map"];
    // The camera may cross into another anchor cell (5 km lattice) on its
    // 330 m of flight; nothing else rebuilds the map here.
    if (m["rebuilt"]) {
      EXPECT_EQ(m["reason"], "anchor moved") << frames[i].dump();
      continue;
    }
    if (m["texels_rewritten"].get<std::uint64_t>() == 0) continue;
    ++perTile;
    EXPECT_LT(m["bytes_uploaded"].get<std::uint64_t>() * 20, whole) << frames[i].dump();
  }
  EXPECT_EQ(perTile, 1u) << "one change, applied tile by tile in one frame";
  EXPECT_GT(frames.back()["weather_version"].get<int>(), frames.front()["weather_version"].get<int>());
}

}  // namespace
}  // namespace sky::test
