// The near-precipitation pass (shaders/near_precip_mean.comp, then
// near_precip.comp): recorded last in the frame's command buffer, after
// every pass that writes the image the renderer returns, and only in a
// frame with drops to draw. It takes the image's mean radiance, then draws
// the frame's streaks (near_precip.hpp) over the image in place. Nothing
// that a later frame reads is changed: the reprojection has copied its
// history out of the image before this pass runs.
#pragma once

#include <cstdint>

#include "compute_pipeline.hpp"
#include "gpu_context.hpp"
#include "gpu_memory.hpp"
#include "gpu_timer.hpp"
#include "near_precip.hpp"

namespace sky::render {

class NearPrecipPass {
 public:
  // image: the frame's last image, width x height vec4 (radiance +
  // transmittance), which must outlive the pass.
  // Errors: Io/Malformed for the SPIR-V; other Vulkan failures throw.
  static Result<NearPrecipPass> create(const GpuContext& ctx, std::uint32_t width, std::uint32_t height,
                                       const GpuBuffer& image);

  // Records a barrier on the image's earlier writes and reads (the passes
  // before, the history's copy), the two dispatches, and the barrier that
  // makes the image readable by the host. frame must have streaks and be
  // for this pass's size.
  void record(const vk::raii::CommandBuffer& commands, GpuTimer& timer, const NearPrecipFrame& frame);

 private:
  NearPrecipPass() = default;

  // Destroyed in reverse order: the sets before the buffers they bind and
  // the pipelines whose layouts they follow.
  ComputePipeline meanPipeline_;
  ComputePipeline streakPipeline_;
  GpuBuffer params_;
  GpuBuffer mean_;
  GpuBuffer tiles_;
  GpuBuffer entries_;
  GpuBuffer streaks_;
  StorageSet meanSet_;
  StorageSet streakSet_;
  std::uint32_t width_ = 0, height_ = 0;
};

}  // namespace sky::render
