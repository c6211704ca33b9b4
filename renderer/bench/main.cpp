// skyshell-bench: measures what each render configuration costs and how far
// its image is from `reference` over a suite of scenes (deploy/bench/suite.toml),
// and writes results.json, results.md, plots and contact sheets; or, with
// --side-by-side, times one view frame by frame for comparison with another
// renderer on the same machine. docs/performance.md, "Speed against accuracy".
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <filesystem>
#include <sstream>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

#include "sky/bench/configurations.hpp"
#include "sky/bench/report.hpp"
#include "sky/bench/runner.hpp"
#include "sky/bench/side_by_side.hpp"
#include "sky/bench/suite_loader.hpp"

namespace {

// Exit status when no Vulkan device exists (ctest's SKIP_RETURN_CODE).
constexpr int kExitUnsupported = 77;
// Smallest output edge: SSIM needs its 11x11 window, and quarter-res still a few pixels.
constexpr std::uint32_t kMinEdge = 16;
// --quick: tiny frames, one still and one path, one timed repeat (the ctest smoke run).
constexpr std::uint32_t kQuickWidth = 48, kQuickHeight = 27;
const std::vector<std::string> kQuickScenes{"cumulus-midday", "fast-turn"};

std::vector<std::string> splitList(const std::string& text) {
  std::vector<std::string> out;
  std::stringstream in(text);
  for (std::string item; std::getline(in, item, ',');)
    if (!item.empty()) out.push_back(item);
  return out;
}

bool parseResolution(const std::string& text, sky::bench::Resolution& out) {
  unsigned w = 0, h = 0;
  char x = 0, extra = 0;
  if (std::sscanf(text.c_str(), "%u%c%u%c", &w, &x, &h, &extra) != 3 || (x != 'x' && x != 'X')) return false;
  out = {w, h};
  return w >= kMinEdge && h >= kMinEdge && w <= 8192 && h <= 8192;
}

std::string defaultOutDir() {
  const std::time_t now = std::time(nullptr);
  char buf[32];
  std::strftime(buf, sizeof buf, "%Y%m%d-%H%M%S", std::gmtime(&now));
  return std::string("bench-output/") + buf;
}

int reportError(const sky::Error& e) {
  std::fprintf(stderr, "skyshell-bench: %s\n", sky::describe(e).c_str());
  return e.code == sky::ErrorCode::NoDevice ? kExitUnsupported : 1;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"skyshell-bench: cost and error of render configurations against reference"};
  std::string suite = SKY_BENCH_DEFAULT_SUITE;
  std::string scenes, configs = "all", outDir, referenceKeys;
  std::vector<std::string> resolutions;
  unsigned warmup = 2, repeats = 5, pathRepeats = 1;
  bool quick = false, noPlots = false, list = false, sideBySide = false;
  sky::bench::SideBySideOptions sbs;
  sbs.weatherFile = SKY_BENCH_DEFAULT_WEATHER;
  std::string sun = "-0.5,0.5,1", config = sky::bench::kReferenceName, weatherFile = sbs.weatherFile.string();
  unsigned width = 0, height = 0;
  std::string truthKind;
  unsigned truthSpp = 64, truthEvents = 0, truthThreads = 0;
  std::vector<double> truthOctaves;
  std::vector<std::string> truthModels;
  bool truthNoParts = false;

