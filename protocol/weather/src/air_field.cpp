// The air field (see air_field.hpp).
#include "sky/weather/air_field.hpp"

#include <cmath>
#include <limits>
#include <utility>
#include <vector>

#include "cell_kernel.hpp"
#include "sky/weather/query.hpp"

namespace sky::weather {

AirField::AirField(const WeatherSnapshot& snapshot) : cellLevel_(snapshot.airTileLevel), levels_m_(snapshot.airLevels_m) {
  if (snapshot.airTiles.empty()) return;
  byLevel_.resize(levels_m_.size());
  for (const AirTile& t : snapshot.airTiles)
    if (t.level < byLevel_.size()) byLevel_[t.level][t.cellId] = {t.temperature_c, t.humidity_pct};
}

std::optional<AirValues> AirField::at(double lat_deg, double lon_deg, double alt_m) const {
  if (empty() || !std::isfinite(alt_m)) return std::nullopt;
  // The kernel's cells and weights, once for all levels.
  std::vector<std::pair<std::uint64_t, double>> kernel;
  detail::forEachKernelCell(cellLevel_, lat_deg, lon_deg,
                            [&](std::uint64_t cell, double w) { kernel.emplace_back(cell, w); });
  // Each level's temperature and humidity here (NaN: none in reach).
  constexpr double kNone = std::numeric_limits<double>::quiet_NaN();
  std::vector<double> temperature(levels_m_.size(), kNone), humidity(levels_m_.size(), kNone);
  for (std::size_t k = 0; k < byLevel_.size(); ++k) {
    double t = 0, tw = 0, h = 0, hw = 0;
    for (const auto& [cell, w] : kernel) {
      const auto it = byLevel_[k].find(cell);
      if (it == byLevel_[k].end()) continue;
      t += w * it->second.temperature_c;
      tw += w;
      if (it->second.humidity_pct >= 0) {
        h += w * it->second.humidity_pct;
        hw += w;
      }
    }
    if (tw > 0) temperature[k] = t / tw;
    if (hw > 0) humidity[k] = h / hw;
  }
  // Of the levels with a value: linear in height between the two round
  // alt_m; past them the nearest one's within kAirBeyondLevels_m, the
  // temperature carried along the standard atmosphere's profile.
  auto profile = [&](const std::vector<double>& v, bool lapse) -> std::optional<double> {
    std::optional<std::size_t> below, above;
    for (std::size_t k = 0; k < v.size(); ++k) {
      if (std::isnan(v[k])) continue;
      if (levels_m_[k] <= alt_m) {
        below = k;
      } else {
        above = k;
        break;
      }
    }
    if (below && above) {
      const double f = (alt_m - levels_m_[*below]) / (levels_m_[*above] - levels_m_[*below]);
      return v[*below] + f * (v[*above] - v[*below]);
    }
    const std::optional<std::size_t> nearest = below ? below : above;
    if (!nearest || std::abs(alt_m - levels_m_[*nearest]) > kAirBeyondLevels_m) return std::nullopt;
    return v[*nearest] + (lapse ? isaTemperature_c(alt_m) - isaTemperature_c(levels_m_[*nearest]) : 0.0);
  };
  const std::optional<double> t = profile(temperature, true);
  if (!t) return std::nullopt;
  return AirValues{*t, profile(humidity, false).value_or(double(kNoHumidity))};
}

}  // namespace sky::weather
