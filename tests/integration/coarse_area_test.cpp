// The renderer's two areas of interest against a real skyshell-weatherd: the
// detailed area (120 km at ~4.9 km tiles) and the wide coarse one (900 km at
// ~18 km tiles) for the weather map's coarse ring. A storm region 300 km
// from the flight is outside the detailed area, so its tiles can reach the
// renderer only through the coarse one: the frames' metadata must show the
// coarse area holding tiles while the detailed area, uniform there, holds none.
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "child_process.hpp"
#include "weatherd_process.hpp"

namespace fs = std::filesystem;

namespace sky::test {
namespace {

std::vector<nlohmann::json> readFrames(const fs::path& jsonl) {
  std::vector<nlohmann::json> out;
  std::ifstream in(jsonl);
  for (std::string line; std::getline(in, line);)
    if (!line.empty()) out.push_back(nlohmann::json::parse(line));
  return out;
}

TEST(CoarseArea, FarWeatherReachesTheRendererThroughTheCoarseArea) {
  Weatherd w("coarse-area");
  ASSERT_GT(w.streamPort, 0u) << w.process->log();
  // 300 km north of the test flight (46.2 N 12.8 E): 2.7 degrees of latitude.
  const auto posted = w.request("POST", "/api/changes", R"({"changes": [{"op": "set_region", "region": {
      "id": 3, "center_lat_deg": 48.9, "center_lon_deg": 12.8, "size_x_m": 40000, "size_y_m": 40000,
      "corner_radius_m": 5000, "transition_m": 5000, "drifts_with_wind": false,
      "layers": [{"id": 1, "type": "cumulus", "base_m": 1500, "thickness_m": 1500, "transition_band_m": 100,
                  "coverage": 1.0, "density": 1,
                  "wind": {"speed_mps": 10, "from_deg": 270, "vertical_mps": 0}}]}}]})");
  ASSERT_EQ(posted.status, 200) << posted.body;

  const fs::path out = w.dir / "out";
  ChildProcess render({SKY_RENDER, "--headless", "--server", "127.0.0.1:" + std::to_string(w.streamPort), "--replay",
                       SKY_TEST_FLIGHT, "--step", "3", "--no-exr", "--no-video", "--out", out.string(), "--width",
                       "160", "--height", "90"},
                      (w.dir / "render.log").string(), {"ASAN_OPTIONS=detect_leaks=0:abort_on_error=1"});
  ASSERT_EQ(render.wait(300s).value_or(-1), 0) << render.log();
  const auto frames = readFrames(out / "frames" / "frames.jsonl");
  ASSERT_EQ(frames.size(), 3u) << render.log();
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
}

}  // namespace
}  // namespace sky::test
