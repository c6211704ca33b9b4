// The weather map on the GPU: a fixed-size RGBA8 2D array (one slice per cloud
// layer and ring) and the CPU field it was uploaded from. Rebuilt and
// uploaded whole when the camera's anchor moves (kWeatherAnchorLattice_m) or
// the snapshots change in more than tiles; when only tiles changed or came,
// their texels are rewritten (WeatherFieldUpdater) and, per array layer,
// the rectangle around them uploaded.
#pragma once

#include <cstdint>

#include "gpu_context.hpp"
#include "gpu_memory.hpp"
#include "gpu_timer.hpp"
#include "sky/render/cloud_renderer.hpp"
#include "weather_field.hpp"
#include "weather_field_update.hpp"

namespace sky::render {

class WeatherTexture {
 public:
  // Creates the image and uploads an empty (clear-sky) map. Vulkan failures throw.
  static Result<WeatherTexture> create(const GpuContext& ctx);

  // Makes the map current for these inputs (validated): inputs.weather and
  // inputs.coarseWeather around the camera's anchor. Errors from the upload.
  Result<void> update(const GpuContext& ctx, const FrameInputs& inputs);

  const WeatherField& field() const { return updater_.field(); }
  const GpuImage& image() const { return image_; }
  // Uploads so far, whole or partial: a change of it means the map changed.
  std::uint64_t uploads() const { return uploads_; }
  // GPU time of the upload done by the last update(); empty when it uploaded nothing.
  const std::vector<PassTime>& lastUploadTimes() const { return lastUploadTimes_; }
  // What the last update() did: rebuilt or not, texels rewritten, bytes uploaded.
  const WeatherMapReport& lastUpdate() const { return lastUpdate_; }
  // The texel rectangles the last update() rewrote and uploaded, when it
  // did not rebuild (empty otherwise).
  const std::vector<TexelRect>& lastRects() const { return lastRects_; }

 private:
  WeatherTexture() = default;
  Result<void> uploadWhole(const GpuContext& ctx);
  Result<void> uploadRects(const GpuContext& ctx, const std::vector<TexelRect>& rects);

  GpuImage image_;
  GpuTimer timer_;
  WeatherFieldUpdater updater_;
  std::uint64_t uploads_ = 0;
  std::vector<PassTime> lastUploadTimes_;
  WeatherMapReport lastUpdate_;
  std::vector<TexelRect> lastRects_;
  bool imageBehind_ = false;  // an upload failed: the image may not hold the field
};

}  // namespace sky::render
