// The shared cloud model (shaders/include/cloud_core.glsl) compiled as C++ in
// double precision inside a class whose texture hooks return what a test
// sets (a uniform field, no air extinction unless a table is given), for the
// closed-form tests of the core.
#pragma once

#include <cstdint>
#include <functional>
#include <vector>

#include <glm/glm.hpp>

#include "air_table_texels.hpp"
#include "glsl_double.hpp"
#include "sun_map_texels.hpp"
#include "sky_shared.h"

namespace sky::test {

using namespace glm;
using gpu::kMaxLayers;
using gpu::kWindMapScale_mps;

class Core : public render::GlslDouble {
 public:

  real coverage = 1.0, density = 1.0, blend = 0.0, noise = 1.0, detail = 0.5;
  // When set, the weather's coverage at a camera-relative point (instead of
  // the uniform `coverage`): a cell, a region.
  std::function<real(real3)> coverageAt;
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
  static constexpr bool kWindField = true;  // (cloud_core.glsl: the layer's flow.w decides)
  static constexpr bool kLightning = true;  // (lightning.glsl: the frame's counts decide)
  static constexpr bool kShowers = true;    // (cloud_core.glsl: each layer's carrier decides)
#define SKY_AIR_TABLE_BUILDER
#define SKY_SUN_MAP_BUILDER
#include "cloud_core.glsl"
#undef SKY_SUN_MAP_BUILDER
#undef SKY_AIR_TABLE_BUILDER
#undef SKY_CORE_CONST

  // When set, the shape noise of a layer (its sampling's coverageShift.z is
  // its index) at a camera-relative point, instead of the uniform `noise`.
  std::function<real2(LayerSampling, real3)> shapeAt;
  CoreLayer layers[kMaxLayers]{};
  // The frame's lightning a test sets (lightning.glsl's hooks).
  std::vector<real4> flashes, boltStarts;
  std::vector<real3> boltEnds;
  // The air table a test built (buildAirTable), read by shadePixel when the
  // frame asks for it.
  sky::render::AirTableTexels airTexels;

  // sun_map.glsl's global: the secondary march unless a test sets a map.
  SunMap gSunMap{kSunMarch, 16, 1, 16, 4000.0, real3(1, 0, 0), real3(0, 1, 0), 0.0, 0.0,
                 real3(0.0),       real3(0.0),     real3(0.0),     real3(0.0),     0};
  sky::render::SunMapTexels sunTexels;

  // Builds the sun map gSunMap describes for frame f's layers.
  void buildSunMap(const CoreFrame& f) {
    sunTexels = sky::render::SunMapTexels(gSunMap.size, gSunMap.cascades, sunMapParts(gSunMap.method));
    sunTexels.build([&](int cascade, int i, int j) { buildSunMapTexel(f.air, gSunMap, f.layerCount, cascade, i, j); });
  }

