// A forecast's winds (forecast_wind.hpp).
#include "sky/server/forecast_wind.hpp"

#include <algorithm>
#include <cmath>
#include <map>

#include "forecast_axes.hpp"
#include "sky/weather/query.hpp"

namespace sky::server {

namespace {

// GRIB2 code table 4.2, discipline 0 category 2 (momentum).
constexpr long kCatMomentum = 2, kU = 2, kV = 3, kOmega = 8, kVerticalVelocity = 9;
constexpr long kIsobaric = 100;
constexpr double kGravity = 9.80665, kAirGasConstant = 287.05;
// How far above the highest level and below the lowest its wind is taken.
constexpr double kBeyondLevels_m = 1500;

struct LevelFields {
  const GribField* u = nullptr;
  const GribField* v = nullptr;
  const GribField* w = nullptr;
  bool omega = false;  // w is in Pa/s (code 8), not m/s (code 9)
  double pressure_pa = 0;
};

}  // namespace

ForecastWind ForecastWind::fromGrib(const std::vector<const GribFile*>& files, std::vector<std::string>& notes) {
  // valid time -> level height -> fields
  std::map<std::int64_t, std::map<double, LevelFields>> found;
  for (const GribFile* file : files)
    for (const GribField& f : file->fields) {
      const GribMeta& m = f.meta;
      if (m.discipline != 0 || m.category != kCatMomentum) continue;
      const auto alt = forecastLevelAltitude(m);
      if (!alt) continue;
      LevelFields& l = found[m.valid_unix][*alt];
      l.pressure_pa = m.levelType == kIsobaric ? m.level : 0;
      if (m.number == kU && !l.u) l.u = &f;
      if (m.number == kV && !l.v) l.v = &f;
      if ((m.number == kOmega || m.number == kVerticalVelocity) && !l.w && m.levelType == kIsobaric) {
        l.w = &f;
        l.omega = m.number == kOmega;
      }
    }
  ForecastWind out;
  std::size_t skipped = 0;
  for (const auto& [valid, levels] : found) {
    Step step;
    step.valid_unix = valid;
    for (const auto& [alt, f] : levels) {
      if (!f.u || !f.v || !(f.u->meta.grid == f.v->meta.grid) || f.u->values.size() != f.v->values.size()) {
        ++skipped;
        continue;
      }
      Level l;
      l.alt_m = alt;
      l.grid = f.u->meta.grid;
      l.u.resize(f.u->values.size());
      l.v.resize(f.u->values.size());
      // Earth-relative once, at each grid point, so sampling needs no turn.
      for (int j = 0; j < l.grid.nj; ++j)
        for (int i = 0; i < l.grid.ni; ++i) {
          const std::size_t k = valueIndex(l.grid, i, j);
          const LatLon at = gridLatLon(l.grid, i, j);
          const auto [east, north] = eastNorthWind(l.grid, at.lat_deg, at.lon_deg, f.u->values[k], f.v->values[k]);
          l.u[k] = static_cast<float>(east);
          l.v[k] = static_cast<float>(north);
        }
      if (f.w && f.w->meta.grid == l.grid && f.w->values.size() == l.u.size()) {
        l.w = f.w->values;
        if (f.omega) {
          // omega = -rho g w, with the standard atmosphere's density at the level.
          const double t_k = weather::isaTemperature_c(alt) + 273.15;
          const double rho = f.pressure_pa / (kAirGasConstant * t_k);
          for (float& x : l.w) x = static_cast<float>(-x / (rho * kGravity));
        }
      }
      step.levels.push_back(std::move(l));
    }
    if (!step.levels.empty()) out.steps_.push_back(std::move(step));
  }
  if (!out.empty()) {
    const Step& s = out.steps_.front();
    notes.push_back("wind: u and v at " + std::to_string(out.levelCount()) + " level(s) from " +
                    std::to_string(static_cast<int>(s.levels.front().alt_m)) + " to " +
                    std::to_string(static_cast<int>(s.levels.back().alt_m)) + " m, " +
                    std::to_string(out.steps_.size()) + " step(s)" +
                    (s.levels.front().grid.uvRelativeToGrid ? ", turned from the grid's axes to east and north" : ""));
  }
  if (skipped > 0) notes.push_back("wind: " + std::to_string(skipped) + " level(s) without both u and v on one grid, left out");
  return out;
}

std::size_t ForecastWind::levelCount() const {
  std::size_t n = 0;
  for (const Step& s : steps_) n = std::max(n, s.levels.size());
  return n;
}

std::optional<weather::WindVector> ForecastWind::atStep(const Step& step, double lat_deg, double lon_deg,
                                                        double alt_m) const {
  // The levels with a value here, and of them the two round alt_m.
  const Level* below = nullptr;
  const Level* above = nullptr;
  weather::WindVector vb, va;
  for (const Level& l : step.levels) {
    const float u = sampleField(l.grid, l.u, lat_deg, lon_deg);
    const float v = sampleField(l.grid, l.v, lat_deg, lon_deg);
    if (std::isnan(u) || std::isnan(v)) continue;
    float w = l.w.empty() ? 0.0f : sampleField(l.grid, l.w, lat_deg, lon_deg);
    if (std::isnan(w)) w = 0;
    const weather::WindVector here{u, v, std::clamp(double(w), -50.0, 50.0)};
    if (l.alt_m <= alt_m) {
      below = &l;
      vb = here;
    } else {
      above = &l;
      va = here;
      break;
    }
  }
  if (!below && !above) return std::nullopt;
  // Beyond the levels the nearest one's wind holds, up to kBeyondLevels_m
  // from it: a file with the 10 m wind alone says nothing of cirrus.
  if (!above) return alt_m - below->alt_m <= kBeyondLevels_m ? std::optional(vb) : std::nullopt;
  if (!below) return above->alt_m - alt_m <= kBeyondLevels_m ? std::optional(va) : std::nullopt;
  const double f = std::clamp((alt_m - below->alt_m) / (above->alt_m - below->alt_m), 0.0, 1.0);
  return weather::WindVector{vb.east_mps + f * (va.east_mps - vb.east_mps), vb.north_mps + f * (va.north_mps - vb.north_mps),
                             vb.up_mps + f * (va.up_mps - vb.up_mps)};
}

std::optional<weather::WindVector> ForecastWind::at(double lat_deg, double lon_deg, double alt_m,
                                                    double valid_unix) const {
  if (steps_.empty()) return std::nullopt;
  using Wind = std::optional<weather::WindVector>;
  return atValidTime(
      steps_, valid_unix, [&](const Step& s) { return atStep(s, lat_deg, lon_deg, alt_m); },
      [](const Wind& a, const Wind& b, double t) -> Wind {
        if (!a) return b;
        if (!b) return a;
        return weather::WindVector{a->east_mps + t * (b->east_mps - a->east_mps),
                                   a->north_mps + t * (b->north_mps - a->north_mps),
                                   a->up_mps + t * (b->up_mps - a->up_mps)};
      });
}

}  // namespace sky::server
