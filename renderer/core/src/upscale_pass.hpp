// The upscale pass (shaders/upscale.comp): recorded after the cloud pass (and
// the reprojection) in the same command buffer when the clouds are drawn at a
// fraction of the image size (ResolutionSettings). It reads the small image
// and its cloud depth and writes the full-size image, which is what the
// renderer returns.
#pragma once

#include <cstdint>
#include <optional>
#include <utility>
#include <vector>

#include "compute_pipeline.hpp"
#include "gpu_context.hpp"
#include "gpu_memory.hpp"
#include "gpu_timer.hpp"
#include "pixel_mirror.hpp"
#include "sky/render/cloud_renderer.hpp"
#include "sky_shared.h"
#include "upscale_shared.h"

namespace sky::render {

class UpscalePass {
 public:
  // A source: the buffers of one small image (radiance + transmittance,
  // cloud depth; smallWidth * smallHeight entries each), which must outlive
  // the pass; the reprojection's output alternates between two. The pass
  // reads a copy of the one it is told in storage images (pixel_mirror.hpp).
  using Source = std::pair<const GpuBuffer*, const GpuBuffer*>;

  // Errors: Io/Malformed for the SPIR-V; other Vulkan failures throw.
  static Result<UpscalePass> create(const GpuContext& ctx, std::uint32_t smallWidth, std::uint32_t smallHeight,
                                    std::uint32_t width, std::uint32_t height, const std::vector<Source>& sources);

  // Records the copy of sources[source] (after a barrier on its writes),
  // the pass over it and the barrier that makes the output readable by the
  // host.
  void record(const vk::raii::CommandBuffer& commands, GpuTimer& timer, std::size_t source,
              const gpu::SkyUpscale& params);
  // After the submission completed: the full-size image.
  Image readBack() const;

 private:
  UpscalePass() = default;

  ComputePipeline pipeline_;
  GpuBuffer params_;
  GpuBuffer colour_;
  GpuBuffer depth_;
  std::vector<std::pair<vk::Buffer, vk::Buffer>> sources_;  // the sources' handles
  std::optional<PixelMirror> source_;                       // the copy of the one being upscaled
  vk::raii::DescriptorPool descriptorPool_{nullptr};
  vk::raii::DescriptorSet set_{nullptr};
  std::uint32_t smallWidth_ = 0, smallHeight_ = 0;
  std::uint32_t width_ = 0, height_ = 0;  // the full size
};

// The block for one frame: the camera and Earth as the cloud pass sees them
// (its frame block), the two sizes (the full one width x height) and the mode.
gpu::SkyUpscale upscaleParams(const gpu::SkyFrame& frame, const ResolutionSettings& resolution, std::uint32_t width,
                              std::uint32_t height);

}  // namespace sky::render
