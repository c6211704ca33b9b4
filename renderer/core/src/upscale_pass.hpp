// The upscale pass (shaders/upscale.comp): recorded after the cloud pass (and
// the reprojection) in the same command buffer when the clouds are drawn at a
// fraction of the image size (ResolutionSettings). It reads the small image
// and its cloud depth and writes the full-size image, which is what the
// renderer returns.
#pragma once

#include <cstdint>
#include <optional>
#include <utility>

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
  // What it upscales, smallWidth x smallHeight, read from storage images
  // (pixel_mirror.hpp): either images another pass keeps up to date (the
  // reprojection's image(), which must outlive the pass), or the cloud
  // pass's output buffers (radiance + transmittance, cloud depth), which
  // the pass copies into images of its own at each record().
  struct Input {
    const PixelMirror* images = nullptr;
    std::pair<const GpuBuffer*, const GpuBuffer*> buffers{nullptr, nullptr};  // when images is null
  };

  // Errors: Io/Malformed for the SPIR-V; other Vulkan failures throw.
  static Result<UpscalePass> create(const GpuContext& ctx, std::uint32_t smallWidth, std::uint32_t smallHeight,
                                    std::uint32_t width, std::uint32_t height, const Input& input);

  // Records (with buffers as input, their copy after a barrier on their
  // writes) the pass and the barrier that makes the output readable by the
  // host.
  void record(const vk::raii::CommandBuffer& commands, GpuTimer& timer, const gpu::SkyUpscale& params);
  // After the submission completed: the full-size image.
  Image readBack() const;
  // The full-size image's buffer.
  const GpuBuffer& output() const { return colour_; }
  const GpuBuffer& depth() const { return depth_; }

 private:
  UpscalePass() = default;

  ComputePipeline pipeline_;
  GpuBuffer params_;
  GpuBuffer colour_;
  GpuBuffer depth_;
  std::pair<vk::Buffer, vk::Buffer> sourceBuffers_;  // with buffers as input: their handles (the owner moves)
  std::optional<PixelMirror> ownImages_;              // with buffers as input: their copy
  StorageSet set_;
  std::uint32_t smallWidth_ = 0, smallHeight_ = 0;
  std::uint32_t width_ = 0, height_ = 0;  // the full size
};

// The block for one frame: the camera and Earth as the cloud pass sees them
// (its frame block), the two sizes (the full one width x height) and the mode.
gpu::SkyUpscale upscaleParams(const gpu::SkyFrame& frame, const ResolutionSettings& resolution, std::uint32_t width,
                              std::uint32_t height);

}  // namespace sky::render
