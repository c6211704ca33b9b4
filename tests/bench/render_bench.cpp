// Renderer benchmark: GPU time per pass (Vulkan timestamps) on fixed views,
// with the frame's wall time, the process's CPU time and the busiest
// thread's CPU time (lavapipe runs the GPU work on CPU threads; wall time
// doubles when another process takes a core, CPU time does not:
// reference/lavapipe.md). Not a timed test (ctest runs it briefly, label
// bench); the numbers come from running it by hand on a Release build:
//   LP_NUM_THREADS=2 build/release/tests/bench/sky_render_bench --width 320 --height 180 --frames 30
// Views: the peer comparison's (camera 800 m above the ground, vertical field
// of view 60 degrees, pitch 0 and 30, sun towards (-0.5, 0.5, 1) in east,
// north, up) under the bundled cumulus layer (base 1500 m, 1500 m thick,
// coverage 0.6), the same layer seen from 4000 m looking 30 degrees down, and
// a climb at 5 m/s through the first view (the camera moves every frame, as
// in a flight: a driver that specialises the shader on the frame's values
// recompiles it then; lavapipe did, 0.4-0.6 s per frame, until the frame
// block became a storage buffer). Mesa's disk shader cache is off, so the
// numbers do not depend on what this machine rendered before.
#include <dirent.h>
#include <time.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "sky/render/cloud_renderer.hpp"
#include "sky/render/cpu_reference.hpp"
#include "sky/render/presets.hpp"

