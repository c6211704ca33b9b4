// The shared cloud model (shaders/include/cloud_core.glsl) compiled as C++
// in double, inside a class whose members emulate the GPU's texture
// lookups: what the CPU reference marches and the path tracer's medium
// reads (one density function for both). Private to renderer/core.
#pragma once

#include <algorithm>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "air_table_texels.hpp"
#include "atmosphere_tables.hpp"
#include "blue_noise.hpp"
#include "coverage_mip.hpp"
#include "frame_setup.hpp"
#include "glsl_double.hpp"
#include "noise_volume.hpp"
#include "sky_shared.h"
#include "sun_map_texels.hpp"
#include "weather_field.hpp"
#include "sky/render/cpu_reference.hpp"

namespace sky::render::cpu_core {

// The core calls GLSL built-ins (dot, normalize, clamp, mix, min, max, sqrt,
// exp, pow, smoothstep) unqualified; GLM provides them with GLSL semantics.
using namespace glm;
using gpu::kMaxLayers;
using gpu::kWindMapLayers;
using gpu::kWindMapScale_mps;

// What the CPU core reads besides the frame: the shape and detail noise,
// the atmosphere's tables and the cloud pass's blue-noise tile, built as
// the GPU's are from the settings' noise seed (the noise from the disk
// cache in noiseCacheDir when it holds it, as the GPU renderer's).
struct CoreTables {
  NoiseVolume shape;
  NoiseVolume detail;
  AtmosphereTables atmosphere;
  std::vector<float> blueNoise;
};
std::shared_ptr<const CoreTables> makeCoreTables(std::uint32_t noiseSeed, const std::string& noiseCacheDir);

class CpuCore : public GlslDouble {
 public:

  CpuCore(const FrameSetup& setup, const CoreTables& tables, const WeatherField& weather)
      : setup_(setup), shape_(tables.shape), detail_(tables.detail), atmosphere_(tables.atmosphere), weather_(weather),
        blueNoise_(tables.blueNoise), coverageMip_(buildCoverageMip(weather)) {}

  real3 sampleTransmittanceLut(real2 uv) const { return atmosphere_.sampleTransmittance(uv); }
  real3 sampleMultipleScatteringLut(real2 uv) const { return atmosphere_.sampleMultipleScattering(uv); }

#define SKY_CORE_CONST static constexpr
  static constexpr bool kLightning = true;  // (lightning.glsl: the frame's counts decide)
  static constexpr bool kShowers = true;    // (cloud_core.glsl: each layer's carrier decides)
  static constexpr bool kWindField = true;  // (cloud_core.glsl's flow: the layer's flow.w decides)
// The model's switches (cloud_core.glsl, SKY_MODEL_CONST) as data members
// with their defaults: setModel() changes them for a measurement.
#define SKY_MODEL_CONST
#define SKY_AIR_TABLE_BUILDER
#define SKY_SUN_MAP_BUILDER
#include "cloud_core.glsl"
#undef SKY_SUN_MAP_BUILDER
#undef SKY_AIR_TABLE_BUILDER
#undef SKY_MODEL_CONST
#undef SKY_CORE_CONST

  // Switches parts of the model off (from the defaults a new core has).
  void setModel(const ModelSwitches& m) {
    if (m.octaveContribution) kOctaveContribution = *m.octaveContribution;
    if (m.octaveExtinction) kOctaveExtinction = *m.octaveExtinction;
    if (m.octaveEccentricity) kOctaveEccentricity = *m.octaveEccentricity;
    if (!m.octaves) kOctaveContribution = 0.0;
    if (!m.ambient) kAmbientGain = 0.0;
    if (m.sunDiffuseGain) kSunDiffuseGain = *m.sunDiffuseGain;
    if (!m.scatteredSun) kSunDiffuseGain = 0.0;
    if (!m.miePhase) kMiePhase = false;
  }

  static CloudType coreType(const CloudTypeParams& p) { return coreCloudType<CloudType>(p); }

