// What skyshell-render --headless --replay leaves per frame besides the PNG:
// an EXR whose radiance, transmittance and depth channels (read back by
// tinyexr) equal the PFM floats of the same frame and, tonemapped, the PNG;
// physics on the channels (a clear sky: transmittance 1 and depth 0
// everywhere; cloud: depth exactly where light was taken); and a metadata
// line per frame in frames.jsonl with the pose, weather clock and version,
// sun, preset, settings, seeds, resolution and GPU time per pass, summed up
// per pass in report.json; and the noise cache across starts of the process.
#include <algorithm>
#include <array>
#include <cstdio>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>
#include <tinyexr.h>

#define STB_IMAGE_IMPLEMENTATION
#define STBI_ONLY_PNG
#include <stb_image.h>

#include "child_process.hpp"

namespace fs = std::filesystem;
using namespace std::chrono_literals;

namespace sky::test {
namespace {

constexpr int kWidth = 96, kHeight = 54;
// 0, 2, 4, 6 s of the 6 s test flight.
constexpr std::size_t kFrames = 4;

std::string readAll(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

// PFM, top row first (the file stores the bottom row first).
std::vector<float> readPfm(const fs::path& path, int channels) {
  std::ifstream f(path, std::ios::binary);
  std::string magic;
  int w = 0, h = 0;
  float scale = 0;
  f >> magic >> w >> h >> scale;
  f.get();
  EXPECT_EQ(magic, channels == 3 ? "PF" : "Pf") << path;
  EXPECT_EQ(w, kWidth);
  EXPECT_EQ(h, kHeight);
  const std::size_t row = std::size_t(w) * channels;
  std::vector<float> file(row * h), out(row * h);
  f.read(reinterpret_cast<char*>(file.data()), std::streamsize(file.size() * sizeof(float)));
  EXPECT_TRUE(f) << path;
  for (int y = 0; y < h; ++y)
    std::copy_n(file.begin() + std::ptrdiff_t((h - 1 - y) * row), row, out.begin() + std::ptrdiff_t(y * row));
  return out;
}

std::map<std::string, std::vector<float>> readExr(const fs::path& path) {
  std::map<std::string, std::vector<float>> out;
  EXRVersion version;
  EXRHeader header;
  InitEXRHeader(&header);
  const char* err = nullptr;
  if (ParseEXRVersionFromFile(&version, path.c_str()) != TINYEXR_SUCCESS ||
      ParseEXRHeaderFromFile(&header, &version, path.c_str(), &err) != TINYEXR_SUCCESS) {
    ADD_FAILURE() << path << ": " << (err ? err : "not an EXR");
    FreeEXRErrorMessage(err);
    return out;
  }
  for (int c = 0; c < header.num_channels; ++c) header.requested_pixel_types[c] = TINYEXR_PIXELTYPE_FLOAT;
  EXRImage image;
  InitEXRImage(&image);
  if (LoadEXRImageFromFile(&image, &header, path.c_str(), &err) != TINYEXR_SUCCESS) {
    ADD_FAILURE() << path << ": " << (err ? err : "cannot load");
    FreeEXRErrorMessage(err);
    FreeEXRHeader(&header);
    return out;
  }
  EXPECT_EQ(image.width, kWidth);
  EXPECT_EQ(image.height, kHeight);
  for (int c = 0; c < header.num_channels; ++c) {
    const auto* plane = reinterpret_cast<const float*>(image.images[c]);
    out[header.channels[c].name].assign(plane, plane + std::size_t(image.width) * image.height);
  }
  FreeEXRImage(&image);
  FreeEXRHeader(&header);
  return out;
}

// The PNG's display transform as docs/ground-truth.md ("The camera's
// exposure") states it, written out here: the frame's recorded camera
// exposure (frames.jsonl "camera_exposure"), the ACES filmic fit of
// Narkowicz 2015, the sRGB transfer (IEC 61966-2-1), 8 bits.
int tonemapped(float linear, double exposure) {
  const double x = std::max(0.0, double(linear) * exposure);
  const double aces = std::clamp((x * (2.51 * x + 0.03)) / (x * (2.43 * x + 0.59) + 0.14), 0.0, 1.0);
  const double srgb = aces <= 0.0031308 ? 12.92 * aces : 1.055 * std::pow(aces, 1 / 2.4) - 0.055;
  return int(std::lround(srgb * 255));
}

struct ReplayResult {
  fs::path dir;
  std::vector<nlohmann::json> frames;
  nlohmann::json report;
  std::string log;
};

ReplayResult replay(const std::string& name, const std::string& scenario, std::vector<std::string> extra = {}) {
  ReplayResult run;
  run.dir = fs::path(SKY_TEST_OUTPUT_DIR) / ("outputs-" + name);
  fs::remove_all(run.dir);
  fs::create_directories(run.dir);
  std::vector<std::string> argv = {SKY_RENDER, "--headless", "--replay", SKY_TEST_FLIGHT, "--weather-file", scenario,
                                   "--step", "2", "--out", run.dir.string(), "--width", std::to_string(kWidth),
                                   "--height", std::to_string(kHeight), "--write-float", "--no-video"};
  argv.insert(argv.end(), extra.begin(), extra.end());
  ChildProcess render(argv, run.dir.string() + ".log", {"ASAN_OPTIONS=detect_leaks=0:abort_on_error=1"});
  const auto code = render.wait(300s);
  run.log = render.log();
  EXPECT_EQ(code.value_or(-1), 0) << run.log;
  std::ifstream jsonl(run.dir / "frames" / "frames.jsonl");
  for (std::string line; std::getline(jsonl, line);)
    if (!line.empty()) run.frames.push_back(nlohmann::json::parse(line));
  if (fs::exists(run.dir / "report.json")) run.report = nlohmann::json::parse(readAll(run.dir / "report.json"));
  return run;
}

TEST(HeadlessOutputs, ExrChannelsEqualTheLinearValuesAndThePng) {
  const ReplayResult run = replay("cloudy", SKY_SCENARIO_CLOUDY);
  ASSERT_EQ(run.frames.size(), kFrames);
  std::size_t cloudyPixels = 0;
  for (const auto& f : run.frames) {
    SCOPED_TRACE(f.dump());
    const fs::path frames = run.dir / "frames";
    ASSERT_TRUE(f.contains("exr"));
    const auto exr = readExr(frames / f["exr"].get<std::string>());
    ASSERT_EQ(exr.size(), 5u) << "R, G, B, cloud.depth, cloud.transmittance";
    const auto& R = exr.at("R");
    const auto& G = exr.at("G");
    const auto& B = exr.at("B");
    const auto& T = exr.at("cloud.transmittance");
    const auto& Z = exr.at("cloud.depth");
    const fs::path png = frames / f["file"].get<std::string>();
    const auto radiance = readPfm(fs::path(png).replace_extension(".pfm"), 3);
    const auto transmittance = readPfm(fs::path(png).replace_extension(".transmittance.pfm"), 1);
    int w = 0, h = 0, n = 0;
    const std::string pngBytes = readAll(png);
    unsigned char* rgb = stbi_load_from_memory(reinterpret_cast<const unsigned char*>(pngBytes.data()),
                                               int(pngBytes.size()), &w, &h, &n, 3);
    ASSERT_NE(rgb, nullptr) << png;
    ASSERT_EQ(w, kWidth);
    ASSERT_EQ(h, kHeight);
    int worstLsb = 0;
    const double exposure = f["camera_exposure"]["exposure"].get<double>();
    for (std::size_t i = 0; i < std::size_t(kWidth * kHeight); ++i) {
      ASSERT_EQ(R[i], radiance[i * 3 + 0]) << "pixel " << i;
      ASSERT_EQ(G[i], radiance[i * 3 + 1]) << "pixel " << i;
      ASSERT_EQ(B[i], radiance[i * 3 + 2]) << "pixel " << i;
      ASSERT_EQ(T[i], transmittance[i]) << "pixel " << i;
      const float linear[3] = {R[i], G[i], B[i]};
      for (std::size_t c = 0; c < 3; ++c)
        worstLsb = std::max(worstLsb, std::abs(int(rgb[i * 3 + c]) - tonemapped(linear[c], exposure)));
      // Physics: transmittance in [0, 1]; depth exactly where light was taken,
      // and within the march's reach (600 km plus one 60 km span).
      ASSERT_GE(T[i], 0.0f);
      ASSERT_LE(T[i], 1.0f);
      if (T[i] == 1.0f) {
        ASSERT_EQ(Z[i], 0.0f) << "pixel " << i;
      } else if (T[i] < 0.99f) {
        ASSERT_GT(Z[i], 0.0f) << "pixel " << i;
        ASSERT_LT(Z[i], 660000.0f) << "pixel " << i;
        ++cloudyPixels;
      }
    }
    stbi_image_free(rgb);
    EXPECT_LE(worstLsb, 1) << "PNG is not the tonemapped EXR radiance";
  }
  EXPECT_GT(cloudyPixels, std::size_t(kWidth * kHeight / 10)) << "the cumulus scenario must show cloud";
}

TEST(HeadlessOutputs, ClearSkyHasTransmittanceOneAndNoCloudDepth) {
  const ReplayResult run = replay("clear", SKY_SCENARIO_CLEAR);
  ASSERT_EQ(run.frames.size(), kFrames);
  for (const auto& f : run.frames) {
    const auto exr = readExr(run.dir / "frames" / f["exr"].get<std::string>());
    ASSERT_EQ(exr.count("cloud.transmittance"), 1u);
    for (std::size_t i = 0; i < std::size_t(kWidth * kHeight); ++i) {
      ASSERT_EQ(exr.at("cloud.transmittance")[i], 1.0f) << "pixel " << i;
      ASSERT_EQ(exr.at("cloud.depth")[i], 0.0f) << "pixel " << i;
    }
  }
}

TEST(HeadlessOutputs, MetadataDescribesEachFrameAndTheReportSumsGpuTimes) {
  const ReplayResult run = replay("metadata", SKY_SCENARIO_CLOUDY);
  ASSERT_EQ(run.frames.size(), kFrames);
  for (std::size_t i = 0; i < kFrames; ++i) {
    const auto& f = run.frames[i];
    SCOPED_TRACE(f.dump());
    EXPECT_EQ(f["frame"], i);
    EXPECT_EQ(f["preset"], "high");
    EXPECT_EQ(f["march"]["primary_steps"], 48);
    EXPECT_EQ(f["resolution"], nlohmann::json::array({kWidth, kHeight}));
    EXPECT_EQ(f["vertical_fov_deg"], 60.0);
    EXPECT_EQ(f["noise_seeds"]["shape"], 1);
    EXPECT_GE(f["weather_version"].get<int>(), 1);
    EXPECT_EQ(f["weather_connected"], false) << "--weather-file: no server";
    for (const char* key : {"lat_deg", "lon_deg", "alt_m", "yaw_deg", "pitch_deg", "roll_deg", "weather_clock_s",
                            "sun_azimuth_deg", "sun_elevation_deg"})
      EXPECT_TRUE(f[key].is_number()) << key;
    EXPECT_EQ(f["sun_azimuth_deg"], 135.0) << "a CSV flight has no date: the --sun-azimuth default";
    EXPECT_EQ(f["sun_elevation_deg"], 40.0);
    // GPU timestamps of the cloud pass every frame; the weather map is
    // uploaded on the first frame (the same weather afterwards).
    ASSERT_TRUE(f["gpu_ms"].contains("clouds"));
    const double clouds = f["gpu_ms"]["clouds"];
    EXPECT_GT(clouds, 0.0);
    EXPECT_LE(clouds, f["render_ms"].get<double>()) << "the GPU part of a frame cannot outlast the frame";
    EXPECT_EQ(f["gpu_ms"].contains("weather_upload"), i == 0);
    EXPECT_GT(f["cpu_ms"].get<double>(), 0.0);
    // The EXR's units: the sun's 20 units stand for 1361 W/m^2 and 128 klx.
    EXPECT_NEAR(f["units"]["radiance_W_m2_sr"].get<double>(), 1361.0 / 20, 1e-9);
    EXPECT_NEAR(f["units"]["luminance_cd_m2"].get<double>(), 128000.0 / 20, 1e-9);
    // Auto exposure by default: frames 2 s apart each meter (every 0.25 s),
    // the first takes its metering at once; the exposure is Lagarde 2014's
    // 1 / (1.2 x 2^EV100) per cd/m^2, in the 6400 cd/m^2 units.
    const auto& e = f["camera_exposure"];
    EXPECT_EQ(e["mode"], "auto");
    EXPECT_EQ(e["metered"], true);
    const double ev100 = e["ev100"].get<double>(), metered = e["metered_ev100"].get<double>();
    EXPECT_GE(metered, 5.32);
    EXPECT_LE(metered, 18.0);
    if (i == 0) {
      EXPECT_EQ(ev100, metered);
    }
    EXPECT_NEAR(e["exposure"].get<double>() * 1.2 * std::exp2(ev100) / 6400.0, 1.0, 1e-9);
    EXPECT_GT(e["meter_ms"].get<double>(), 0.0);
  }
  const auto& gpu = run.report["gpu_ms"];
  ASSERT_TRUE(gpu.contains("clouds")) << run.report.dump(2);
  EXPECT_EQ(gpu["clouds"]["frames"], kFrames);
  EXPECT_GT(gpu["clouds"]["p50"].get<double>(), 0.0);
  EXPECT_LE(gpu["clouds"]["p50"].get<double>(), gpu["clouds"]["p90"].get<double>());
  EXPECT_EQ(gpu["weather_upload"]["frames"], 1);
  EXPECT_EQ(run.report["preset"], "high");
  EXPECT_EQ(run.report["camera_exposure"]["mode"], "auto");
  EXPECT_EQ(run.report["camera_exposure"]["adaptation_tau_s"], 0.5);
}

// --ev100 14 --ev-compensation 1: every frame exposed at EV100 14, one EV
// brighter, none metered; the PNG is its EXR at that exposure (checked on
// the first frame, as ExrChannelsEqualTheLinearValuesAndThePng does).
TEST(HeadlessOutputs, FixedEv100IsRecordedAndUsed) {
  const ReplayResult run = replay("fixed-ev", SKY_SCENARIO_CLOUDY, {"--ev100", "14", "--ev-compensation", "1"});
  ASSERT_EQ(run.frames.size(), kFrames);
  for (const auto& f : run.frames) {
    SCOPED_TRACE(f.dump());
    const auto& e = f["camera_exposure"];
    EXPECT_EQ(e["mode"], "fixed");
    EXPECT_EQ(e["ev100"], 14.0);
    EXPECT_EQ(e["compensation_ev"], 1.0);
    EXPECT_EQ(e["metered"], false);
    EXPECT_TRUE(e["metered_ev100"].is_null());
    EXPECT_NEAR(e["exposure"].get<double>(), 6400.0 / (1.2 * std::exp2(13.0)), 1e-12);
  }
  const auto& f = run.frames[0];
  const fs::path png = run.dir / "frames" / f["file"].get<std::string>();
  const auto radiance = readPfm(fs::path(png).replace_extension(".pfm"), 3);
  const std::string bytes = readAll(png);
  int w = 0, h = 0, n = 0;
  unsigned char* rgb =
      stbi_load_from_memory(reinterpret_cast<const unsigned char*>(bytes.data()), int(bytes.size()), &w, &h, &n, 3);
  ASSERT_NE(rgb, nullptr) << png;
  int worstLsb = 0;
  for (std::size_t i = 0; i < std::size_t(w) * std::size_t(h) * 3; ++i)
    worstLsb = std::max(worstLsb, std::abs(int(rgb[i]) - tonemapped(radiance[i], 6400.0 / (1.2 * std::exp2(13.0)))));
  stbi_image_free(rgb);
  EXPECT_LE(worstLsb, 1);
}

// --frame-budget-ms: a budget no level can meet (0.1 ms) takes the frames
// down the ladder to its cheapest level, one decision per frame, and every
// frame's metadata says the level it was drawn at, its march and what the
// model expected; the report counts the frames per level. (That the budget
// is held on a real path: tests/gpu/frame_budget_test.cpp.)
TEST(HeadlessOutputs, FrameBudgetIsRecordedPerFrame) {
  const ReplayResult run = replay("budget", SKY_SCENARIO_CLOUDY, {"--frame-budget-ms", "0.1"});
  ASSERT_EQ(run.frames.size(), kFrames);
  for (std::size_t i = 0; i < kFrames; ++i) {
    const auto& f = run.frames[i];
    SCOPED_TRACE(f.dump());
    ASSERT_TRUE(f.contains("budget"));
    EXPECT_EQ(f["budget"]["target_ms"], 0.1);
    EXPECT_EQ(f["budget"]["level"], i == 0 ? 0 : 7) << "the first frame at the preset, then the cheapest";
    EXPECT_EQ(f["budget"]["name"], i == 0 ? "high" : "realtime/1.5");
    // high marches 48 samples evenly; realtime's way in steps of 60 m in
    // cloud (40 m over 1.5), 1 pixel of 16 at half size.
    EXPECT_EQ(f["budget"]["march"]["primary_steps"], i == 0 ? 48 : 256);
    EXPECT_EQ(f["budget"]["march"]["cloud_step_m"], i == 0 ? 0.0 : 60.0);
    EXPECT_EQ(f["budget"]["interleave"], i == 0 ? 1 : 4);
    EXPECT_EQ(f["budget"]["resolution_divisor"], i == 0 ? 1 : 2);
    EXPECT_GT(f["budget"]["expected_psnr_db"].get<double>(), 0.0);
    EXPECT_EQ(f["budget"]["predicted_ms"].get<double>() > 0, i > 0) << "no prediction before the first frame";
    // From the second frame on the frames are interleaved, the first of
    // them with high's image boxed down to half size as its history.
    ASSERT_EQ(f.contains("temporal"), i > 0);
    if (i > 0) {
      EXPECT_EQ(f["temporal"]["drawn_whole"], false) << f["temporal"]["reason"];
    }
  }
  EXPECT_EQ(run.report["budget"]["target_ms"], 0.1);
  EXPECT_EQ(run.report["budget"]["frames_per_level"]["high"], 1);
  EXPECT_EQ(run.report["budget"]["frames_per_level"]["realtime/1.5"], kFrames - 1);
  // reference has no cheaper level: refused, naming the option.
  ChildProcess refused({SKY_RENDER, "--headless", "--replay", SKY_TEST_FLIGHT, "--weather-file", SKY_SCENARIO_CLOUDY,
                        "--out", (fs::path(SKY_TEST_OUTPUT_DIR) / "outputs-budget-refused").string(), "--preset",
                        "reference", "--frame-budget-ms", "20"},
                       (fs::path(SKY_TEST_OUTPUT_DIR) / "outputs-budget-refused.log").string(),
                       {"ASAN_OPTIONS=detect_leaks=0:abort_on_error=1"});
  EXPECT_EQ(refused.wait(120s).value_or(-1), 2);
  EXPECT_NE(refused.log().find("--frame-budget-ms"), std::string::npos) << refused.log();
}

// --radar: a weather radar picture beside every frame, from the weather the
// frame drew. Rain of 10 mm/h up to 1.5 km over the whole area, the flight
// level at 900 m: every cell within the range echoes Marshall-Palmer's 39.0
// dBZ (10 log10(200 x 10^1.6); the file's layers are uniform, no 8-bit
// tiles), the scale's 35-40 dBZ step (yellow), none past the range.
TEST(HeadlessOutputs, RadarPictureBesideEveryFrame) {
  const fs::path scenario = fs::path(SKY_TEST_OUTPUT_DIR) / "radar-rain.toml";
  {
    std::ofstream f(scenario);
    f << "[clock]\nstart_s = 0.0\nrate = 1.0\n\n[[layer]]\nid = 1\ntype = \"nimbostratus\"\nbase_m = 1500.0\n"
         "thickness_m = 2500.0\ntransition_band_m = 0.0\ncoverage = 1.0\ndensity = 1.0\n"
         "wind = { speed_mps = 5.0, from_deg = 270.0, vertical_mps = 0.0 }\n\n[[layer]]\nid = 2\ntype = \"rain\"\n"
         "base_m = 0.0\nthickness_m = 2500.0\ntransition_band_m = 0.0\ncoverage = 1.0\ndensity = 0.1067\n"
         "wind = { speed_mps = 5.0, from_deg = 270.0, vertical_mps = 0.0 }\n";
  }
  const ReplayResult run = replay("radar", scenario.string(), {"--radar", "40"});
  ASSERT_EQ(run.frames.size(), kFrames);
  for (std::size_t i = 0; i < kFrames; ++i) {
    char name[32];
    std::snprintf(name, sizeof name, "radar_%06zu.png", i);
    const fs::path png = run.dir / "frames" / name;
    int w = 0, h = 0, n = 0;
    unsigned char* px = stbi_load(png.c_str(), &w, &h, &n, 3);
    ASSERT_NE(px, nullptr) << png;
    ASSERT_EQ(w, 160);
    ASSERT_EQ(h, 160);
    auto at = [&](int x, int y) { return std::array<int, 3>{px[(y * w + x) * 3], px[(y * w + x) * 3 + 1], px[(y * w + x) * 3 + 2]}; };
    // Half way to the range, north-east: the 35-40 dBZ colour.
    EXPECT_EQ(at(110, 50), (std::array<int, 3>{253, 248, 2})) << png;
    // A corner is past the range: black.
    EXPECT_EQ(at(2, 2), (std::array<int, 3>{0, 0, 0})) << png;
    stbi_image_free(px);
  }
}

// --sun-shadow: the run draws with the chosen way of shadowing the clouds,
// at every budget level too, and every frame's metadata names it with its
// map's size and memory (two deep maps, one read while the other is built, of
// 128^2 x 4 cascades: 2 RGBA32F parts, 2 MiB each, all of it filled by their
// 8 values a texel).
TEST(HeadlessOutputs, SunShadowMethodIsRecordedPerFrame) {
  const ReplayResult run =
      replay("sun-shadow", SKY_SCENARIO_CLOUDY, {"--sun-shadow", "deep", "--frame-budget-ms", "0.1"});
  ASSERT_EQ(run.frames.size(), kFrames);
  for (const auto& f : run.frames) {
    SCOPED_TRACE(f.dump());
    const auto& sun = f["march"]["sun_shadow"];
    EXPECT_EQ(sun["method"], "deep");
    EXPECT_EQ(sun["size"], 128);
    EXPECT_EQ(sun["cascades"], 4);
    EXPECT_EQ(sun["bytes"], 2 * 128 * 128 * 4 * 2 * 16);
    EXPECT_EQ(sun["used_bytes"], 2 * 128 * 128 * 4 * 32);
    EXPECT_EQ(f["budget"]["march"]["sun_shadow"]["method"], "deep") << "the budget's levels keep the method";
  }
  ChildProcess refused({SKY_RENDER, "--headless", "--replay", SKY_TEST_FLIGHT, "--weather-file", SKY_SCENARIO_CLOUDY,
                        "--out", (fs::path(SKY_TEST_OUTPUT_DIR) / "outputs-sun-shadow-refused").string(),
                        "--sun-shadow", "shadowmap"},
                       (fs::path(SKY_TEST_OUTPUT_DIR) / "outputs-sun-shadow-refused.log").string(),
                       {"ASAN_OPTIONS=detect_leaks=0:abort_on_error=1"});
  EXPECT_NE(refused.wait(120s).value_or(-1), 0);
  EXPECT_NE(refused.log().find("--sun-shadow"), std::string::npos) << refused.log();
}

// The noise textures (the cloud model's shape and detail noise) through
// skyshell-render's --cache-dir: the first start generates and writes them,
// the second loads them (and draws the same bytes), a damaged cache file is
// detected and regenerated (the same image again), the other still loaded.
TEST(HeadlessOutputs, NoiseCacheIsLoadedOnTheSecondStartAndRegeneratedWhenDamaged) {
  const fs::path cache = fs::path(SKY_TEST_OUTPUT_DIR) / "noise-cache";
  fs::remove_all(cache);
  // The weather clock pinned: the scenario's runs with the wall clock, and the
  // same clouds need the same clock.
  const std::vector<std::string> args = {"--cache-dir", cache.string(), "--replay-end", "0", "--no-exr",
                                         "--weather-clock", "0"};
  const ReplayResult first = replay("cache-1", SKY_SCENARIO_CLOUDY, args);
  EXPECT_NE(first.log.find("shape noise 64^3 seed 1: generated into " + cache.string()), std::string::npos)
      << first.log;
  EXPECT_NE(first.log.find("detail noise 32^3 seed 1: generated into " + cache.string()), std::string::npos)
      << first.log;
  std::vector<fs::path> files;  // the shape noise's file first
  for (const auto& e : fs::directory_iterator(cache)) files.push_back(e.path());
  ASSERT_EQ(files.size(), 2u);
  std::sort(files.begin(), files.end(), [](const fs::path& a, const fs::path& b) {
    return (a.filename().string().rfind("shape-", 0) == 0) > (b.filename().string().rfind("shape-", 0) == 0);
  });
  ASSERT_EQ(files[0].filename().string().rfind("shape-", 0), 0u) << files[0];
  ASSERT_EQ(files[1].filename().string().rfind("detail-", 0), 0u) << files[1];
  for (const auto& f : files) EXPECT_EQ(f.extension(), ".noise");
  const auto cachedBytes = readAll(files[0]);
  const auto detailBytes = readAll(files[1]);
  EXPECT_GT(cachedBytes.size(), std::size_t(64 * 64 * 64 * 4)) << "the 64^3 RGBA texels and a header";
  EXPECT_GT(detailBytes.size(), std::size_t(32 * 32 * 32)) << "the 32^3 texels and a header";

  const ReplayResult second = replay("cache-2", SKY_SCENARIO_CLOUDY, args);
  EXPECT_NE(second.log.find("loaded from " + files[0].string()), std::string::npos) << second.log;
  EXPECT_NE(second.log.find("loaded from " + files[1].string()), std::string::npos) << second.log;
  EXPECT_EQ(second.log.find("generated"), std::string::npos) << second.log;
  EXPECT_EQ(readAll(files[0]), cachedBytes);
  EXPECT_EQ(readAll(files[1]), detailBytes);
  const std::string png = "frames/frame_000000.png";
  EXPECT_TRUE(readAll(first.dir / png) == readAll(second.dir / png)) << "cached noise must draw the same clouds";

  std::string damaged = cachedBytes;
  damaged[damaged.size() / 2] = char(damaged[damaged.size() / 2] ^ 0x40);
  std::ofstream(files[0], std::ios::binary | std::ios::trunc) << damaged;
  const ReplayResult third = replay("cache-3", SKY_SCENARIO_CLOUDY, args);
  EXPECT_NE(third.log.find("regenerated into " + files[0].string()), std::string::npos) << third.log;
  EXPECT_NE(third.log.find("checksum"), std::string::npos) << third.log;
  EXPECT_EQ(readAll(files[0]), cachedBytes) << "the damaged file is rewritten whole";
  EXPECT_NE(third.log.find("loaded from " + files[1].string()), std::string::npos) << third.log;
  EXPECT_TRUE(readAll(first.dir / png) == readAll(third.dir / png));
}

// The headless passes (weather upload, cloud pass, timestamps, readback)
// under Khronos validation, on a scenario with several layers.
TEST(HeadlessOutputs, NoValidationErrors) {
  if (!fs::exists("/usr/share/vulkan/explicit_layer.d/VkLayer_khronos_validation.json"))
    GTEST_SKIP() << "no Vulkan validation layer (Debian: vulkan-validationlayers)";
  const ReplayResult run = replay("validation", SKY_SCENARIO_LAYERED,
                                  {"--vulkan-validation"});
  EXPECT_EQ(run.frames.size(), kFrames);
  EXPECT_NE(run.log.find("vulkan validation: 0 errors, 0 warnings"), std::string::npos) << run.log;
}

}  // namespace
}  // namespace sky::test