namespace {

using Clock = std::chrono::steady_clock;

struct Options {
  std::uint32_t width = 320, height = 180;
  int frames = 30, warmup = 3;
  bool lookups = false;  // also count the cloud model's lookups (CPU reference) per view
  std::string json;
  std::string preset = "high";  // its march and interleave (sky/render/presets.hpp)
  std::uint32_t divisor = 0;    // the resolution divisor; 0: the preset's
};

struct View {
  const char* name;
  double alt_m, pitch_deg;
  double climb_mps = 0;  // altitude change per second of frames at 30 frames/s
};

double processCpu_ms() {
  timespec t{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
  return double(t.tv_sec) * 1e3 + double(t.tv_nsec) * 1e-6;
}

// CPU time of each thread of this process so far, ns (schedstat's first field).
std::map<std::string, double> threadCpu_ns() {
  std::map<std::string, double> out;
  DIR* dir = opendir("/proc/self/task");
  if (!dir) return out;
  while (dirent* e = readdir(dir)) {
    if (e->d_name[0] == '.') continue;
    std::ifstream f(std::string("/proc/self/task/") + e->d_name + "/schedstat");
    double ns = 0;
    if (f >> ns) out[e->d_name] = ns;
  }
  closedir(dir);
  return out;
}

double busiestDelta_ms(const std::map<std::string, double>& before, const std::map<std::string, double>& after) {
  double best = 0;
  for (const auto& [tid, ns] : after) {
    const auto it = before.find(tid);
    best = std::max(best, (ns - (it == before.end() ? 0.0 : it->second)) * 1e-6);
  }
  return best;
}

double rank(std::vector<double> v, double q) {
  if (v.empty()) return 0;
  std::sort(v.begin(), v.end());
  const auto k = static_cast<std::size_t>(std::ceil(q * double(v.size())));
  return v[std::clamp<std::size_t>(k, 1, v.size()) - 1];
}

}  // namespace

int main(int argc, char** argv) {
  Options o;
  for (int i = 1; i + 1 < argc; i += 2) {
    const std::string k = argv[i], v = argv[i + 1];
    if (k == "--width") o.width = std::uint32_t(std::stoul(v));
    else if (k == "--height") o.height = std::uint32_t(std::stoul(v));
    else if (k == "--frames") o.frames = std::stoi(v);
    else if (k == "--warmup") o.warmup = std::stoi(v);
    else if (k == "--json") o.json = v;
    else if (k == "--preset") o.preset = v;
    else if (k == "--lookups") o.lookups = v != "0";
    else if (k == "--divisor") o.divisor = std::uint32_t(std::stoul(v));
    else {
      std::fprintf(stderr,
                   "usage: sky_render_bench [--width W] [--height H] [--frames N] [--warmup N] [--lookups 0|1] "
                   "[--preset NAME] [--divisor 1|2|4] [--json FILE]\n");
      return 2;
    }
  }
  // Before the driver loads: compiled shaders are not taken from earlier runs.
  setenv("MESA_SHADER_CACHE_DISABLE", "true", 0);
  sky::render::RenderSettings settings;
  settings.width = o.width;
  settings.height = o.height;
  const auto preset = sky::render::findPreset(o.preset);
  if (!preset) {
    std::fprintf(stderr, "sky_render_bench: --preset: %s\n", sky::describe(preset.error()).c_str());
    return 2;
  }
  settings.march = preset->march;
  settings.temporal = preset->temporal;
  settings.resolution = preset->resolution;
  if (o.divisor != 0) settings.resolution.divisor = o.divisor;
  // An interleaved preset is timed with its history full.
  o.warmup = std::max(o.warmup, int(sky::render::historyWarmupFrames(settings.temporal)));
  auto renderer = sky::render::CloudRenderer::create(settings);
  if (!renderer) {
    std::fprintf(stderr, "sky_render_bench: %s\n", sky::describe(renderer.error()).c_str());
    return renderer.error().code == sky::ErrorCode::NoDevice ? 77 : 1;
  }
  sky::weather::WeatherSnapshot weather;
  sky::weather::CloudLayer layer;
  layer.id = 1;
  layer.type = sky::weather::CloudType::Cumulus;
  layer.base_m = 1500;
  layer.thickness_m = 1500;
  layer.transitionBand_m = 100;
  layer.coverage = 0.6;
  layer.density = 1;
  layer.wind = {10.0, 270.0, 0.0};
  weather.layers.push_back(layer);
  // Sun towards (-0.5, 0.5, 1): azimuth atan2(-0.5, 0.5) = 315 deg, elevation asin(1 / sqrt(1.5)) = 54.7 deg.
  const double sunAzimuth_deg = 315.0, sunElevation_deg = std::asin(1.0 / std::sqrt(1.5)) * 180.0 / 3.14159265358979;
  const char* threads = std::getenv("LP_NUM_THREADS");
  std::printf("sky_render_bench: %ux%u on '%s', LP_NUM_THREADS=%s, %d frames per view after %d warm-up\n", o.width,
              o.height, (*renderer)->deviceName().c_str(), threads ? threads : "(unset)", o.frames, o.warmup);
  // The cloud model's texture lookups of a frame are counted by the CPU
  // reference, which runs the same core with the same march (in double: an
  // early exit may fall a sample apart); divided by the GPU pass's time they
  // are the pass's effective lookup rate, to set against sky_lookup_bench's
  // limit (one 3D lookup per step and nothing else).
  std::optional<sky::render::CpuReference> reference;
  if (o.lookups) {
    auto created = sky::render::CpuReference::create(settings);
    if (!created) {
      std::fprintf(stderr, "sky_render_bench: %s\n", sky::describe(created.error()).c_str());
      return 1;
    }
    reference.emplace(std::move(*created));
  }
  std::printf("%-14s %9s %9s %9s %9s %9s %11s%s\n", "view", "gpu p50", "gpu p90", "wall p50", "cpu p50", "busiest",
              "ns/pixel", o.lookups ? "   lookups  M/s (gpu)  M/cpu-s" : "");
  nlohmann::json report = {{"width", o.width}, {"height", o.height}, {"device", (*renderer)->deviceName()},
                           {"lp_num_threads", threads ? threads : ""}, {"views", nlohmann::json::object()}};
  const View views[] = {{"peer_pitch0", 800, 0}, {"peer_pitch30", 800, 30}, {"above_down30", 4000, -30},
                        {"climb_pitch0", 800, 0, 5.0}};
  for (const View& v : views) {
    std::map<std::string, std::vector<double>> gpu;
    std::vector<double> wall, cpu, busiest;
    sky::render::FrameInputs last;
    for (int f = 0; f < o.warmup + o.frames; ++f) {
      sky::render::FrameInputs in;
      in.camera.position = {46.2, 12.8, v.alt_m + v.climb_mps * f / 30.0};
      in.camera.yaw_deg = 0;
      in.camera.pitch_deg = v.pitch_deg;
      in.weather = &weather;
      in.weatherClock_s = f / 30.0;  // the clouds move as at 30 frames/s
      in.sunAzimuth_deg = sunAzimuth_deg;
      in.sunElevation_deg = sunElevation_deg;
      in.frameIndex = std::uint64_t(f);
      last = in;
      const auto threads0 = threadCpu_ns();
      const double cpu0 = processCpu_ms();
      const auto t0 = Clock::now();
      auto image = (*renderer)->render(in);
      const double wall_ms = std::chrono::duration<double, std::milli>(Clock::now() - t0).count();
      if (!image) {
        std::fprintf(stderr, "sky_render_bench: %s\n", sky::describe(image.error()).c_str());
        return 1;
      }
      if (f < o.warmup) continue;  // the first dispatch compiles the pipeline (lavapipe.md)
      wall.push_back(wall_ms);
      cpu.push_back(processCpu_ms() - cpu0);
      busiest.push_back(busiestDelta_ms(threads0, threadCpu_ns()));
      for (const auto& p : (*renderer)->lastPassTimes()) gpu[p.pass].push_back(p.gpu_ms);
    }
    const double clouds50 = rank(gpu["clouds"], 0.5);
    std::printf("%-14s %7.1f ms %7.1f ms %7.1f ms %7.1f ms %7.1f ms %11.0f", v.name, clouds50,
                rank(gpu["clouds"], 0.9), rank(wall, 0.5), rank(cpu, 0.5), rank(busiest, 0.5),
                clouds50 * 1e6 / (double(o.width) * o.height));
    if (!gpu["reproject"].empty()) std::printf("  reproject p50 %.2f ms", rank(gpu["reproject"], 0.5));
    if (!gpu["upscale"].empty()) std::printf("  upscale p50 %.2f ms", rank(gpu["upscale"], 0.5));
    std::uint64_t lookups = 0;
    if (reference) {
      auto counted = reference->render(last, &lookups);
      if (!counted) {
        std::fprintf(stderr, "\nsky_render_bench: %s\n", sky::describe(counted.error()).c_str());
        return 1;
      }
      std::printf(" %9.3g %9.1f %9.1f", double(lookups), double(lookups) / (clouds50 * 1e-3) * 1e-6,
                  double(lookups) / (rank(cpu, 0.5) * 1e-3) * 1e-6);
    }
    std::printf("\n");
    nlohmann::json passes = nlohmann::json::object();
    for (const auto& [name, samples] : gpu)
      passes[name] = {{"frames", samples.size()}, {"p50", rank(samples, 0.5)}, {"p90", rank(samples, 0.9)}};
    report["views"][v.name] = {{"gpu_ms", passes},
                               {"wall_ms", {{"p50", rank(wall, 0.5)}, {"p90", rank(wall, 0.9)}}},
                               {"process_cpu_ms", {{"p50", rank(cpu, 0.5)}}},
                               {"busiest_thread_cpu_ms", {{"p50", rank(busiest, 0.5)}}}};
    if (reference) report["views"][v.name]["cloud_model_lookups"] = lookups;
  }
  if (!o.json.empty()) std::ofstream(o.json) << report.dump(2) << '\n';
  return 0;
}
