// The reprojection pass (shaders/reproject.comp): recorded after the cloud
// pass in the same command buffer, it reads the pixels the clouds drew this
// frame and the previous frame's full image, and writes this frame's full
// image, which the next frame reads as its history. It writes two image
// buffers (radiance + transmittance, cloud depth) in turn; what it reads
// (the drawn pixels, the history) it reads from copies in storage images
// (pixel_mirror.hpp). An outcome per pixel says what became of it
// (reproject_shared.h), counted on the host.
#pragma once

#include <array>
#include <optional>
#include <cstdint>
#include <utility>

#include "compute_pipeline.hpp"
#include "gpu_context.hpp"
#include "gpu_memory.hpp"
#include "gpu_timer.hpp"
#include "pixel_mirror.hpp"
#include "reproject_shared.h"
#include "sky/render/cloud_renderer.hpp"

namespace sky::render {

class ReprojectPass {
 public:
  // fresh and freshDepth: the cloud pass's output buffers (width * height
  // entries; they must outlive the pass). Errors: Io/Malformed for the
  // SPIR-V; other Vulkan failures throw.
  static Result<ReprojectPass> create(const GpuContext& ctx, std::uint32_t width, std::uint32_t height,
                                      const GpuBuffer& fresh, const GpuBuffer& freshDepth);

  // Records the pass (after a barrier on the cloud pass's writes) and the
  // barrier that makes its output readable by the host. The block is copied
  // now; the output buffers swap at the next record().
  void record(const vk::raii::CommandBuffer& commands, GpuTimer& timer, const gpu::SkyReproject& params);
  // After the submission completed: the image the last record() wrote, and
  // what became of its pixels.
  Image readBack() const;
  TemporalReport counts() const;
  // The two full images it writes in turn (k = 0, 1: radiance +
  // transmittance, cloud depth), and which of them the last record() wrote.
  std::pair<const GpuBuffer*, const GpuBuffer*> output(std::uint32_t k) const { return {&colour_[k], &depth_[k]}; }
  std::uint32_t current() const { return current_; }

 private:
  ReprojectPass() = default;

  ComputePipeline pipeline_;
  GpuBuffer params_;
  std::pair<vk::Buffer, vk::Buffer> freshBuffers_;  // the cloud pass's output (its handles: the pass moves)
  std::optional<PixelMirror> fresh_;    // its copy, read by the shader
  std::optional<PixelMirror> history_;  // the last image written, read by the shader as the history
  std::array<GpuBuffer, 2> colour_;  // full images; [current_] is written, the other read
  std::array<GpuBuffer, 2> depth_;
  GpuBuffer outcomes_;  // uint per pixel: what became of it (kStat*)
  vk::raii::DescriptorPool descriptorPool_{nullptr};
  std::array<vk::raii::DescriptorSet, 2> sets_{nullptr, nullptr};  // [k] writes colour_[k], reads the other
  std::uint32_t width_ = 0, height_ = 0;
  std::uint32_t current_ = 0;  // the buffers the last record() wrote
};

}  // namespace sky::render
