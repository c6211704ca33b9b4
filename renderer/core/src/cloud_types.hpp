// The cloud types' numbers: for each CIGI cloud type, the height profile,
// density scale, noise and erosion parameters and droplet size the shared
// density model (shaders/include/cloud_density.glsl) takes, plus the noise
// periods the frame setup places the textures with. One table for the GPU
// pass and the CPU reference.
#pragma once

#include "sky/weather/model.hpp"
#include "sky_shared.h"

namespace sky::render {

struct CloudTypeParams {
  // cloud_density.glsl's CloudType, in its order.
  double extinction_perm = 0;     // 1/m at density 1
  double dropletDiameter_um = 0;  // Jendersie-d'Eon Mie fit, [5, 50]; 0 = ice crystals
  double baseRound = 0;           // fractions of the layer thickness, see CloudType
  double topRoundStart = 0;
  double peak = 0;
  double peakVariation = 0;
  double anvil = 0;
  double densityGradient = 0;
  double densityBaseFade = 0;
  double densityTopFade = 0;
  double coverageEdge = 0;
  double fibrous = 0;
  double erosion = 0;
  double wispyHeight = 0;
  double columnFill = 0;
  // Placement of the noise textures.
  double shapePeriod_m = 0;   // world size of one period of the shape noise
  double detailPeriod_m = 0;  // of the detail noise
  double streak = 1;          // length of shape features along the Earth's axis over their width (>= 1)
};

// The same numbers as the shared core's CloudType (cloud_core.glsl compiled
// as C++: the CPU reference's core and the tests' harness each have one).
template <class CoreCloudType>
CoreCloudType coreCloudType(const CloudTypeParams& p) {
  CoreCloudType t{};
  t.extinction_perm = p.extinction_perm;
  t.dropletDiameter_um = p.dropletDiameter_um;
  t.baseRound = p.baseRound;
  t.topRoundStart = p.topRoundStart;
  t.peak = p.peak;
  t.peakVariation = p.peakVariation;
  t.anvil = p.anvil;
  t.densityGradient = p.densityGradient;
  t.densityBaseFade = p.densityBaseFade;
  t.densityTopFade = p.densityTopFade;
  t.coverageEdge = p.coverageEdge;
  t.fibrous = p.fibrous;
  t.erosion = p.erosion;
  t.wispyHeight = p.wispyHeight;
  t.columnFill = p.columnFill;
  return t;
}

// The numbers of a type; None (no type given) draws as cumulus.
const CloudTypeParams& cloudTypeParams(weather::CloudType type);

// The GPU's packing of the density part (sky_shared.h's SkyCloudType).
gpu::SkyCloudType packCloudType(const CloudTypeParams& p);

}  // namespace sky::render
