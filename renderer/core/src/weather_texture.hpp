// The weather map on the GPU: a fixed-size RGBA8 2D array (one slice per cloud
// layer and ring) and the CPU field it was uploaded from. Rebuilt and
// re-uploaded only when the snapshot's content changes (at the same anchor
// reusing the texels' cells) or the camera's anchor moves (kWeatherAnchorLattice_m).
#pragma once

#include <cstdint>

#include "gpu_context.hpp"
#include "gpu_memory.hpp"
#include "gpu_timer.hpp"
#include "sky/render/cloud_renderer.hpp"
#include "weather_field.hpp"

namespace sky::render {

class WeatherTexture {
 public:
  // Creates the image and uploads an empty (clear-sky) map. Vulkan failures throw.
  static Result<WeatherTexture> create(const GpuContext& ctx);

  // Makes the map current for these inputs (validated). Errors from the upload.
  Result<void> update(const GpuContext& ctx, const FrameInputs& inputs);

  const WeatherField& field() const { return field_; }
  const GpuImage& image() const { return image_; }
  std::uint64_t uploads() const { return uploads_; }
  // GPU time of the upload done by the last update(); empty when it uploaded nothing.
  const std::vector<PassTime>& lastUploadTimes() const { return lastUploadTimes_; }

 private:
  WeatherTexture() = default;
  Result<void> upload(const GpuContext& ctx);

  GpuImage image_;
  GpuTimer timer_;
  WeatherField field_;
  std::uint64_t uploads_ = 0;
  std::vector<PassTime> lastUploadTimes_;
};

}  // namespace sky::render