  void buildAirTable(const CoreFrame& f) {
    airTexels = sky::render::AirTableTexels(f.airTable.azimuths, f.airTable.zeniths, f.airTable.slices);
    airTexels.build(
        [&](int i, int j) { buildAirTableColumn(f.air, f.airTable, airTableDirection(f.air, f.airTable, i, j)); });
  }
};

inline Core::CoreLayer Core::layerAt(int li) { return layers[li]; }
inline Core::real4 Core::flashAt(int k) { return flashes[std::size_t(k)]; }
inline Core::real4 Core::boltStartAt(int k) { return boltStarts[std::size_t(k)]; }
inline Core::real3 Core::boltEndAt(int k) { return boltEnds[std::size_t(k)]; }
inline Core::real3 Core::sampleWeather(LayerSampling, real3 p) {
  ++lookups;
  return real3(coverageAt ? coverageAt(p) : coverage, density, blend);
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
inline Core::real2 Core::sampleShape(LayerSampling s, real3 p) {
  ++lookups;
  ++shapeLookups;
  return shapeAt ? shapeAt(s, p) : real2(noise, noise);
}
inline Core::real Core::sampleDetail(LayerSampling, real3) {
  ++lookups;
  return detail;
}
// A uniform field: the layer's own wind everywhere.
inline Core::real3 Core::sampleWindLocal(LayerSampling s, real3) { return real3(s.windRef); }
inline Core::real2 Core::airCloudShadow(AirFrame a, real3 p, real h, real muSun) {
  return airSunShadow(a, p, h, muSun);
}
inline void Core::storeSunMap(real4 part0, real4 part1) { sunTexels.store(part0, part1); }
inline Core::real4 Core::sampleSunMap(int layer, real2 uv) { return sunTexels.sample(layer, uv); }
inline void Core::storeAirTable(int slice, real4 part0, real4 part1, real4 part2) {
  airTexels.store(slice, part0, part1, part2);
}
inline Core::real4 Core::sampleAirTable(int part, real3 uvw) { return airTexels.sample(part, uvw); }

// Scenes for the closed-form tests.

// A cloud type that fills its layer uniformly: fades far thinner than a
// march step, density flat with height, no erosion, no diffuse depth.
inline Core::CloudType uniformType(double extinction_perm) {
  Core::CloudType t{};
  t.extinction_perm = extinction_perm;
  t.dropletDiameter_um = 10.0;
  t.baseRound = 1e-9;
  t.topRoundStart = 1.0 - 1e-9;
  t.peak = 1.0 + 1e-6;
  t.peakVariation = 0.0;
  t.anvil = 0.0;
  t.densityGradient = 0.0;
  t.densityBaseFade = 1e-9;
  t.densityTopFade = 1e-9;
  t.coverageEdge = 0.25;
  t.fibrous = 0.0;
  t.erosion = 0.0;
  t.wispyHeight = 0.2;
  t.columnFill = 0.0;
  return t;
}

// Haggstrom's cumulus (eq. 5-10, 14) as the type table writes it.
inline Core::CloudType haggstromCumulus(double extinction_perm = 0.06) {
  Core::CloudType t = uniformType(extinction_perm);
  t.baseRound = 0.07;
  t.topRoundStart = 0.2;
  t.peak = 1.0;
  t.densityGradient = 1.0;
  t.densityBaseFade = 0.15;
  t.densityTopFade = 0.1;
  t.erosion = 0.35;
  t.columnFill = 0.5;
  return t;
}

// A frame for a camera at altitude alt (m) over a sphere of radius R (m):
// the ground and atmosphere-top shells, the sun straight up with irradiance
// `sun` (0: none), no ground light, no layer yet, the core's default march.
inline Core::CoreFrame frameOver(double R, double alt, double sun) {
  Core::CoreFrame f{};
  f.clouds = true;
  f.march = Core::MarchParams{Core::kPrimarySteps, Core::kLightSteps, Core::kMinTransmittance, Core::kEmptyStride,
                              Core::kCloudStep_m, Core::kEmptyStep_m, Core::kStepGrowth};
  f.air.r = R + alt;
  f.air.h = alt;
  f.air.cGround = alt * (2 * f.air.r - alt);
  const double hTopAtm = alt - Core::kAtmosphereHeight_m;
  f.air.cTop = hTopAtm * (2 * f.air.r - hTopAtm);
  f.air.sunDir = Core::real3(0, 0, 1);
  f.air.sunIrradiance = Core::real3(sun);
  f.groundIrradiance = Core::real3(0);
  return f;
}

// The layer of type t from base to base + thickness (m), for frame f's
// camera at altitude alt, sampled with no offsets.
inline Core::CoreLayer shellLayer(const Core::CoreFrame& f, double alt, double base, double thickness,
                                  const Core::CloudType& t) {
  const double hBase = alt - base, hTop = alt - (base + thickness);
  return Core::CoreLayer{hBase, hTop, hBase * (2 * f.air.r - hBase), hTop * (2 * f.air.r - hTop), thickness,
                         0.5 * thickness, false, t, t, Core::real3(0), Core::real3(0), 1.0,
                         Core::LayerSampling{Core::real4(0.0), Core::real4(0.0), Core::real4(0.0), Core::real3(0.0), 1.0,
                                             Core::real4(0.0), Core::real4(0.0), Core::real3(0.0), Core::real3(0.0)},
                         false, 1.0, 0.0, -1};
}

}  // namespace sky::test
