// A timed frame (see timed_render.hpp).
#include "sky/app/timed_render.hpp"

#include <time.h>

#include <chrono>

#include <spdlog/spdlog.h>

#include "sky/render/ephemeris.hpp"

namespace sky::app {

double processCpu_ms() {
  timespec t{};
  if (clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t) != 0) return 0;
  return double(t.tv_sec) * 1e3 + double(t.tv_nsec) * 1e-6;
}

Result<render::Image> timedRender(render::CloudRenderer& renderer, const render::FrameInputs& in, FrameRecord& record) {
  using Clock = std::chrono::steady_clock;
  const double cpu0 = processCpu_ms();
  const auto t0 = Clock::now();
  auto image = renderer.render(in);
  if (!image) return image;
  record.render_ms = std::chrono::duration<double, std::milli>(Clock::now() - t0).count();
  record.cpu_ms = processCpu_ms() - cpu0;
  record.gpu = renderer.lastPassTimes();
  record.temporal = renderer.lastTemporal();
  record.sunMap = renderer.lastSunMap();
  record.nearPrecip = renderer.lastNearPrecip();
  record.weatherMap = renderer.lastWeatherMap();
  record.stats = render::computeStats(*image);
  recordLighting(in, record);
  return image;
}

void recordLighting(const render::FrameInputs& in, FrameRecord& record) {
  // The same choice as the renderer's frame setup: the ephemeris when the
  // frame has a date, else the given angles.
  if (in.utc_s) {
    const auto sun = render::sunDirection(*in.utc_s, in.camera.position.lat_deg, in.camera.position.lon_deg);
    const auto moon = render::moonDirection(*in.utc_s, in.camera.position.lat_deg, in.camera.position.lon_deg);
    record.sunAzimuth_deg = sun.azimuth_deg;
    record.sunElevation_deg = sun.elevation_deg;
    record.moonAzimuth_deg = moon.azimuth_deg;
    record.moonElevation_deg = moon.elevation_deg;
    record.utc_s = in.utc_s;
  } else {
    record.sunAzimuth_deg = in.sunAzimuth_deg;
    record.sunElevation_deg = in.sunElevation_deg;
    record.moonAzimuth_deg = in.moonAzimuth_deg;
    record.moonElevation_deg = in.moonElevation_deg;
  }
  record.visibility_m = in.visibility_m;
}

void logValidationMessages(render::CloudRenderer& renderer) {
  for (const auto& m : renderer.takeValidationMessages()) {
    if (m.rfind("error: ", 0) == 0)
      spdlog::error("vulkan validation {}", m);
    else
      spdlog::warn("vulkan validation {}", m);
  }
}

}  // namespace sky::app