  app.add_option("--suite", suite, "scene suite file (TOML)")->capture_default_str();
  app.add_option("--scenes", scenes, "comma-separated scene names (default: every scene of the suite)");
  app.add_option("--reference", referenceKeys,
                 "the ground truth's settings as key=value,... (the custom keys; default: the reference preset), "
                 "e.g. base=reference,light=64");
  app.add_option("--configs", configs, "comma-separated configurations, or all; reference is always run; NAME:key=value,... adds a custom one (then separate the list with ;)")
      ->capture_default_str();
  app.add_option("--resolution", resolutions, "output size WxH; repeat for several (default 320x180)");
  app.add_option("--width", width, "output width (with --height: one resolution; side-by-side default 640)");
  app.add_option("--height", height, "output height (side-by-side default 360)");
  app.add_option("--warmup", warmup, "untimed frames before each case")->capture_default_str();
  bool noHistoryWarmup = false;
  app.add_flag("--no-history-warmup", noHistoryWarmup,
               "do not fill a temporal configuration's history before timing (checks only: stills then show an "
               "unconverged image)");
  app.add_option("--repeats", repeats, "timed renders of each still")->capture_default_str();
  app.add_option("--path-repeats", pathRepeats, "timed runs of each camera path")->capture_default_str();
  app.add_option("--out", outDir, "output folder (default bench-output/<UTC date-time>)");
  app.add_flag("--quick", quick, "48x27, two scenes (a still and a path), 1 warm-up (no history fill), 1 repeat: checks the bench works");
  app.add_flag("--no-plots", noPlots, "skip the gnuplot plots");
  app.add_option("--truth", truthKind,
                 "path: also measure each still against its path-traced frame (slow; resumes from OUT/truth/)")
      ->check(CLI::IsMember({"path"}));
  app.add_option("--truth-spp", truthSpp, "--truth path: samples per pixel (passes of 1, 4, 16, ...)")
      ->capture_default_str()
      ->check(CLI::Range(1u, 65536u));
  app.add_option("--truth-events", truthEvents,
                 "--truth path: scattering events a path may have (0: any; 1: single scattering)")
      ->capture_default_str();
  app.add_option("--truth-threads", truthThreads, "--truth path: threads (0: every CPU)")->capture_default_str();
  app.add_option("--truth-octaves", truthOctaves,
                 "--truth path: octave weights b to measure besides the model's, comma-separated (e.g. 0.25,0.35)")
      ->delimiter(',')
      ->check(CLI::Range(0.0, 1.0));
  app.add_option("--truth-model", truthModels,
                 "--truth path: another model to measure, b=<octave weight 0-1>:a=<octave extinction (0,1]>:"
                 "c=<octave eccentricity 0-1>:sd=<scattered sun's diffuse gain 0-2> (any of them; repeat the "
                 "option for more)");
  app.add_flag("--truth-no-parts", truthNoParts,
               "--truth path: skip the model's parts switched off one at a time (measure the model and the "
               "--truth-model/--truth-octaves variants only)");
  app.add_flag("--list", list, "list the suite's scenes and the configurations, then exit");
  app.add_flag("--side-by-side", sideBySide, "time one view: one CLOUDPASS line per frame on stdout");
  app.add_option("--height-above-ground", sbs.heightAboveGround_m, "side-by-side: camera height, m")
      ->capture_default_str();
  app.add_option("--pitch", sbs.pitch_deg, "side-by-side: camera pitch, deg")->capture_default_str();
  app.add_option("--yaw", sbs.yaw_deg, "side-by-side: camera heading, deg")->capture_default_str();
  app.add_option("--turn", sbs.turn_deg, "side-by-side: heading added per frame, deg (a turning camera)")
      ->capture_default_str();
  app.add_option("--vfov", sbs.verticalFov_deg, "side-by-side: vertical field of view, deg")->capture_default_str();
  app.add_option("--sun", sun, "side-by-side: direction to the sun east,north,up")->capture_default_str();
  app.add_option("--lat", sbs.lat_deg, "side-by-side: camera latitude, deg")->capture_default_str();
  app.add_option("--lon", sbs.lon_deg, "side-by-side: camera longitude, deg")->capture_default_str();
  app.add_option("--frames", sbs.frames, "side-by-side: timed frames")->capture_default_str();
  app.add_option("--weather", weatherFile, "side-by-side: weather (scenario file)")->capture_default_str();
  app.add_option("--config", config, "side-by-side: configuration")->capture_default_str();
  CLI11_PARSE(app, argc, argv);

  // Benchmarks pin lavapipe to two worker threads (lavapipe.md, "Threads").
  if (std::getenv("LP_NUM_THREADS") == nullptr) setenv("LP_NUM_THREADS", "2", 1);

  if ((width == 0) != (height == 0)) {
    std::fprintf(stderr, "skyshell-bench: --width and --height go together\n");
    return 2;
  }
  if (width != 0 && (width < kMinEdge || height < kMinEdge || width > 8192 || height > 8192)) {
    std::fprintf(stderr, "skyshell-bench: --width/--height %ux%u outside [%u, 8192]\n", width, height, kMinEdge);
    return 2;
  }

  if (sideBySide) {
    auto chosen = sky::bench::selectConfigurations(config);
    if (!chosen) return reportError(chosen.error());
    sbs.configuration = chosen->back();
    if (width != 0) sbs.width = width, sbs.height = height;
    sbs.weatherFile = weatherFile;
    const auto parts = splitList(sun);
    char* end = nullptr;
    if (parts.size() != 3) {
      std::fprintf(stderr, "skyshell-bench: --sun wants three numbers east,north,up (got '%s')\n", sun.c_str());
      return 2;
    }
    double* fields[3] = {&sbs.sunEast, &sbs.sunNorth, &sbs.sunUp};
    for (int i = 0; i < 3; ++i) {
      *fields[i] = std::strtod(parts[std::size_t(i)].c_str(), &end);
      if (end == parts[std::size_t(i)].c_str() || *end != '\0') {
        std::fprintf(stderr, "skyshell-bench: --sun: '%s' is not a number\n", parts[std::size_t(i)].c_str());
        return 2;
      }
    }
    if (auto ok = sky::bench::runSideBySide(sbs, stdout, stderr); !ok) return reportError(ok.error());
    return 0;
  }

