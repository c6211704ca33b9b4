// sky_lookup_bench: this machine's density-lookup throughput limit, the
// ceiling for a cloud march's inner loop (issue 7). A compute shader
// (lookup_march.comp) marches one ray per pixel through a tiled 128^3 volume
// doing exactly one 3D texture lookup per step and nothing else, dispatched
// with the workgroup permutation of reference/lavapipe.md; lookups per second
// = pixels x steps / GPU time of the dispatch; per CPU-second (pixels x steps /
// the process's CPU time) is the figure that survives a shared, loaded
// machine: the limit with n idle cores is about n times it. Prints a markdown table.
//   sky_lookup_bench                      # 320x180 and 640x360, RGBA8 and R8, coherent and scattered steps
//   sky_lookup_bench --smoke              # tiny run that checks every lookup happened (ctest)
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <memory>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

#include "lookup_gpu.hpp"

namespace {

using sky::bench::LookupDispatch;
using sky::bench::LookupGpu;
using sky::bench::VolumeFilter;
using sky::bench::VolumeFormat;

constexpr int kExitUnsupported = 77;  // ctest SKIP_RETURN_CODE: no Vulkan device
// Texel value of the --check volume: every trilinear lookup returns exactly 128/255.
constexpr std::uint8_t kCheckTexel = 128;

struct Size {
  std::uint32_t width = 0, height = 0;
};

std::vector<std::string> split(const std::string& s) {
  std::vector<std::string> out;
  std::stringstream in(s);
  for (std::string item; std::getline(in, item, ',');)
    if (!item.empty()) out.push_back(item);
  return out;
}

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  const std::size_t n = v.size();
  return n == 0 ? 0 : (n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]));
}

std::vector<std::uint8_t> volumeTexels(bool constant) {
  std::vector<std::uint8_t> texels(std::size_t(sky::bench::kVolumeSize) * sky::bench::kVolumeSize *
                                   sky::bench::kVolumeSize);
  if (constant) {
    std::fill(texels.begin(), texels.end(), kCheckTexel);
    return texels;
  }
  std::mt19937 rng(7);  // fixed: the same volume every run
  std::uniform_int_distribution<int> byte(0, 255);
  for (auto& t : texels) t = std::uint8_t(byte(rng));
  return texels;
}

