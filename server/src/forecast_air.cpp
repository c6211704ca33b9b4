// A forecast's air (forecast_air.hpp).
#include "sky/server/forecast_air.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>

#include "forecast_axes.hpp"
#include "sky/weather/query.hpp"

namespace sky::server {

namespace {

// GRIB2 code table 4.2, discipline 0: temperature (K), relative humidity (%).
constexpr long kCatTemperature = 0, kTemperature = 0, kCatMoisture = 1, kRelativeHumidity = 1;

struct Found {
  const GribField* temperature = nullptr;
  const GribField* humidity = nullptr;
};

}  // namespace

ForecastAir ForecastAir::fromGrib(const std::vector<const GribFile*>& files, std::vector<std::string>& notes) {
  std::map<std::int64_t, std::map<double, Found>> found;  // valid time -> height -> fields
  for (const GribFile* file : files)
    for (const GribField& f : file->fields) {
      const GribMeta& m = f.meta;
      if (m.discipline != 0) continue;
      const bool t = m.category == kCatTemperature && m.number == kTemperature;
      const bool rh = m.category == kCatMoisture && m.number == kRelativeHumidity;
      if (!t && !rh) continue;
      const auto alt = forecastLevelAltitude(m);
      if (!alt) continue;
      Found& at = found[m.valid_unix][*alt];
      if (t && !at.temperature) at.temperature = &f;
      if (rh && !at.humidity) at.humidity = &f;
    }
  ForecastAir out;
  // Heights with a temperature in any step, by height (at most the
  // snapshot's kMaxAirLevels, the lowest kept).
  std::map<double, std::size_t> heights;
  for (const auto& [valid, levels] : found)
    for (const auto& [alt, f] : levels)
      if (f.temperature) heights.emplace(alt, 0);
  while (heights.size() > weather::kMaxAirLevels) heights.erase(std::prev(heights.end()));
  std::size_t k = 0;
  for (auto& [alt, index] : heights) {
    index = k++;
    out.levels_m_.push_back(alt);
  }
  std::size_t withHumidity = 0;
  for (const auto& [valid, levels] : found) {
    Step step;
    step.valid_unix = valid;
    step.levels.resize(out.levels_m_.size());
    bool any = false;
    for (const auto& [alt, f] : levels) {
      const auto h = heights.find(alt);
      if (h == heights.end() || !f.temperature) continue;
      Level& l = step.levels[h->second];
      l.grid = f.temperature->meta.grid;
      l.temperature_c.resize(f.temperature->values.size());
      std::transform(f.temperature->values.begin(), f.temperature->values.end(), l.temperature_c.begin(),
                     [](float kelvin) { return kelvin - 273.15f; });
      if (f.humidity) {
        l.humidityGrid = f.humidity->meta.grid;
        l.humidity_pct = f.humidity->values;
        ++withHumidity;
      }
      any = true;
    }
    if (any) out.steps_.push_back(std::move(step));
  }
  if (!out.empty())
    notes.push_back("air: temperature at " + std::to_string(out.levels_m_.size()) + " level(s) from " +
                    std::to_string(static_cast<int>(out.levels_m_.front())) + " to " +
                    std::to_string(static_cast<int>(out.levels_m_.back())) + " m, " + std::to_string(out.steps_.size()) +
                    " step(s); relative humidity on " + std::to_string(withHumidity) + " of the steps' levels");
  return out;
}

std::optional<weather::AirValues> ForecastAir::atStep(const Step& step, std::size_t level, double lat_deg,
                                                      double lon_deg) const {
  const Level& l = step.levels[level];
  if (l.temperature_c.empty()) return std::nullopt;
  const float t = sampleField(l.grid, l.temperature_c, lat_deg, lon_deg);
  if (std::isnan(t)) return std::nullopt;
  const float rh = l.humidity_pct.empty() ? std::numeric_limits<float>::quiet_NaN()
                                          : sampleField(l.humidityGrid, l.humidity_pct, lat_deg, lon_deg);
  return weather::AirValues{t, std::isnan(rh) ? rh : std::clamp(rh, 0.0f, 100.0f)};
}

std::optional<weather::AirValues> ForecastAir::at(std::size_t level, double lat_deg, double lon_deg,
                                                  double valid_unix) const {
  if (steps_.empty() || level >= levels_m_.size()) return std::nullopt;
  using Air = std::optional<weather::AirValues>;
  return atValidTime(
      steps_, valid_unix, [&](const Step& s) { return atStep(s, level, lat_deg, lon_deg); },
      [](const Air& a, const Air& b, double f) -> Air {
        if (!a) return b;
        if (!b) return a;
        // A humidity one step lacks is the other's.
        const double ha = std::isnan(a->humidity_pct) ? b->humidity_pct : a->humidity_pct;
        const double hb = std::isnan(b->humidity_pct) ? a->humidity_pct : b->humidity_pct;
        return weather::AirValues{a->temperature_c + f * (b->temperature_c - a->temperature_c), ha + f * (hb - ha)};
      });
}

}  // namespace sky::server
