// Weather map upload and caching (see weather_texture.hpp).
#include "weather_texture.hpp"

#include <span>

#include "sky_shared.h"

namespace sky::render {

Result<WeatherTexture> WeatherTexture::create(const GpuContext& ctx) {
  WeatherTexture t;
  t.image_ = createSampledImage(ctx, vk::ImageType::e2D, vk::Format::eR8G8B8A8Unorm,
                                vk::Extent3D(kWeatherMapSize, kWeatherMapSize, 1), gpu::kMaxLayers * kWeatherRings,
                                "sky.weatherMap");
  t.timer_ = GpuTimer(ctx, 1, "sky.weatherMap.timer");
  t.field_ = buildWeatherField(nullptr, geo::Geodetic{});
  if (auto ok = t.upload(ctx); !ok) return tl::unexpected(ok.error());
  return t;
}

Result<void> WeatherTexture::update(const GpuContext& ctx, const FrameInputs& inputs) {
  lastUploadTimes_.clear();
  const std::uint64_t key = weatherContentKey(inputs.weather);
  const geo::Geodetic anchor = weatherAnchorFor(inputs.camera.position);
  if (!weatherFieldStale(field_, key, anchor)) return {};
  // New weather at the same anchor reuses the texels' cells (no geodesy).
  field_ = buildWeatherField(inputs.weather, anchor, &field_);
  return upload(ctx);
}

Result<void> WeatherTexture::upload(const GpuContext& ctx) {
  ++uploads_;
  if (auto ok = uploadImage(ctx, image_, std::as_bytes(std::span(field_.texels)), &timer_, "weather_upload"); !ok)
    return ok;
  lastUploadTimes_ = timer_.results();
  return {};
}

}  // namespace sky::render
