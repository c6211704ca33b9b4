// Sky light from a grid filled on first use (see sky_light_grid.hpp).
#include "sky_light_grid.hpp"

#include <algorithm>
#include <cmath>

#include <glm/glm.hpp>

namespace sky::render {

SkyDome SkyLightGrid::node(const AtmosphereTables& tables, std::int64_t radiusKey, std::int64_t hIndex,
                           std::int64_t muIndex) {
  // Radius in km (< 2^20), height index (< 2^28: 67,000 km), cosine index (0..256).
  const std::uint64_t key = (std::uint64_t(radiusKey) << 40) | (std::uint64_t(hIndex) << 12) | std::uint64_t(muIndex);
  {
    std::lock_guard lock(mutex_);
    if (const auto it = nodes_.find(key); it != nodes_.end()) return it->second;
  }
  // Computed outside the lock: two threads may both compute a node, to the
  // same value.
  const double mu = std::clamp(double(muIndex) / kSkyGridPerSunCosine - 1.0, -1.0, 1.0);
  const glm::dvec3 sunDir(std::sqrt(std::max(1.0 - mu * mu, 0.0)), 0.0, mu);
  const SkyDome dome = skyDomeAt(tables, double(hIndex) * kSkyGridHeightStep_m,
                                 double(radiusKey) * kSkyGridRadiusStep_m, sunDir);
  std::lock_guard lock(mutex_);
  if (nodes_.size() >= kMaxNodes) nodes_.clear();
  nodes_.emplace(key, dome);
  return dome;
}

SkyLight SkyLightGrid::at(const AtmosphereTables& tables, double h_m, double groundRadius_m, const glm::dvec3& sunDir,
                          const glm::dvec3& sunIrradiance) {
  const std::int64_t radiusKey = std::llround(groundRadius_m / kSkyGridRadiusStep_m);
  // The dome integral is the same for every sun azimuth (it sums over all
  // azimuths), up to its quadrature: only the sun's cosine matters.
  const double h = std::max(h_m, 0.0) / kSkyGridHeightStep_m;
  const double u = (std::clamp(sunDir.z, -1.0, 1.0) + 1.0) * kSkyGridPerSunCosine;
  const double h0 = std::floor(h);
  const double u0 = std::min(std::floor(u), 2 * kSkyGridPerSunCosine - 1);
  const double fh = h - h0, fu = u - u0;
  const double weight[2][2] = {{(1 - fh) * (1 - fu), (1 - fh) * fu}, {fh * (1 - fu), fh * fu}};
  SkyDome corner[2][2];
  for (int dh = 0; dh <= 1; ++dh)
    for (int du = 0; du <= 1; ++du)
      if (weight[dh][du] > 0)  // a node not needed (h on a node: the ground) is not computed
        corner[dh][du] = node(tables, radiusKey, std::int64_t(h0) + dh, std::int64_t(u0) + du);
  // Geometric between the nodes where all four are positive: the light falls
  // off about exponentially with height and, through twilight, with the
  // sun's depression (linear gave 4 % at -6 degrees); linear where one is 0.
  auto blend = [&](auto value) {
    glm::dvec3 out(0.0);
    for (int c = 0; c < 3; ++c) {
      bool positive = true;
      double linear = 0, logSum = 0;
      for (int dh = 0; dh <= 1; ++dh)
        for (int du = 0; du <= 1; ++du) {
          const double w = weight[dh][du];
          if (w <= 0) continue;
          const double v = value(corner[dh][du])[c];
          linear += w * v;
          positive = positive && v > 0;
          if (v > 0) logSum += w * std::log(v);
        }
      out[c] = positive ? std::exp(logSum) : linear;
    }
    return out;
  };
  SkyDome sum;
  sum.perSun.meanRadiance = blend([](const SkyDome& d) { return d.perSun.meanRadiance; });
  sum.perSun.irradiance = blend([](const SkyDome& d) { return d.perSun.irradiance; });
  sum.night.meanRadiance = blend([](const SkyDome& d) { return d.night.meanRadiance; });
  sum.night.irradiance = blend([](const SkyDome& d) { return d.night.irradiance; });
  return sum.lit(sunIrradiance);
}

std::size_t SkyLightGrid::nodes() const {
  std::lock_guard lock(mutex_);
  return nodes_.size();
}

SkyLight skyLight(const AtmosphereTables& tables, double h_m, double groundRadius_m, const glm::dvec3& sunDir,
                  const glm::dvec3& sunIrradiance) {
  if (!tables.skyLight) return skyLightAt(tables, h_m, groundRadius_m, sunDir, sunIrradiance);
  return tables.skyLight->at(tables, h_m, groundRadius_m, sunDir, sunIrradiance);
}

}  // namespace sky::render
