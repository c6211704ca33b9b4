// The frame budget's real-time claim, measured (renderer/core/src/frame_budget.cpp):
// over a replayed camera path, a budget set halfway between two levels'
// measured times holds the frames within 20 % of it, at the most accurate
// level that fits. Not a timed test: ctest runs it briefly (label bench) and
// checks nothing of its numbers; which level the controller picks for given
// frame times is tested in tests/unit/renderer and tests/gpu (frame_budget_test.cpp).
// The numbers come from running it by hand on a Release build:
//   LP_NUM_THREADS=1 build/release/tests/bench/sky_frame_budget_bench --width 320 --height 180
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <map>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include "sky/render/cloud_renderer.hpp"
#include "sky/render/frame_budget.hpp"
#include "sky/render/presets.hpp"

namespace {

using Clock = std::chrono::steady_clock;

struct Options {
  std::uint32_t width = 320, height = 180;
  int rounds = 9;   // calibration rounds over every level; the first is not counted
  int frames = 40;  // frames under the budget
  int settle = 10;  // of which the first are not counted
  std::string preset = "high";
  std::string json;
};

// The frames' claim: each within this fraction of the budget (above or below).
constexpr double kHoldFraction = 0.2;
// After each budgeted frame a probe frame is drawn by a second renderer
// with high's march at every pixel (no history, so its cost does not depend
// on the budget's frames): its times against its times during the
// calibration say how fast the machine ran while the budget did (it is
// shared, and its speed drifts by a third within a minute).

double median(std::vector<double> v) {
  if (v.empty()) return 0;
  std::sort(v.begin(), v.end());
  return v[v.size() / 2];
}

// The replayed path: east at 800 m under half-covered cumulus (base 1500 m,
// 1000 m thick), turning 3 degrees a frame, looking 12 degrees up.
sky::render::FrameInputs pathFrame(const sky::weather::WeatherSnapshot& snap, std::uint64_t i) {
  sky::render::FrameInputs in;
  in.camera.position = {46.0, 13.0 + 2e-4 * double(i), 800};
  in.camera.yaw_deg = 30 + 3.0 * double(i);
  in.camera.pitch_deg = 12;
  in.weather = &snap;
  in.weatherClock_s = double(i) / 30.0;
  in.frameIndex = i;
  return in;
}

// The frame's wall time, ms; a negative value when it failed (said on stderr).
double timedFrame(sky::render::CloudRenderer& r, const sky::render::FrameInputs& in) {
  const auto t0 = Clock::now();
  auto image = r.render(in);
  const double ms = std::chrono::duration<double, std::milli>(Clock::now() - t0).count();
  if (!image) {
    std::fprintf(stderr, "sky_frame_budget_bench: %s\n", sky::describe(image.error()).c_str());
    return -1;
  }
  return ms;
}

sky::Result<void> setLevel(sky::render::CloudRenderer& r, const sky::render::BudgetLevel& level) {
  return r.setLevel(level.march, level.temporal, level.resolution);
}

// The most accurate level whose time fits the budget, else the cheapest.
std::size_t bestFitting(const std::vector<double>& levelMs, double budgetMs) {
  for (std::size_t level = 0; level < levelMs.size(); ++level)
    if (levelMs[level] <= budgetMs) return level;
  return levelMs.size() - 1;
}

}  // namespace