  sky::bench::RunOptions options;
  options.warmup = warmup;
  options.repeats = repeats;
  options.pathRepeats = pathRepeats;
  options.historyWarmup = !noHistoryWarmup;
  std::vector<std::string> sceneNames = splitList(scenes);
  if (quick) {
    options.resolutions = {{kQuickWidth, kQuickHeight}};
    options.warmup = 1;
    options.repeats = 1;
    options.pathRepeats = 1;
    options.historyWarmup = false;
    if (sceneNames.empty()) sceneNames = kQuickScenes;
  }
  if (!resolutions.empty()) {
    options.resolutions.clear();
    for (const std::string& r : resolutions) {
      sky::bench::Resolution res;
      if (!parseResolution(r, res)) {
        std::fprintf(stderr, "skyshell-bench: --resolution '%s' is not WxH with edges in [%u, 8192]\n", r.c_str(),
                     kMinEdge);
        return 2;
      }
      options.resolutions.push_back(res);
    }
  } else if (width != 0) {
    options.resolutions = {{width, height}};
  }
  auto chosen = sky::bench::selectConfigurations(configs);
  if (!chosen) return reportError(chosen.error());
  if (!referenceKeys.empty()) {
    auto truth = sky::bench::referenceConfiguration(referenceKeys);
    if (!truth) return reportError(truth.error());
    chosen->front() = *truth;
  }
  options.configurations = *chosen;
  auto loaded = sky::bench::loadSuite(suite, list ? std::vector<std::string>{} : sceneNames);
  if (!loaded) return reportError(loaded.error());
  if (list) {
    for (const auto& s : *loaded)
      std::printf("scene %-22s %s%s\n", s.scene.name.c_str(), s.scene.isPath() ? "(path) " : "",
                  s.scene.description.c_str());
    for (const auto& c : sky::bench::builtInConfigurations())
      std::printf("configuration %-14s %s\n", c.name.c_str(), c.description.c_str());
    return 0;
  }

  options.outDir = outDir.empty() ? defaultOutDir() : outDir;
  if (truthKind == "path") {
    options.truth.samplesPerPixel = truthSpp;
    options.truth.maxEvents = truthEvents;
    options.truth.threads = truthThreads;
    options.truth.octaveWeights = truthOctaves;
    options.truth.parts = !truthNoParts;
    for (const std::string& spec : truthModels) {
      auto model = sky::bench::parseModelSpec(spec);
      if (!model) {
        std::fprintf(stderr, "skyshell-bench: --truth-model: %s\n", model.error().detail.c_str());
        return 2;
      }
      options.truth.models.emplace_back(spec, *model);
    }
  }
  std::error_code ec;
  std::filesystem::create_directories(options.outDir, ec);
  if (ec) {
    std::fprintf(stderr, "skyshell-bench: %s: %s\n", options.outDir.c_str(), ec.message().c_str());
    return 1;
  }
  if (outDir.empty()) {  // bench-output/latest -> the newest run, as deploy/demo does
    const auto latest = options.outDir.parent_path() / "latest";
    std::filesystem::remove(latest, ec);
    std::filesystem::create_directory_symlink(options.outDir.filename(), latest, ec);
  }
  options.log = [](const std::string& line) { std::fprintf(stderr, "skyshell-bench: %s\n", line.c_str()); };

  auto report = sky::bench::runBench(*loaded, options);
  if (!report) return reportError(report.error());
  if (auto ok = sky::bench::writeReport(*report, options.outDir); !ok) return reportError(ok.error());
  if (!noPlots) {
    auto plots = sky::bench::writePlots(*report, options.outDir);
    if (!plots && plots.error().code == sky::ErrorCode::Unsupported)
      std::fprintf(stderr, "skyshell-bench: no plots: %s (scripts are in %s/plots)\n", plots.error().detail.c_str(),
                   options.outDir.c_str());
    else if (!plots)
      return reportError(plots.error());
  }
  std::fprintf(stderr, "skyshell-bench: wrote %s/results.md, results.json, contact/, plots/\n", options.outDir.c_str());
  return 0;
}
