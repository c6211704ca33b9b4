// skyshell-render --replay --truth path: a flight's frames path-traced on the
// CPU instead of drawn on the GPU. A short replay of the cumulus scenario
// writes each frame with its samples per pixel and its per-pixel standard
// error (frames.jsonl "truth", the EXR's truth.standard_error, which agree),
// progress lines and a report that says the frames are the truth. A clear
// sky's truth equals the CPU reference (an independent program: the same
// air marched by cpu_reference.cpp in this process) where the view meets no
// ground, and is within its noise and the two ground models' difference
// where it does. Bad --spp values and options that cannot go with the truth
// are refused, before any frame, with a message that says why.
#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>
#include <tinyexr.h>

#include "child_process.hpp"
#include "sky/render/cpu_reference.hpp"
#include "sky/render/presets.hpp"

namespace fs = std::filesystem;
using namespace std::chrono_literals;

namespace sky::test {
namespace {

std::string readAll(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

fs::path outputDir() {
  const fs::path dir = fs::path(SKY_TEST_OUTPUT_DIR) /
                       ("truth-" + std::string(::testing::UnitTest::GetInstance()->current_test_info()->name()));
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir;
}

struct RenderRun {
  int exitCode = -1;
  std::string log;
};

RenderRun run(std::vector<std::string> argv, const fs::path& log) {
  ChildProcess child(std::move(argv), log.string(), {"ASAN_OPTIONS=detect_leaks=0:abort_on_error=1"});
  const auto code = child.wait(300s);
  return {code.value_or(-1), child.log()};
}

std::vector<nlohmann::json> frameLines(const fs::path& out) {
  std::vector<nlohmann::json> lines;
  std::ifstream jsonl(out / "frames" / "frames.jsonl");
  for (std::string line; std::getline(jsonl, line);)
    if (!line.empty()) lines.push_back(nlohmann::json::parse(line));
  return lines;
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
  const std::size_t n = std::size_t(image.width) * image.height;
  for (int c = 0; c < header.num_channels; ++c) {
    const float* p = reinterpret_cast<const float*>(image.images[c]);
    out[header.channels[c].name].assign(p, p + n);
  }
  FreeEXRImage(&image);
  FreeEXRHeader(&header);
  return out;
}

// The test flight (6 s, level, east, nose up 15 deg) at --step 3: frames at
// 0, 3 and 6 s, 32x18, 4 samples per pixel on both cores.
TEST(TruthReplay, WritesPathTracedFramesWithTheirSamplesAndStandardError) {
  const fs::path dir = outputDir();
  const RenderRun r = run({SKY_RENDER, "--headless", "--replay", SKY_TEST_FLIGHT, "--weather-file", SKY_SCENARIO_CLOUDY,
                     "--step", "3", "--width", "32", "--height", "18", "--no-video", "--truth", "path", "--spp", "4",
                     "--truth-threads", "2", "--out", (dir / "out").string()},
                    dir / "render.log");
  ASSERT_EQ(r.exitCode, 0) << r.log;
  EXPECT_NE(r.log.find("path-traced truth: 4 samples per pixel on 2 threads"), std::string::npos) << r.log;
  EXPECT_NE(r.log.find("truth: frame 1/3, rows 1/18"), std::string::npos) << "no row progress in\n" << r.log;
  EXPECT_NE(r.log.find("replay: frame 3/3 (100%)"), std::string::npos) << "no frame progress in\n" << r.log;

  const auto frames = frameLines(dir / "out");
  ASSERT_EQ(frames.size(), 3u);
  double cloudyError = 0;
  for (std::size_t i = 0; i < frames.size(); ++i) {
    const auto& f = frames[i];
    SCOPED_TRACE("frame " + std::to_string(i));
    EXPECT_NEAR(f["host_time_s"].get<double>(), 3.0 * double(i), 1e-9);
    EXPECT_EQ(f["preset"], "reference") << "the truth's view-ray air is the reference march";
    EXPECT_EQ(f["non_finite"], 0);
    EXPECT_GT(f["mean_luminance"].get<double>(), 0.0);
    EXPECT_EQ(f["camera_exposure"]["mode"], "auto");
    const auto& t = f["truth"];
    ASSERT_TRUE(t.is_object()) << f.dump();
    EXPECT_EQ(t["mode"], "path");
    EXPECT_EQ(t["samples_per_pixel"], 4);
    EXPECT_EQ(t["threads"], 2);
    EXPECT_EQ(t["seed"], i + 1);
    EXPECT_EQ(t["majorant_violations"], 0);
    EXPECT_GT(t["density_lookups"].get<double>(), 0.0) << "the cumulus layer was traced";
    const auto& e = t["standard_error"];
    EXPECT_GT(e["mean"].get<double>(), 0.0) << "4 samples through cloud are not all equal";
    EXPECT_GE(e["max"].get<double>(), e["mean"].get<double>());
    EXPECT_LT(e["image_mean"].get<double>(), e["mean"].get<double>()) << "the image mean is less noisy than a pixel";
    cloudyError += e["mean"].get<double>();

    // The EXR carries the same per-pixel standard errors.
    auto exr = readExr(dir / "out" / "frames" / f["exr"].get<std::string>());
    ASSERT_EQ(exr.count("truth.standard_error"), 1u);
    const auto& se = exr["truth.standard_error"];
    ASSERT_EQ(se.size(), 32u * 18u);
    double sum = 0, largest = 0;
    for (float v : se) {
      ASSERT_TRUE(std::isfinite(v) && v >= 0.0f) << v;
      sum += v;
      largest = std::max(largest, double(v));
    }
    EXPECT_NEAR(sum / double(se.size()), e["mean"].get<double>(), 1e-6 * e["mean"].get<double>());
    EXPECT_EQ(largest, e["max"].get<double>());
    EXPECT_TRUE(fs::exists(dir / "out" / "frames" / f["file"].get<std::string>()));
  }
  std::printf("cumulus truth at 4 spp: mean per-pixel standard error %.4f radiance units\n", cloudyError / 3.0);

  const auto report = nlohmann::json::parse(readAll(dir / "out" / "report.json"));
  EXPECT_EQ(report["complete"], true);
  EXPECT_EQ(report["frames"], 3);
  EXPECT_EQ(report["truth"]["mode"], "path");
  EXPECT_EQ(report["truth"]["samples_per_pixel"], 4);
  EXPECT_EQ(report["truth"]["threads"], 2);
  EXPECT_EQ(report["truth"]["majorant_violations"], 0);
  EXPECT_EQ(report["truth"]["exr_channel"], "truth.standard_error");
  EXPECT_EQ(report["device"], "CPU path tracer, 2 threads");
  EXPECT_EQ(report["preset"], "reference");
  EXPECT_EQ(report["camera_exposure"]["mode"], "auto");
}

// A clear sky, the first frame of the test flight at 48x27, 8 samples per
// pixel, sun fixed, EV100 fixed at 14. Where a pixel's ray leaves the air
// without meeting the ground the truth is the reference's own air march
// (path_tracer.cpp, ViewAir) and has no noise: it must equal the CPU
// reference to float rounding (measured: bit for bit, 960 pixels). Where
// it meets the ground, the truth traces the ground's light (Lambertian,
// albedo 0.1, lit by the sun and by the sky its paths find) and the
// reference models it: measured, the 336 ground pixels' mean 0.52052
// traced, 0.52084 modelled (ratio 0.9994), and no pixel further apart than
// 1.8 % of the reference past 4.5 of its standard errors.
constexpr double kSkyTolerance = 1e-5;     // relative: float rounding of the same double march
constexpr double kDeterministic = 1e-6;    // a standard error under this share of the pixel: no noise
constexpr double kGroundTolerance = 0.05;  // per pixel, relative, past 4.5 standard errors: 1.8 % measured
constexpr double kGroundMeanTolerance = 0.01;  // the ground's mean, relative, past 4.5 of its standard errors
TEST(TruthReplay, AClearSkyAgreesWithTheCpuReference) {
  constexpr std::uint32_t kW = 48, kH = 27;
  const fs::path dir = outputDir();
  const RenderRun r = run({SKY_RENDER, "--headless", "--replay", SKY_TEST_FLIGHT, "--weather-file", SKY_SCENARIO_CLEAR,
                     "--max-frames", "1", "--width", std::to_string(kW), "--height", std::to_string(kH), "--no-video",
                     "--fixed-sun", "--sun-azimuth", "200", "--sun-elevation", "35", "--ev100", "14", "--truth", "path",
                     "--spp", "8", "--out", (dir / "out").string()},
                    dir / "render.log");
  ASSERT_EQ(r.exitCode, 0) << r.log;
  const auto frames = frameLines(dir / "out");
  ASSERT_EQ(frames.size(), 1u);
  const auto& f = frames[0];
  EXPECT_EQ(f["camera_exposure"]["mode"], "fixed");
  EXPECT_EQ(f["camera_exposure"]["ev100"], 14.0);
  EXPECT_EQ(f["truth"]["samples_per_pixel"], 8);
  auto exr = readExr(dir / "out" / "frames" / f["exr"].get<std::string>());
  ASSERT_EQ(exr["R"].size(), std::size_t(kW) * kH);

  // The same frame through the CPU reference, from the metadata alone.
  auto preset = render::findPreset("reference");
  ASSERT_TRUE(preset.has_value());
  render::RenderSettings settings;
  settings.width = kW;
  settings.height = kH;
  settings.march = preset->march;
  auto reference = render::CpuReference::create(settings);
  ASSERT_TRUE(reference.has_value());
  render::FrameInputs in;
  in.camera.position = {f["lat_deg"].get<double>(), f["lon_deg"].get<double>(), f["alt_m"].get<double>()};
  in.camera.yaw_deg = f["yaw_deg"].get<double>();
  in.camera.pitch_deg = f["pitch_deg"].get<double>();
  in.camera.roll_deg = f["roll_deg"].get<double>();
  in.sunAzimuth_deg = f["sun_azimuth_deg"].get<double>();
  in.sunElevation_deg = f["sun_elevation_deg"].get<double>();
  in.weatherClock_s = f["weather_clock_s"].get<double>();
  auto image = reference->render(in);
  ASSERT_TRUE(image.has_value());

  const auto& se = exr["truth.standard_error"];
  std::size_t sky = 0, ground = 0, outside = 0;
  double worstSky = 0, worstGround = 0, groundTruth = 0, groundReference = 0, groundVariance = 0;
  for (std::size_t i = 0; i < std::size_t(kW) * kH; ++i) {
    const double truth = (exr["R"][i] + exr["G"][i] + exr["B"][i]) / 3.0;
    const double ref = (image->rgba[i * 4] + image->rgba[i * 4 + 1] + image->rgba[i * 4 + 2]) / 3.0;
    EXPECT_EQ(exr["cloud.transmittance"][i], 1.0f) << "no cloud in a clear sky";
    // A sky pixel's samples are all the same number: its standard error is
    // the rounding of sum of squares less square of sum, ~1e-8 of it.
    if (se[i] <= kDeterministic * truth) {
      ++sky;
      for (const char* c : {"R", "G", "B"}) {
        const int k = c[0] == 'R' ? 0 : c[0] == 'G' ? 1 : 2;
        const double a = exr[c][i], b = image->rgba[i * 4 + k];
        worstSky = std::max(worstSky, std::abs(a - b) / std::max(b, 1e-9));
        EXPECT_NEAR(a, b, kSkyTolerance * b) << "sky pixel " << i << " channel " << c;
      }
    } else {
      ++ground;
      groundTruth += truth;
      groundReference += ref;
      groundVariance += double(se[i]) * se[i];
      if (std::abs(truth - ref) > kGroundTolerance * ref + 4.5 * se[i]) ++outside;
      worstGround = std::max(worstGround, (std::abs(truth - ref) - 4.5 * se[i]) / ref);
    }
  }
  std::printf("clear sky: %zu sky pixels, largest relative difference %.2e; %zu ground pixels, mean truth %.5f, "
              "reference %.5f (ratio %.4f), largest difference past 4.5 standard errors %.2f %% of the reference; "
              "%zu outside %.0f %% + 4.5 standard errors\n",
              sky, worstSky, ground, ground ? groundTruth / ground : 0.0, ground ? groundReference / ground : 0.0,
              groundReference > 0 ? groundTruth / groundReference : 0.0, 100 * worstGround, outside,
              100 * kGroundTolerance);
  EXPECT_GT(sky, std::size_t(kW) * kH / 2) << "nose up 15 deg: most of the view is sky";
  EXPECT_GT(ground, 0u) << "the lower edge (15 deg below the horizon) is ground";
  EXPECT_EQ(outside, 0u);
  if (ground > 0) {
    EXPECT_NEAR(groundTruth / ground, groundReference / ground,
                kGroundMeanTolerance * groundReference / ground + 4.5 * std::sqrt(groundVariance) / ground);
  }
}

// Each refused before any frame is drawn (exit 2), with its reason.
TEST(TruthReplay, RefusesBadSampleCountsAndOptionsThatCannotApply) {
  const fs::path dir = outputDir();
  const std::vector<std::string> base = {SKY_RENDER, "--headless", "--replay", SKY_TEST_FLIGHT, "--weather-file",
                                         SKY_SCENARIO_CLEAR, "--width", "32", "--height", "18", "--no-video",
                                         "--out", (dir / "out").string()};
  const auto refused = [&](std::vector<std::string> extra, const std::string& says, bool withBase = true) {
    std::vector<std::string> argv = withBase ? base : std::vector<std::string>{SKY_RENDER, "--headless"};
    argv.insert(argv.end(), extra.begin(), extra.end());
    std::string name;
    for (const auto& e : extra) name += e;
    const RenderRun r = run(argv, dir / ("refused-" + std::to_string(std::hash<std::string>{}(name)) + ".log"));
    EXPECT_EQ(r.exitCode, 2) << name << "\n" << r.log;
    EXPECT_NE(r.log.find(says), std::string::npos) << name << ": expected '" << says << "' in\n" << r.log;
    EXPECT_FALSE(fs::exists(dir / "out" / "frames" / "frames.jsonl")) << name << ": refused after starting";
  };
  const std::string range = "the samples per pixel must be a whole number from 2 to 65536";
  for (const std::string spp : {"0", "1", "65537", "-4", "abc", "4x", "1e3", "18446744073709551617"})
    refused({"--truth", "path", "--spp", spp}, "--spp '" + spp + "': " + range);
  refused({"--truth", "path", "--spp", ""}, "--spp '': " + range);  // given, though empty
  refused({"--truth", "gpu"}, "--truth 'gpu': the only ground truth is 'path'");
  refused({"--spp", "16"}, "--spp and --truth-threads go with --truth path");
  refused({"--truth", "path", "--window"}, "cannot show its frames in a --window");
  refused({"--truth", "path", "--frame-budget-ms", "30"}, "--frame-budget-ms does not apply to --truth path");
  refused({"--truth", "path", "--preset", "medium"}, "--preset does not apply to --truth path");
  refused({"--truth", "path", "--truth-threads", "5000"}, "--truth-threads 5000: at most 1024");
  refused({"--truth", "path", "--out", (dir / "out").string()}, "--truth path draws the frames of a --replay flight",
          false);
}

}  // namespace
}  // namespace sky::test