int main(int argc, char** argv) {
  Options o;
  CLI::App app{"sky_frame_budget_bench: the frame budget's frame times against the budget over a replayed path"};
  app.add_option("--width", o.width, "frame width, pixels")->capture_default_str();
  app.add_option("--height", o.height, "frame height, pixels")->capture_default_str();
  app.add_option("--rounds", o.rounds, "calibration rounds over every level (the first is not counted)")
      ->check(CLI::Range(2, 1000))
      ->capture_default_str();
  app.add_option("--frames", o.frames, "frames under the budget")->check(CLI::Range(1, 100000))->capture_default_str();
  app.add_option("--settle", o.settle, "of which the first are not counted")
      ->check(CLI::Range(0, 100000))
      ->capture_default_str();
  app.add_option("--preset", o.preset, "its ladder (sky/render/frame_budget.hpp)")->capture_default_str();
  app.add_option("--json", o.json, "also write the numbers to this file");
  CLI11_PARSE(app, argc, argv);
  o.settle = std::min(o.settle, o.frames - 1);
  // Before the driver loads: compiled shaders are not taken from earlier runs.
  setenv("MESA_SHADER_CACHE_DISABLE", "true", 0);
  const auto preset = sky::render::findPreset(o.preset);
  if (!preset) {
    std::fprintf(stderr, "sky_frame_budget_bench: --preset: %s\n", sky::describe(preset.error()).c_str());
    return 2;
  }
  auto ladder = sky::render::budgetLadder(*preset);
  if (!ladder) {
    std::fprintf(stderr, "sky_frame_budget_bench: %s\n", sky::describe(ladder.error()).c_str());
    return 2;
  }
  sky::render::RenderSettings settings;
  settings.width = o.width;
  settings.height = o.height;
  settings.march = preset->march;
  settings.temporal = preset->temporal;
  settings.resolution = preset->resolution;
  auto renderer = sky::render::CloudRenderer::create(settings);
  if (!renderer) {
    std::fprintf(stderr, "sky_frame_budget_bench: %s\n", sky::describe(renderer.error()).c_str());
    return renderer.error().code == sky::ErrorCode::NoDevice ? 77 : 1;
  }
  sky::render::CloudRenderer& r = **renderer;
  sky::render::RenderSettings probeSettings;
  probeSettings.width = o.width;
  probeSettings.height = o.height;
  auto probeRenderer = sky::render::CloudRenderer::create(probeSettings);
  if (!probeRenderer) {
    std::fprintf(stderr, "sky_frame_budget_bench: %s\n", sky::describe(probeRenderer.error()).c_str());
    return 1;
  }
  sky::render::CloudRenderer& probeR = **probeRenderer;
  sky::weather::WeatherSnapshot snap;
  sky::weather::CloudLayer layer;
  layer.id = 1;
  layer.type = sky::weather::CloudType::Cumulus;
  layer.base_m = 1500;
  layer.thickness_m = 1000;
  layer.coverage = 0.5;
  layer.density = 1;
  snap.layers.push_back(layer);
  const char* threads = std::getenv("LP_NUM_THREADS");
  std::printf("sky_frame_budget_bench: %s at %ux%u on '%s', LP_NUM_THREADS=%s\n", o.preset.c_str(), o.width,
              o.height, r.deviceName().c_str(), threads ? threads : "(unset)");

  // Each level's frame time over the rounds, round-robin (the first round
  // also builds what each level needs and is not counted), so the machine's
  // drift falls on all levels alike: the median per level, and the fastest
  // (the machine's other load only adds time, so the fastest frames give the
  // levels' own relative costs best). After each change of level a frame is
  // drawn untimed: the first frame of a level carries the last one's
  // history over (a copy, or a box filter to a smaller size) and builds
  // what the level had not built yet.
  const std::size_t levels = ladder->size();
  std::vector<std::vector<double>> calibration(levels);
  std::vector<double> probesCalibrated;
  for (int round = 0; round < o.rounds; ++round) {
    const double probe = timedFrame(probeR, pathFrame(snap, std::uint64_t(2 * round)));
    if (probe < 0) return 1;
    if (round > 0) probesCalibrated.push_back(probe);
    for (std::size_t level = 0; level < levels; ++level) {
      if (auto set = setLevel(r, (*ladder)[level]); !set) {
        std::fprintf(stderr, "sky_frame_budget_bench: %s\n", sky::describe(set.error()).c_str());
        return 1;
      }
      if (timedFrame(r, pathFrame(snap, std::uint64_t(2 * round))) < 0) return 1;
      const double ms = timedFrame(r, pathFrame(snap, std::uint64_t(2 * round + 1)));
      if (ms < 0) return 1;
      if (round > 0) calibration[level].push_back(ms);
    }
  }
  std::vector<double> levelMs, fastestMs;
  for (const auto& ms : calibration) {
    levelMs.push_back(median(ms));
    fastestMs.push_back(*std::min_element(ms.begin(), ms.end()));
  }
  std::printf("%-26s %9s %9s %14s %14s\n", "level", "p50 ms", "min ms", "cost (min)", "cost (ladder)");
  for (std::size_t level = 0; level < levels; ++level)
    std::printf("%-26s %9.2f %9.2f %14.3f %14.3f\n", (*ladder)[level].name.c_str(), levelMs[level], fastestMs[level],
                fastestMs[level] / fastestMs[0], (*ladder)[level].relativeCost);

  // The budget halfway between levels 1 and 3 (on a short ladder: between
  // the first and the last), so one level in between fits.
  const std::size_t below = levels > 3 ? 1 : 0, above = levels > 3 ? 3 : levels - 1;
  const double budgetMs = 0.5 * (levelMs[below] + levelMs[above]);
  std::printf("budget %.2f ms (halfway between levels %zu and %zu), level %zu fits at the calibration's speed\n",
              budgetMs, below, above, bestFitting(levelMs, budgetMs));

  sky::render::FrameBudget budget(budgetMs, *ladder);
  std::vector<double> held, probes;
  std::map<std::size_t, int> framesPerLevel;
  nlohmann::json perFrame = nlohmann::json::array();
  std::printf("%5s %5s %9s %9s %7s %9s\n", "frame", "level", "ms", "budget", "ratio", "probe ms");
  for (int i = 0; i < o.frames; ++i) {
    const std::size_t drawnAt = budget.level();
    if (auto set = setLevel(r, budget.current()); !set) {
      std::fprintf(stderr, "sky_frame_budget_bench: %s\n", sky::describe(set.error()).c_str());
      return 1;
    }
    const double ms = timedFrame(r, pathFrame(snap, std::uint64_t(i)));
    if (ms < 0) return 1;
    budget.update(ms, sky::render::timesLevel(budget.current(), r.lastTemporal()));
    const double probe = timedFrame(probeR, pathFrame(snap, std::uint64_t(i)));
    if (probe < 0) return 1;
    std::printf("%5d %5zu %9.2f %9.2f %7.3f %9.2f%s\n", i, drawnAt, ms, budgetMs, ms / budgetMs, probe,
                i < o.settle ? "  (settling)" : "");
    perFrame.push_back({{"frame", i}, {"level", drawnAt}, {"ms", ms}, {"ratio", ms / budgetMs}, {"probe_ms", probe}});
    if (i < o.settle) continue;
    held.push_back(ms);
    probes.push_back(probe);
    ++framesPerLevel[drawnAt];
  }

  // The machine's speed while the budget ran: the probes' median over
  // their median during the calibration.
  const double speed = median(probes) / median(probesCalibrated);
  std::vector<double> duringMs;
  for (double ms : levelMs) duringMs.push_back(ms * speed);
  const std::size_t fits = bestFitting(duringMs, budgetMs);
  const auto most = std::max_element(framesPerLevel.begin(), framesPerLevel.end(),
                                     [](const auto& a, const auto& b) { return a.second < b.second; });
  const std::size_t within = std::size_t(std::count_if(held.begin(), held.end(), [&](double ms) {
    return std::abs(ms / budgetMs - 1) <= kHoldFraction;
  }));
  std::vector<double> ratios;
  for (double ms : held) ratios.push_back(ms / budgetMs);
  std::sort(ratios.begin(), ratios.end());
  const double heldMs = median(held);
  std::printf("held: median %.2f ms against the budget's %.2f ms (ratio %.3f; min %.3f, max %.3f); %zu of %zu frames "
              "within %.0f %% of the budget\n",
              heldMs, budgetMs, heldMs / budgetMs, ratios.front(), ratios.back(), within, held.size(),
              100 * kHoldFraction);
  std::printf("level %zu drawn in %d of %zu frames; the machine ran at %.2fx the calibration's times, where level %zu "
              "fits (the cheapest takes %.2f ms then)\n",
              most->first, most->second, held.size(), speed, fits, duringMs.back());
  if (!o.json.empty()) {
    nlohmann::json levelsJson = nlohmann::json::array();
    for (std::size_t level = 0; level < levels; ++level)
      levelsJson.push_back({{"name", (*ladder)[level].name},
                            {"p50_ms", levelMs[level]},
                            {"min_ms", fastestMs[level]},
                            {"relative_cost_measured", fastestMs[level] / fastestMs[0]},
                            {"relative_cost_ladder", (*ladder)[level].relativeCost}});
    const nlohmann::json report = {{"preset", o.preset},
                                   {"width", o.width},
                                   {"height", o.height},
                                   {"device", r.deviceName()},
                                   {"lp_num_threads", threads ? threads : ""},
                                   {"levels", levelsJson},
                                   {"budget_ms", budgetMs},
                                   {"frames", perFrame},
                                   {"held_p50_ms", heldMs},
                                   {"held_p50_ratio", heldMs / budgetMs},
                                   {"hold_fraction", kHoldFraction},
                                   {"frames_within_hold", within},
                                   {"frames_counted", held.size()},
                                   {"machine_speed", speed},
                                   {"level_that_fits", fits}};
    std::ofstream(o.json) << report.dump(2) << '\n';
  }
  return 0;
}
