// A forecast's two axes besides the map, one rule each for the cover, the
// winds and the air: where a level is, and the value at a valid time.
#pragma once

#include <algorithm>
#include <cmath>
#include <optional>
#include <vector>

#include "sky/server/grib.hpp"
#include "sky/weather/query.hpp"

namespace sky::server {

// A level's height (m MSL): a pressure level's through the standard
// atmosphere (the layers' heights come the same way, so a layer, its wind
// and its air agree on where a pressure is); a level above the ground (10 m
// wind, 2 m temperature) at that height above sea level, as the forecast
// carries no terrain the server reads. nullopt for other level types.
inline std::optional<double> forecastLevelAltitude(const GribMeta& m) {
  constexpr long kIsobaric = 100, kHeightAboveGround = 103;
  if (!std::isfinite(m.level)) return std::nullopt;
  if (m.levelType == kIsobaric && m.level > 0) return weather::isaAltitude_m(m.level / 100);
  if (m.levelType == kHeightAboveGround && m.level >= 0 && m.level <= 200) return m.level;
  return std::nullopt;
}

// The value at a valid time from the steps (each with valid_unix, by valid
// time): the first step's before it, the last's after it, and between two
// steps mix(a, b, f) of their values, f the fraction of the way from the
// earlier to the later.
template <class Step, class Sample, class Mix>
auto atValidTime(const std::vector<Step>& steps, double valid_unix, Sample&& sample, Mix&& mix)
    -> decltype(sample(steps.front())) {
  if (steps.size() == 1 || valid_unix <= static_cast<double>(steps.front().valid_unix)) return sample(steps.front());
  if (valid_unix >= static_cast<double>(steps.back().valid_unix)) return sample(steps.back());
  const auto next = std::upper_bound(steps.begin(), steps.end(), valid_unix,
                                     [](double t, const Step& s) { return t < static_cast<double>(s.valid_unix); });
  const auto prev = next - 1;
  const double f = (valid_unix - static_cast<double>(prev->valid_unix)) /
                   static_cast<double>(next->valid_unix - prev->valid_unix);
  return mix(sample(*prev), sample(*next), f);
}

}  // namespace sky::server
