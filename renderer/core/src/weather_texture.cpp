// Weather map upload and caching (see weather_texture.hpp).
#include "weather_texture.hpp"

#include <cstring>
#include <span>

#include "sky_shared.h"

namespace sky::render {

Result<WeatherTexture> WeatherTexture::create(const GpuContext& ctx) {
  WeatherTexture t;
  // Cover and wind: two layers per ring and slice.
  t.image_ = createSampledImage(ctx, vk::ImageType::e2D, vk::Format::eR8G8B8A8Unorm,
                                vk::Extent3D(kWeatherMapSize, kWeatherMapSize, 1), 2 * gpu::kMaxLayers * kWeatherRings,
                                "sky.weatherMap");
  t.timer_ = GpuTimer(ctx, 1, "sky.weatherMap.timer");
  if (auto ok = t.uploadWhole(ctx); !ok) return tl::unexpected(ok.error());
  return t;
}

Result<void> WeatherTexture::update(const GpuContext& ctx, const FrameInputs& inputs) {
  lastUploadTimes_.clear();
  lastUpdate_ = {};
  lastRects_.clear();
  const WeatherFieldChange change =
      updater_.update(inputs.weather, inputs.coarseWeather, weatherAnchorFor(inputs.camera.position),
                      inputs.weatherVersion);
  lastUpdate_.texelsRewritten = change.texelsRewritten;
  // After a failed upload the image may lag the field anywhere: whole again.
  if (imageBehind_ && change.kind != WeatherFieldChange::Kind::Rebuilt) {
    lastUpdate_.rebuilt = true;
    lastUpdate_.reason = "the last upload failed";
    return uploadWhole(ctx);
  }
  switch (change.kind) {
    case WeatherFieldChange::Kind::Unchanged:
      return {};
    case WeatherFieldChange::Kind::Rebuilt:
      lastUpdate_.rebuilt = true;
      lastUpdate_.reason = change.reason;
      return uploadWhole(ctx);
    case WeatherFieldChange::Kind::Tiles: {
      lastRects_ = change.dirty;
      lastUpdate_.largestStep = change.largestStep;
      std::vector<TexelRect> rects = change.dirty;
      rects.insert(rects.end(), change.windDirty.begin(), change.windDirty.end());
      return uploadRects(ctx, rects);
    }
  }
  return {};
}

Result<void> WeatherTexture::uploadWhole(const GpuContext& ctx) {
  ++uploads_;
  const auto& texels = updater_.field().texels;
  imageBehind_ = true;
  if (auto ok = uploadImage(ctx, image_, std::as_bytes(std::span(texels)), &timer_, "weather_upload"); !ok)
    return ok;
  imageBehind_ = false;
  lastUpdate_.bytesUploaded = texels.size();
  lastUploadTimes_ = timer_.results();
  return {};
}

Result<void> WeatherTexture::uploadRects(const GpuContext& ctx, const std::vector<TexelRect>& rects) {
  if (rects.empty()) return {};  // the tiles that changed cover no texel's centre
  ++uploads_;
  const WeatherField& field = updater_.field();
  // Each rectangle's rows, one after another, in one staging buffer.
  std::vector<ImageRegion> regions;
  std::vector<std::byte> packed;
  for (const TexelRect& r : rects) {
    regions.push_back({r.layer, r.x, r.y, r.width, r.height, packed.size()});
    const std::size_t rowBytes = std::size_t(r.width) * kWeatherChannels;
    for (std::uint32_t row = r.y; row < r.y + r.height; ++row) {
      const std::size_t from = ((std::size_t(r.layer) * field.size + row) * field.size + r.x) * kWeatherChannels;
      const std::size_t at = packed.size();
      packed.resize(at + rowBytes);
      std::memcpy(packed.data() + at, field.texels.data() + from, rowBytes);
    }
  }
  imageBehind_ = true;
  if (auto ok = uploadImageRegions(ctx, image_, packed, regions, &timer_, "weather_upload"); !ok) return ok;
  imageBehind_ = false;
  lastUpdate_.bytesUploaded = packed.size();
  lastUploadTimes_ = timer_.results();
  return {};
}

}  // namespace sky::render
