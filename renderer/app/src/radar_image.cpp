// A headless replay's radar pictures (see radar_image.hpp).
#include "sky/app/radar_image.hpp"

#include <array>
#include <cmath>

#include "sky/render/cloud_renderer.hpp"
#include "sky/weather/precipitation.hpp"
#include "sky/weather/query.hpp"
#include "sky/weather/radar.hpp"

namespace sky::app {

namespace {

// From 5 dBZ in 5-dBZ steps (the last from 70 up).
constexpr std::array<std::array<std::uint8_t, 3>, 14> kScale = {{
    {4, 233, 231}, {1, 159, 244}, {3, 0, 244},    {2, 253, 2},   {1, 197, 1},   {0, 142, 0},   {253, 248, 2},
    {229, 188, 0}, {253, 149, 0}, {253, 0, 0},    {212, 0, 0},   {188, 0, 0},   {248, 0, 253}, {255, 255, 255},
}};

}  // namespace

void radarColour(double dbz, std::uint8_t rgb[3]) {
  if (!(dbz >= 5)) {
    rgb[0] = rgb[1] = rgb[2] = 0;
    return;
  }
  const std::size_t step = std::min<std::size_t>(static_cast<std::size_t>((dbz - 5) / 5), kScale.size() - 1);
  for (int c = 0; c < 3; ++c) rgb[c] = kScale[step][std::size_t(c)];
}

std::vector<std::uint8_t> radarRgb(const std::vector<float>& dbz, int size) {
  std::vector<std::uint8_t> rgb(std::size_t(size) * size * 3, 0);
  const double half = 0.5 * size;
  for (int i = 0; i < size; ++i)
    for (int j = 0; j < size; ++j) {
      std::uint8_t* px = &rgb[(std::size_t(i) * size + j) * 3];
      radarColour(dbz[std::size_t(i) * size + j], px);
      const double r = std::hypot(j + 0.5 - half, i + 0.5 - half);
      if (std::abs(r - (half - 0.5)) < 0.5) px[0] = px[1] = px[2] = 96;  // the range
      if (r < 1.0) px[0] = px[1] = px[2] = 255;                          // the radar
    }
  return rgb;
}

Result<void> writeRadarPicture(const weather::WeatherSnapshot& snapshot, double clock_s, const geo::Geodetic& at,
                               double range_m, const std::string& path) {
  const weather::RadarSite site{at.lat_deg, at.lon_deg, at.alt_m, range_m, kReplayRadarTilt_deg, kReplayRadarSize};
  const std::vector<float> dbz =
      weather::radarPicture(snapshot.layers, weather::snapshotLookup(snapshot, clock_s), site);
  return render::writeRgbPng(radarRgb(dbz, site.size), std::uint32_t(site.size), std::uint32_t(site.size), path);
}

}  // namespace sky::app
