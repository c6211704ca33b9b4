// CPU reference integrator: compiles the shared cloud model
// (shaders/include/cloud_core.glsl) as C++ with double-precision GLM vectors,
// inside a class whose members emulate the GPU's texture lookups.
#include "sky/render/cpu_reference.hpp"

#include <cstdint>

#include <glm/glm.hpp>

#include "frame_setup.hpp"
#include "noise_volume.hpp"
#include "sky_shared.h"
#include "weather_field.hpp"

namespace sky::render {

namespace {

// The core calls GLSL built-ins (dot, normalize, clamp, mix, min, max, sqrt,
// exp) unqualified; GLM provides them with GLSL semantics.
using namespace glm;
using gpu::kMaxLayers;

class CpuCore {
 public:
  using real = double;
  using real2 = glm::dvec2;
  using real3 = glm::dvec3;
  using uint = std::uint32_t;

  CpuCore(const FrameSetup& setup, const NoiseVolume& noise, const WeatherField& weather)
      : setup_(setup), noise_(noise), weather_(weather) {}

  // Mirrors sampleWeather in shaders/clouds.comp.
  real2 sampleWeather(int layer, real3 p) const {
    const real3 q = setup_.camToAnchor * p + setup_.camInAnchor_m;
    if (q.z <= 0.0) return real2(0.0);
    const real2 plane =
        real2(q.x, q.y) * (setup_.anchorRadius_m / q.z) - setup_.layers[std::size_t(layer)].coverageShift_m;
    return weather_.sample(std::uint32_t(layer), plane.x, plane.y);
  }

  // Mirrors sampleNoise in shaders/clouds.comp.
  real sampleNoise(int layer, real3 p) const {
    return noise_.sample(setup_.layers[std::size_t(layer)].noiseOrigin + (setup_.localToEcef * p) / kNoisePeriod_m);
  }

  // Mirrors sampleCloudMap in shaders/clouds.comp.
  real sampleCloudMap(int layer, real3 p) const {
    return noise_.sample(setup_.layers[std::size_t(layer)].cloudMapOrigin + (setup_.localToEcef * p) / kCloudMapPeriod_m);
  }

#define SKY_CORE_CONST static constexpr
#include "cloud_core.glsl"
#undef SKY_CORE_CONST

  CoreFrame coreFrame() const {
    CoreFrame f{};
    f.r = setup_.r_m;
    f.cGround = setup_.cGround_m2;
    f.sunDir = setup_.sunDir;
    f.sunRadiance = setup_.sunRadiance;
    f.ambient = setup_.ambient;
    f.layerCount = int(setup_.layers.size());
    for (std::size_t i = 0; i < kMaxLayers; ++i) {
      if (i < setup_.layers.size()) {
        const LayerSetup& l = setup_.layers[i];
        f.layers[i] = CoreLayer(l.hBase_m, l.hTop_m, l.cBase_m2, l.cTop_m2, l.thickness_m);
      } else {
        f.layers[i] = CoreLayer(0.0, 0.0, 0.0, 0.0, 1.0);
      }
    }
    return f;
  }

  PixelResult shade(std::uint32_t px, std::uint32_t py, const CoreFrame& f) {
    const real3 dir = cameraRay(setup_.camForward, setup_.camRight, setup_.camDown, setup_.tanHalfFov,
                                setup_.aspect, real(px), real(py), real(setup_.width), real(setup_.height));
    return shadePixel(f, dir, pixelJitter(px, py));
  }

 private:
  const FrameSetup& setup_;
  const NoiseVolume& noise_;
  const WeatherField& weather_;
};

}  // namespace

Result<Image> renderCpuReference(const RenderSettings& settings, const FrameInputs& inputs) {
  if (auto ok = validateSettings(settings); !ok) return tl::unexpected(ok.error());
  if (auto ok = validateInputs(inputs); !ok) return tl::unexpected(ok.error());
  const NoiseVolume noise = makeShapeNoise(kNoiseSize, settings.noiseSeed);
  const WeatherField field = buildWeatherField(inputs.weather, inputs.camera.position);
  const FrameSetup setup = prepareFrame(settings, inputs, field);
  CpuCore core(setup, noise, field);
  const auto frame = core.coreFrame();

  Image image;
  image.width = settings.width;
  image.height = settings.height;
  image.rgba.resize(std::size_t(settings.width) * settings.height * 4);
  image.cloudDepth_m.resize(std::size_t(settings.width) * settings.height);
  for (std::uint32_t y = 0; y < settings.height; ++y)
    for (std::uint32_t x = 0; x < settings.width; ++x) {
      const auto r = core.shade(x, y, frame);
      float* out = &image.rgba[(std::size_t(y) * settings.width + x) * 4];
      out[0] = float(r.radiance.x);
      out[1] = float(r.radiance.y);
      out[2] = float(r.radiance.z);
      out[3] = float(r.transmittance);
      image.cloudDepth_m[std::size_t(y) * settings.width + x] = float(r.depth);
    }
  return image;
}

}  // namespace sky::render
