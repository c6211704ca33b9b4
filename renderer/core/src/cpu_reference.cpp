// CPU reference integrator: the shared cloud model compiled as C++ in
// double (cpu_core.hpp), marched over every pixel as the GPU's cloud pass.
#include "sky/render/cpu_reference.hpp"

#include <cstdint>
#include <string>

#include "cpu_core.hpp"

namespace sky::render {

using cpu_core::CpuCore;

CpuReference::CpuReference(RenderSettings settings, std::shared_ptr<const cpu_core::CoreTables> tables)
    : settings_(settings), tables_(std::move(tables)) {}

Result<CpuReference> CpuReference::create(const RenderSettings& settings) {
  if (auto ok = validateSettings(settings); !ok) return tl::unexpected(ok.error());
  auto tables = cpu_core::makeCoreTables(settings.noiseSeed, settings.noiseCacheDir);
  // The reference draws every pixel at full size: no resolution divisor.
  RenderSettings full = settings;
  full.resolution = {};
  return CpuReference(full, std::move(tables));
}

Result<std::vector<std::array<float, 4>>> CpuReference::renderPixels(const FrameInputs& inputs,
                                                                     std::span<const PixelCoord> pixels) const {
  if (auto ok = validateInputs(inputs); !ok) return tl::unexpected(ok.error());
  for (const PixelCoord& p : pixels)
    if (p.x >= settings_.width || p.y >= settings_.height)
      return fail(ErrorCode::InvalidArgument, "CpuReference::renderPixels: pixel (" + std::to_string(p.x) + ", " +
                                                  std::to_string(p.y) + ") outside the image");
  const WeatherField field =
      buildWeatherField(inputs.weather, inputs.coarseWeather, weatherAnchorFor(inputs.camera.position));
  const FrameSetup setup = prepareFrame(settings_, inputs, field, tables_->atmosphere);
  CpuCore core(setup, *tables_, field);
  core.setModel(model_);
  const auto frame = core.coreFrame();
  core.buildSunMap(frame);
  core.buildAirTable(frame);
  std::vector<std::array<float, 4>> out;
  out.reserve(pixels.size());
  for (const PixelCoord& p : pixels) {
    const auto r = core.shade(p.x, p.y, frame);
    out.push_back({float(r.radiance.x), float(r.radiance.y), float(r.radiance.z), float(r.transmittance)});
  }
  return out;
}

Result<Image> CpuReference::render(const FrameInputs& inputs, std::uint64_t* densityLookups) const {
  if (auto ok = validateInputs(inputs); !ok) return tl::unexpected(ok.error());
  const WeatherField field =
      buildWeatherField(inputs.weather, inputs.coarseWeather, weatherAnchorFor(inputs.camera.position));
  const FrameSetup setup = prepareFrame(settings_, inputs, field, tables_->atmosphere);
  CpuCore core(setup, *tables_, field);
  core.setModel(model_);
  const auto frame = core.coreFrame();
  core.buildSunMap(frame);
  core.buildAirTable(frame);
  Image image;
  image.width = settings_.width;
  image.height = settings_.height;
  image.rgba.resize(std::size_t(settings_.width) * settings_.height * 4);
  image.cloudDepth_m.resize(std::size_t(settings_.width) * settings_.height);
  for (std::uint32_t y = 0; y < settings_.height; ++y)
    for (std::uint32_t x = 0; x < settings_.width; ++x) {
      const auto r = core.shade(x, y, frame);
      const std::size_t i = std::size_t(y) * settings_.width + x;
      float* out = &image.rgba[i * 4];
      out[0] = float(r.radiance.x);
      out[1] = float(r.radiance.y);
      out[2] = float(r.radiance.z);
      out[3] = float(r.transmittance);
      image.cloudDepth_m[i] = float(r.depth);
    }
  if (densityLookups != nullptr) *densityLookups = core.lookups();
  return image;
}

Result<Image> renderCpuReference(const RenderSettings& settings, const FrameInputs& inputs) {
  auto reference = CpuReference::create(settings);
  if (!reference) return tl::unexpected(reference.error());
  return reference->render(inputs);
}

}  // namespace sky::render
