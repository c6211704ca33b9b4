// Side-by-side mode (see side_by_side.hpp).
#include "sky/bench/side_by_side.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <numbers>
#include <string>

#include "sky/bench/cpu_time.hpp"
#include "sky/bench/driver_pin.hpp"
#include "sky/bench/renderer_probe.hpp"
#include "sky/bench/suite_loader.hpp"

namespace sky::bench {

Result<SunAngles> sunAnglesFromEnu(double east, double north, double up) {
  const double horizontal = std::hypot(east, north);
  if (!std::isfinite(horizontal) || !std::isfinite(up) || (horizontal == 0 && up == 0))
    return fail(ErrorCode::InvalidArgument, "sun direction must be a finite, non-zero vector");
  constexpr double kDeg = 180.0 / std::numbers::pi;
  SunAngles s;
  s.azimuth_deg = std::atan2(east, north) * kDeg;
  if (s.azimuth_deg < 0) s.azimuth_deg += 360.0;
  if (s.azimuth_deg >= 360.0) s.azimuth_deg -= 360.0;
  s.elevation_deg = std::atan2(up, horizontal) * kDeg;
  return s;
}

std::string cloudPassLine(std::uint32_t width, std::uint32_t height, double wall_ms, double cpu_ms,
                          double maxThread_ms) {
  char line[160];
  std::snprintf(line, sizeof line, "CLOUDPASS %ux%u %.3f cpu_ms=%.3f cores=%.2f max_thread_ms=%.3f", width, height,
                wall_ms, cpu_ms, wall_ms > 0 ? cpu_ms / wall_ms : 0.0, maxThread_ms);
  return line;
}

Result<void> runSideBySide(const SideBySideOptions& o, std::FILE* out, std::FILE* err) {
  auto sun = sunAnglesFromEnu(o.sunEast, o.sunNorth, o.sunUp);
  if (!sun) return tl::unexpected(sun.error());
  if (o.frames == 0) return fail(ErrorCode::InvalidArgument, "--frames must be at least 1");
  auto weather = loadWeatherFile(o.weatherFile);
  if (!weather) return tl::unexpected(weather.error());
  auto renderer = render::CloudRenderer::create(settingsFor(o.configuration, o.width, o.height, o.verticalFov_deg));
  if (!renderer) return tl::unexpected(renderer.error());
  keepVulkanDriversLoaded();

  render::FrameInputs in;
  in.camera.position = {o.lat_deg, o.lon_deg, o.heightAboveGround_m};
  in.camera.yaw_deg = o.yaw_deg;
  in.camera.pitch_deg = o.pitch_deg;
  in.weather = &weather->snapshot;
  in.weatherClock_s = weather->clockStart_s;
  in.sunAzimuth_deg = sun->azimuth_deg;
  in.sunElevation_deg = sun->elevation_deg;

  const auto& s = (*renderer)->settings();
  // An interleaved configuration is timed with its history full, as the
  // bench times its stills.
  const std::uint32_t warmup = std::max(o.warmup, render::historyWarmupFrames(s.temporal));
  std::fprintf(err, "# skyshell-bench side-by-side: %ux%u (rendered %ux%u, configuration %s) on %s, camera %.1f m above "
               "the ellipsoid at %.4f %.4f, heading %.1f (+%.2f a frame) pitch %.1f, vfov %.1f, sun azimuth %.2f elevation %.2f; "
               "%u warm-up frames not printed; LP_NUM_THREADS=%s\n",
               o.width, o.height, s.width, s.height, o.configuration.name.c_str(), (*renderer)->deviceName().c_str(),
               o.heightAboveGround_m, o.lat_deg, o.lon_deg, o.yaw_deg, o.turn_deg, o.pitch_deg,
               o.verticalFov_deg, sun->azimuth_deg, sun->elevation_deg, warmup,
               std::getenv("LP_NUM_THREADS") ? std::getenv("LP_NUM_THREADS") : "(unset)");
  bool announced = false;
  for (std::uint32_t i = 0; i < warmup + o.frames; ++i) {
    in.frameIndex = i;
    in.camera.yaw_deg = o.yaw_deg + o.turn_deg * double(i);
    const CpuSnapshot before = sampleCpu();
    const auto t0 = std::chrono::steady_clock::now();
    auto image = (*renderer)->render(in);
    const auto t1 = std::chrono::steady_clock::now();
    const CpuSnapshot after = sampleCpu();
    if (!image) return tl::unexpected(image.error());
    if (i < warmup) continue;
    const RendererCounters counters = rendererCounters(**renderer, *image);
    if (!announced) {
      std::fprintf(err, "# %s\n",
                   counters.gpuCloud_ms ? "wall = GPU timestamps around the cloud passes" : rendererCountersSource());
      announced = true;
    }
    const double wall_ms =
        counters.gpuCloud_ms.value_or(std::chrono::duration<double, std::milli>(t1 - t0).count());
    const CpuUse use = cpuBetween(before, after);
    std::fprintf(out, "%s\n", cloudPassLine(o.width, o.height, wall_ms, use.cpu_ms, use.maxThread_ms).c_str());
    std::fflush(out);
    // Per pass on the side (the CLOUDPASS line's format is the peer tools').
    std::string passes;
    for (const auto& pass : (*renderer)->lastPassTimes()) {
      char part[96];
      std::snprintf(part, sizeof part, " %s=%.3f", pass.pass.c_str(), pass.gpu_ms);
      passes += part;
    }
    std::fprintf(err, "# passes (GPU ms):%s\n", passes.c_str());
  }
  return {};
}

}  // namespace sky::bench
