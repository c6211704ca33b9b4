// Atmosphere tables and sky light (see atmosphere_tables.hpp): the shared
// atmosphere model compiled as C++ in double precision, inside a class that
// reads the table as the GPU's sampler does.
#include "atmosphere_tables.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>

#include <glm/glm.hpp>
#include <glm/gtc/packing.hpp>

#include "sky/core/assert.hpp"
#include "sky/render/haze.hpp"
#include "glsl_double.hpp"
#include "sky_light_grid.hpp"

namespace sky::render {

namespace {

// The core calls GLSL built-ins unqualified; GLM provides them.
using namespace glm;

class AirCore : public GlslDouble {
 public:

  explicit AirCore(const AtmosphereTables* tables) : tables_(tables) {}

  real3 sampleTransmittanceLut(real2 uv) const { return tables_->sampleTransmittance(uv); }
  real3 sampleMultipleScatteringLut(real2 uv) const { return tables_->sampleMultipleScattering(uv); }

#define SKY_CORE_CONST static constexpr
#include "core_common.glsl"
#include "atmosphere_core.glsl"
#undef SKY_CORE_CONST

 private:
  const AtmosphereTables* tables_;
};

// Rings in cos(zenith) and azimuths of the sky quadrature.
constexpr int kSkyRings = 8;
constexpr int kSkyAzimuths = 16;

}  // namespace

glm::dvec3 AtmosphereTable::sample(const glm::dvec2& uv) const {
  SKY_ASSERT(width > 0 && height > 0 && texels.size() == std::size_t(width) * height * 4);
  const double tx = std::clamp(uv.x, 0.0, 1.0) * width - 0.5;
  const double ty = std::clamp(uv.y, 0.0, 1.0) * height - 0.5;
  const double fx = std::floor(tx), fy = std::floor(ty);
  const double ax = tx - fx, ay = ty - fy;
  const int i0 = static_cast<int>(fx), j0 = static_cast<int>(fy);
  glm::dvec3 sum(0.0);
  for (int dj = 0; dj <= 1; ++dj)
    for (int di = 0; di <= 1; ++di) {
      const int i = std::clamp(i0 + di, 0, int(width) - 1);
      const int j = std::clamp(j0 + dj, 0, int(height) - 1);
      const std::size_t idx = (std::size_t(j) * width + std::size_t(i)) * 4;
      const double w = (di ? ax : 1 - ax) * (dj ? ay : 1 - ay);
      sum += w * glm::dvec3(glm::unpackHalf1x16(texels[idx]), glm::unpackHalf1x16(texels[idx + 1]),
                            glm::unpackHalf1x16(texels[idx + 2]));
    }
  return sum;
}

double atmosphereHeight_m() { return AirCore::kAtmosphereHeight_m; }
double aerosolExcessForVisibility(double visibility_m) {
  return AirCore(nullptr).aerosolExcessForVisibility(visibility_m);
}
double koschmiederVisibility_m(double extinction_perm) {
  return extinction_perm > 0 ? AirCore::kKoschmiederDepth / extinction_perm : AirCore::kFarAway_m;
}

namespace {

void store(AtmosphereTable& table, std::uint32_t i, std::uint32_t j, const glm::dvec3& v) {
  const std::size_t idx = (std::size_t(j) * table.width + i) * 4;
  for (int c = 0; c < 3; ++c) table.texels[idx + std::size_t(c)] = glm::packHalf1x16(float(v[c]));
  table.texels[idx + 3] = glm::packHalf1x16(1.0f);
}

}  // namespace

const AtmosphereTables& sharedAtmosphereTables() {
  static const AtmosphereTables tables = buildAtmosphereTables();
  return tables;
}

AtmosphereTables buildAtmosphereTables() {
  using C = AirCore;
  AtmosphereTables tables;
  AtmosphereTable& t = tables.transmittance;
  t.width = std::uint32_t(C::kTransmittanceLutWidth);
  t.height = std::uint32_t(C::kTransmittanceLutHeight);
  t.texels.resize(std::size_t(t.width) * t.height * 4);
  AirCore core(&tables);
  const double R = C::kAtmosphereBottomRadius_m, H = C::kAtmosphereHeight_m;
  const double rhoTop = std::sqrt(H * (2 * R + H));
  for (std::uint32_t j = 0; j < t.height; ++j)
    for (std::uint32_t i = 0; i < t.width; ++i) {
      // Inverse of transmittanceUv at the texel centre (Bruneton 2017 sec. 4).
      const double xMu = double(i) / double(t.width - 1);
      const double xR = double(j) / double(t.height - 1);
      const double rho = rhoTop * xR;
      const double r = std::sqrt(rho * rho + R * R);
      const double h = rho * rho / (r + R);  // r - R without cancellation
      const double dMin = H - h, dMax = rho + rhoTop;
      const double d = dMin + xMu * (dMax - dMin);
      const double mu = d <= 0 ? 1.0 : std::clamp((rhoTop * rhoTop - rho * rho - d * d) / (2 * r * d), -1.0, 1.0);
      store(t, i, j, core.transmittanceToTop(h, mu, kTransmittanceTableSteps));
    }
  // The multiple scattering reads the transmittance table just built.
  AtmosphereTable& m = tables.multipleScattering;
  m.width = m.height = std::uint32_t(C::kMultipleScatteringLutSize);
  m.texels.resize(std::size_t(m.width) * m.height * 4);
  for (std::uint32_t j = 0; j < m.height; ++j)
    for (std::uint32_t i = 0; i < m.width; ++i) {
      const double muSun = 2.0 * double(i) / double(m.width - 1) - 1.0;
      const double h = H * double(j) / double(m.height - 1);
      store(m, i, j, core.multipleScattering(h, muSun));
    }
  tables.skyLight = std::make_shared<SkyLightGrid>();
  return tables;
}

glm::dvec3 sunTransmittanceAt(const AtmosphereTables& tables, double h_m, double muSun, double groundRadius_m) {
  AirCore core(&tables);
  return core.sunTransmittance(h_m, muSun, groundRadius_m);
}

SkyDome skyDomeAt(const AtmosphereTables& tables, double h_m, double groundRadius_m, const glm::dvec3& sunDir) {
  using C = AirCore;
  AirCore core(&tables);
  const double h = std::max(h_m, 0.0);
  C::AirFrame a{};
  a.r = groundRadius_m + h;
  a.h = h;
  a.cGround = h * (2 * a.r - h);
  const double hAboveTop = h - C::kAtmosphereHeight_m;
  a.cTop = hAboveTop * (2 * a.r - hAboveTop);
  a.sunDir = sunDir;
  a.sunIrradiance = glm::dvec3(1.0);  // the inscatter is linear in it (atmosphere_core.glsl's marchAir)
  SkyDome dome;
  const double solidAngle = 2 * C::kPi / (kSkyRings * kSkyAzimuths);
  for (int ring = 0; ring < kSkyRings; ++ring) {
    const double mu = (ring + 0.5) / kSkyRings;  // equal solid angle per ring
    const double s = std::sqrt(1 - mu * mu);
    for (int k = 0; k < kSkyAzimuths; ++k) {
      const double phi = 2 * C::kPi * (k + 0.5) / kSkyAzimuths;
      const glm::dvec3 dir(s * std::cos(phi), s * std::sin(phi), mu);
      double q[C::kAirQueries] = {C::kFarAway_m};
      const C::AirPath path = core.marchAir(a, dir, C::kFarAway_m, q, 1);
      const glm::dvec3 night = path.transmittance[0] * C::kNightSkyRadiance;
      dome.perSun.meanRadiance += path.inscatter[0] / double(kSkyRings * kSkyAzimuths);
      dome.perSun.irradiance += path.inscatter[0] * mu * solidAngle;
      dome.night.meanRadiance += night / double(kSkyRings * kSkyAzimuths);
      dome.night.irradiance += night * mu * solidAngle;
    }
  }
  return dome;
}

SkyLight SkyDome::lit(const glm::dvec3& sunIrradiance) const {
  return SkyLight{sunIrradiance * perSun.meanRadiance + night.meanRadiance,
                  sunIrradiance * perSun.irradiance + night.irradiance};
}

SkyLight skyLightAt(const AtmosphereTables& tables, double h_m, double groundRadius_m, const glm::dvec3& sunDir,
                    const glm::dvec3& sunIrradiance) {
  return skyDomeAt(tables, h_m, groundRadius_m, sunDir).lit(sunIrradiance);
}

}  // namespace sky::render
