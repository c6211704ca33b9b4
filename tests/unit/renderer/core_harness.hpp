// The shared cloud model (shaders/include/cloud_core.glsl) compiled as C++ in
// double precision inside a class whose texture hooks return what a test
// sets (a uniform field, no air extinction unless a table is given), for the
// closed-form tests of the core.
#pragma once

#include <cstdint>
#include <functional>

#include <glm/glm.hpp>

#include "sky_shared.h"

namespace sky::test {

using namespace glm;
using gpu::kMaxLayers;

class Core {
 public:
  using real = double;
  using real2 = glm::dvec2;
  using real3 = glm::dvec3;
  using real4 = glm::dvec4;
  using uint = std::uint32_t;

  real coverage = 1.0, density = 1.0, blend = 0.0, noise = 1.0, detail = 0.5;
  real2 cloudMap = real2(0.5, 1.0);
  // Shape-noise lookups so far (primary and light march): the march's cost.
  std::uint64_t shapeLookups = 0;
  // Every texture lookup of the cloud model (weather, cloud map, shape, detail).
  std::uint64_t lookups = 0;
  // Transmittance table lookup; unset: clear air transmits everything.
  std::function<real3(real2)> table;
  // Multiple-scattering table lookup; unset: none.
  std::function<real3(real2)> multipleScatteringTable;

  real3 sampleTransmittanceLut(real2 uv) const { return table ? table(uv) : real3(1.0); }
  real3 sampleMultipleScatteringLut(real2 uv) const {
    return multipleScatteringTable ? multipleScatteringTable(uv) : real3(0.0);
  }

#define SKY_CORE_CONST static constexpr
#include "cloud_core.glsl"
#undef SKY_CORE_CONST

  CoreLayer layers[kMaxLayers]{};
};

inline Core::CoreLayer Core::layerAt(int li) { return layers[li]; }
inline Core::real3 Core::sampleWeather(LayerSampling, real3) {
  ++lookups;
  return real3(coverage, density, blend);
}
inline Core::real2 Core::sampleCloudMap(LayerSampling, real3) {
  ++lookups;
  return cloudMap;
}
// The mip of a uniform field holds its coverage.
inline Core::real Core::sampleMaxCoverage(LayerSampling, real3) {
  ++lookups;
  return coverage;
}
inline Core::real2 Core::sampleShape(LayerSampling, real3) {
  ++lookups;
  ++shapeLookups;
  return real2(noise, noise);
}
inline Core::real Core::sampleDetail(LayerSampling, real3) {
  ++lookups;
  return detail;
}

}  // namespace sky::test
