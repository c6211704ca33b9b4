// The wind field (see wind_field.hpp).
#include "sky/weather/wind_field.hpp"

#include <cmath>
#include <numbers>

#include "cell_kernel.hpp"

namespace sky::weather {

namespace {
constexpr double kDeg = std::numbers::pi / 180.0;
}  // namespace

WindVector toVector(const LayerWind& wind) {
  // The air moves towards the direction opposite to where it comes from.
  const double to = (wind.fromDirection_deg + 180.0) * kDeg;
  return {wind.speed_mps * std::sin(to), wind.speed_mps * std::cos(to), wind.vertical_mps};
}

LayerWind fromVector(const WindVector& v) {
  LayerWind w;
  w.speed_mps = std::hypot(v.east_mps, v.north_mps);
  double from = std::atan2(-v.east_mps, -v.north_mps) / kDeg;
  if (from < 0) from += 360.0;
  w.fromDirection_deg = w.speed_mps > 0 ? std::fmod(from, 360.0) : 0.0;
  w.vertical_mps = v.up_mps;
  return w;
}

WindField::WindField(const WeatherSnapshot& snapshot) : WindField(snapshot.windTileLevel, snapshot.windTiles) {}

WindField::WindField(int level, std::span<const WindTile> tiles) : level_(level) {
  for (const WindTile& t : tiles) byLayer_[t.layerId][t.cellId] = {t.east_mps, t.north_mps, t.up_mps};
}

WindVector WindField::at(const CloudLayer& layer, double lat_deg, double lon_deg) const {
  const WindVector own = toVector(layer.wind);
  const auto found = byLayer_.find(layer.id);
  if (found == byLayer_.end()) return own;
  const auto& cells = found->second;
  WindVector sum{0, 0, 0};
  double total = 0;
  detail::forEachKernelCell(level_, lat_deg, lon_deg, [&](std::uint64_t cell, double w) {
    const auto it = cells.find(cell);
    const WindVector& v = it != cells.end() ? it->second : own;
    sum.east_mps += w * v.east_mps;
    sum.north_mps += w * v.north_mps;
    sum.up_mps += w * v.up_mps;
    total += w;
  });
  if (!(total > 0)) return own;
  return {sum.east_mps / total, sum.north_mps / total, sum.up_mps / total};
}

}  // namespace sky::weather