// Every pixel's sum must be steps x 128/255: a skipped or duplicated lookup shows.
bool sumsMatch(const std::vector<float>& sums, std::uint32_t steps) {
  const double expected = steps * (kCheckTexel / 255.0);
  for (float s : sums)
    if (!(std::abs(s - expected) <= 1e-4 * steps)) {
      std::fprintf(stderr, "sky_lookup_bench: a pixel summed %.6f, expected %.6f\n", double(s), expected);
      return false;
    }
  return true;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"sky_lookup_bench: density-lookup throughput limit (one 3D texture lookup per step)"};
  std::string sizes = "320x180,640x360", formats = "rgba8,r8", stepTexels = "0.5,7.3", filter = "linear";
  unsigned steps = 128, repeats = 10, warmup = 3;
  bool smoke = false, check = false;
  app.add_option("--sizes", sizes, "dispatch sizes WxH, comma-separated")->capture_default_str();
  app.add_option("--formats", formats, "volume formats rgba8,r8")->capture_default_str();
  app.add_option("--step-texels", stepTexels,
                 "step lengths along the ray in texels: 0.5 is a coherent march, 7.3 scatters successive lookups")
      ->capture_default_str();
  app.add_option("--filter", filter, "linear (trilinear) or nearest")->capture_default_str();
  app.add_option("--steps", steps, "lookups per pixel")->capture_default_str();
  app.add_option("--repeats", repeats, "timed dispatches per case")->capture_default_str();
  app.add_option("--warmup", warmup, "untimed dispatches first (the first one compiles)")->capture_default_str();
  app.add_flag("--check", check, "use a constant volume and check every pixel's sum");
  app.add_flag("--smoke", smoke, "64x36, r8, 16 steps, 1 repeat, with --check (ctest)");
  CLI11_PARSE(app, argc, argv);
  if (smoke) sizes = "64x36", formats = "r8", stepTexels = "0.5", steps = 16, repeats = 1, warmup = 1, check = true;
  if (filter != "linear" && filter != "nearest") {
    std::fprintf(stderr, "sky_lookup_bench: --filter must be linear or nearest\n");
    return 2;
  }
  if (steps == 0 || repeats == 0) {
    std::fprintf(stderr, "sky_lookup_bench: --steps and --repeats must be at least 1\n");
    return 2;
  }
  std::vector<Size> sizeList;
  for (const std::string& s : split(sizes)) {
    Size size;
    char x = 0;
    if (std::sscanf(s.c_str(), "%u%c%u", &size.width, &x, &size.height) != 3 || x != 'x' || size.width == 0 ||
        size.height == 0 || size.width > 8192 || size.height > 8192) {
      std::fprintf(stderr, "sky_lookup_bench: size '%s' is not WxH in [1, 8192]\n", s.c_str());
      return 2;
    }
    sizeList.push_back(size);
  }
  std::vector<double> stepList;
  for (const std::string& s : split(stepTexels)) {
    char* end = nullptr;
    const double v = std::strtod(s.c_str(), &end);
    if (*end != '\0' || !(v > 0 && v < 1000)) {
      std::fprintf(stderr, "sky_lookup_bench: step '%s' is not a length in (0, 1000) texels\n", s.c_str());
      return 2;
    }
    stepList.push_back(v);
  }
  // Two lavapipe workers, as every benchmark here (reference/lavapipe.md, "Threads").
  if (std::getenv("LP_NUM_THREADS") == nullptr) setenv("LP_NUM_THREADS", "2", 1);

  // Devices live until the process ends, on purpose: destroying the last
  // Vulkan instance unloads the driver, and LeakSanitizer could then no longer
  // attribute the driver's own leaks to it (tests/lsan.supp). Reachable from
  // here, so not a leak themselves.
  static auto& devices = *new std::vector<std::unique_ptr<LookupGpu>>;
  bool headerDone = false;
  for (const std::string& formatName : split(formats)) {
    if (formatName != "rgba8" && formatName != "r8") {
      std::fprintf(stderr, "sky_lookup_bench: format '%s' is not rgba8 or r8\n", formatName.c_str());
      return 2;
    }
    auto gpu = LookupGpu::create(formatName == "rgba8" ? VolumeFormat::Rgba8 : VolumeFormat::R8,
                                 filter == "linear" ? VolumeFilter::Linear : VolumeFilter::Nearest,
                                 volumeTexels(check), SKY_LOOKUP_BENCH_SPV);
    if (!gpu) {
      std::fprintf(stderr, "sky_lookup_bench: %s\n", sky::describe(gpu.error()).c_str());
      return gpu.error().code == sky::ErrorCode::NoDevice ? kExitUnsupported : 1;
    }
    devices.push_back(std::move(*gpu));
    LookupGpu* device = devices.back().get();
    if (!headerDone) {
      std::printf("# sky_lookup_bench on %s, LP_NUM_THREADS=%s: 128^3 volume, %s filtering, repeat addressing, "
                  "%u lookups per pixel, median of %u dispatches after %u warm-up%s\n\n",
                  device->deviceName().c_str(), std::getenv("LP_NUM_THREADS"), filter.c_str(), steps, repeats, warmup,
                  check ? ", constant volume (checked)" : ", random volume");
      std::printf("| size | format | step texels | GPU ms median [min, max] | wall ms median | cores | "
                  "M lookups/s (GPU) | M lookups/s (wall) | M lookups per CPU-s |\n|---|---|---|---|---|---|---|---|---|\n");
      headerDone = true;
    }
    for (const Size& size : sizeList)
      for (double step : stepList) {
        const LookupDispatch d{size.width, size.height, steps, step, 60};
        std::vector<double> gpuMs, wallMs, cores, cpuMs;
        for (unsigned i = 0; i < warmup + repeats; ++i) {
          std::vector<float> sums;
          auto t = device->run(d, check ? &sums : nullptr);
          if (!t) {
            std::fprintf(stderr, "sky_lookup_bench: %s\n", sky::describe(t.error()).c_str());
            return 1;
          }
          if (check && !sumsMatch(sums, steps)) return 1;
          if (i < warmup) continue;
          gpuMs.push_back(t->gpu_ms);
          wallMs.push_back(t->wall_ms);
          cores.push_back(t->wall_ms > 0 ? t->cpu_ms / t->wall_ms : 0);
          cpuMs.push_back(t->cpu_ms);
        }
        const double lookups = double(size.width) * size.height * steps;
        const double g = median(gpuMs), w = median(wallMs);
        const double c = median(cpuMs);
        std::printf("| %ux%u | %s | %.1f | %.3f [%.3f, %.3f] | %.3f | %.2f | %.1f | %.1f | %.1f |\n", size.width,
                    size.height, formatName.c_str(), step, g, *std::min_element(gpuMs.begin(), gpuMs.end()),
                    *std::max_element(gpuMs.begin(), gpuMs.end()), w, median(cores), lookups / (g * 1e-3) * 1e-6,
                    lookups / (w * 1e-3) * 1e-6, c > 0 ? lookups / (c * 1e-3) * 1e-6 : 0.0);
        std::fflush(stdout);
      }
  }
  return 0;
}