  // Fills the layers layerAt() returns and the frame.
  CoreFrame coreFrame() {
    CoreFrame f{};
    f.air.r = setup_.r_m;
    f.air.h = setup_.hGround_m;
    f.air.cGround = setup_.cGround_m2;
    f.air.cTop = setup_.cAtmosphereTop_m2;
    f.air.sunDir = setup_.sunDir;
    f.air.sunIrradiance = setup_.sunIrradiance;
    f.air.airSteps = int(setup_.march.airSteps);
    f.air.aerosolExcess = setup_.aerosolExcess;
    f.groundIrradiance = setup_.groundIrradiance;
    f.march = MarchParams{int(setup_.march.primarySteps), int(setup_.march.lightSteps), setup_.march.minTransmittance,
                          double(setup_.march.emptyStride), setup_.march.cloudStep_m, setup_.march.emptyStep_m,
                          setup_.march.stepGrowth};
    f.layerCount = int(setup_.layers.size());
    f.flashCount = int(setup_.flashes.lights.size());
    f.boltCount = int(setup_.flashes.boltStart.size());
    f.pixelAngle = setup_.flashes.pixelAngle_rad;
    f.air.shadowLayers = setup_.march.cloudShadows ? f.layerCount : 0;
    const auto drawn =
        std::count_if(setup_.layers.begin(), setup_.layers.end(), [](const LayerSetup& l) { return !l.absent; });
    f.layerShadows = drawn > 1 ? f.air.shadowLayers : 0;
    const AirTableSettings& table = setup_.march.airTable;
    f.clouds = drawn > 0;
    f.airFromTable = table.enabled;
    f.airTable = table.enabled ? AirTableShape{int(table.azimuths), int(table.zeniths), int(table.slices)}
                               : AirTableShape{0, 0, 0};
    const SunMapSettings& sun = setup_.march.sunShadow;
    const SunMapGeometry g = sunMapGeometry(setup_);
    gSunMap = SunMap{int(sun.method), int(sun.size), int(sun.cascades), int(sun.buildSteps), sun.extent_m,
                     g.axisU, g.axisV, g.top_m, g.base_m, g.origin, g.origin, g.origin, g.origin, 0};
    const CloudType cumulus = coreType(cloudTypeParams(weather::CloudType::Cumulus));
    for (std::size_t i = 0; i < kMaxLayers; ++i) {
      CoreLayer& c = layers_[i];
      if (i < setup_.layers.size()) {
        const LayerSetup& l = setup_.layers[i];
        c = CoreLayer{l.hBase_m, l.hTop_m, l.cBase_m2, l.cTop_m2, l.thickness_m, l.lightDistance_m, l.blends,
                      coreType(l.primary), coreType(l.secondary), l.skyTop, l.sunDiffuseTop, l.sunCosine,
                      LayerSampling{real4(l.shapeOrigin, 1.0 / l.shapePeriod_m), real4(l.detailOrigin, 1.0 / l.detailPeriod_m),
                                    real4(l.cloudMapOrigin, 1.0 / l.cloudMapPeriod_m),
                                    real3(l.coverageShift_m, double(i)), l.shapeStretchZ, l.flow, l.windRef,
                                    real3(0.0), real3(0.0)},
                      l.absent, l.stepFactor, l.band, l.carrier};
      } else {
        c = CoreLayer{0.0, 0.0, 0.0, 0.0, 1.0, 1.0, false, cumulus, cumulus, real3(0.0), real3(0.0), 0.0,
                      LayerSampling{real4(0.0), real4(0.0), real4(0.0), real3(0.0, 0.0, double(i)), 1.0, real4(0.0),
                                    real4(0.0), real3(0.0), real3(0.0)},
                      true, 1.0, 0.0, -1};
      }
    }
    return f;
  }

  // Builds the frame's air table as the table pass does, when f has one
  // (after coreFrame: the cloud shadow in it reads the layers).
  void buildAirTable(const CoreFrame& f) {
    if (!f.airFromTable) return;
    airTable_ = AirTableTexels(f.airTable.azimuths, f.airTable.zeniths, f.airTable.slices);
    airTable_.build(
        [&](int i, int j) { buildAirTableColumn(f.air, f.airTable, airTableDirection(f.air, f.airTable, i, j)); });
  }

  // Builds the frame's sun map as the map pass does, when f has one and a
  // layer to shadow (after coreFrame).
  void buildSunMap(const CoreFrame& f) {
    if (!sunMapIsMap(gSunMap.method) || !f.clouds) return;
    sunMap_ = SunMapTexels(gSunMap.size, gSunMap.cascades, sunMapParts(gSunMap.method));
    sunMap_.build([&](int cascade, int i, int j) { buildSunMapTexel(f.air, gSunMap, f.layerCount, cascade, i, j); });
  }

  std::uint64_t lookups() const { return lookups_; }

  PixelResult shade(std::uint32_t px, std::uint32_t py, const CoreFrame& f) {
    const real3 dir = cameraRay(setup_.camForward, setup_.camRight, setup_.camDown, setup_.frustum, real(px),
                                real(py), setup_.rasterWidth, setup_.rasterHeight);
    // The step offset as clouds.comp takes it (a float of the tile, or the hash).
    const real jitter = setup_.march.blueNoise
                            ? real(blueNoise_[(py % kBlueNoiseSize) * kBlueNoiseSize + px % kBlueNoiseSize])
                            : pixelJitter(px, py);
    return shadePixel(f, dir, jitter);
  }

 private:
  // The weather map's plane point of a camera-local point (false behind the
  // anchor sphere's horizon), the layer's wind there (anchor east/north),
  // and where its tiles are read for it (as cloud_pass.glsl's).
  bool weatherPlane(real3 p, real2& plane);
  real2 windInPlane(LayerSampling s, real2 plane);
  real2 tilePlane(LayerSampling s, real2 plane);

  CoreLayer layers_[kMaxLayers]{};
  AirTableTexels airTable_;
  SunMapTexels sunMap_;
  SunMap gSunMap{};  // sun_map.glsl's global
  std::uint64_t lookups_ = 0;  // the cloud model's texture lookups so far
  const FrameSetup& setup_;
  const NoiseVolume& shape_;
  const NoiseVolume& detail_;
  const AtmosphereTables& atmosphere_;
  const WeatherField& weather_;
  const std::vector<float>& blueNoise_;
  const std::vector<float> coverageMip_;
};

}  // namespace sky::render::cpu_core
