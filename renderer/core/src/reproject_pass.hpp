// The reprojection pass (shaders/reproject.comp): recorded after the cloud
// pass in the same command buffer, it reads the pixels the clouds drew this
// frame and the previous frame's full image, and writes this frame's full
// image (radiance + transmittance, cloud depth) into host-visible buffers.
// What it reads, it reads from copies in storage images (pixel_mirror.hpp):
// the drawn pixels, and the previous frame's image, which each record()
// copies its own output into for the next frame (and for the upscale). An
// outcome per pixel says what became of it (reproject_shared.h), counted on
// the host.
#pragma once

#include <cstdint>
#include <optional>
#include <span>
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
  // SPIR-V; other Vulkan failures throw. historyClip: compile the history
  // clip in (TemporalSettings::historyClip > 0); sharpHistory: resample the
  // history with Catmull-Rom weights (TemporalSettings::sharpHistory);
  // freshEdges: read the fresh edges' samples (TemporalSettings::freshEdges).
  // `weather`: the cloud pass's weather texture (CloudPass::weatherDescriptor).
  static Result<ReprojectPass> create(const GpuContext& ctx, std::uint32_t width, std::uint32_t height,
                                      const GpuBuffer& fresh, const GpuBuffer& freshDepth, bool historyClip,
                                      bool sharpHistory, bool freshEdges, const vk::DescriptorImageInfo& weather);

  // Records the copy of the cloud pass's pixels, the pass, the copy of its
  // output into image() and the barrier that makes the output readable by
  // the host. The block and the history-drop mask (its cells, when
  // params.drop.w is set: params.drop.x * params.drop.y of them) are copied now.
  void record(const vk::raii::CommandBuffer& commands, GpuTimer& timer, const gpu::SkyReproject& params,
              std::span<const std::uint32_t> dropCells = {});
  // Records the copy of another pass's image of this size (radiance +
  // transmittance and cloud depth buffers, width x height each) into the
  // history, as if the last record() had written it: the next record()
  // reprojects it. A frame budget's change of the way of drawing
  // (CloudRenderer::setLevel) keeps its history this way.
  void seedHistory(const vk::raii::CommandBuffer& commands, vk::Buffer colour, vk::Buffer depth) {
    history_->record(commands, colour, depth, width_, height_);
  }
  // Prepares the history from another size for the next run: the last
  // frame's full image (radiance + transmittance and cloud depth buffers,
  // fullWidth x fullHeight, which must hold it until then) boxed down by
  // `box` each way, 1 a copy (shaders/history_downsample.comp), as if the
  // last record() had written it. Builds its pipeline at the first call. Errors:
  // Io/Malformed for the SPIR-V; other Vulkan failures throw.
  Result<void> prepareDownsample(const GpuContext& ctx, const GpuBuffer& colour, const GpuBuffer& depth,
                                 std::uint32_t fullWidth, std::uint32_t fullHeight, std::uint32_t box);
  // Records what prepareDownsample prepared, before this frame's record().
  void recordDownsample(const vk::raii::CommandBuffer& commands);
  // After the submission completed: the image the last record() wrote, and
  // what became of its pixels.
  Image readBack() const;
  TemporalReport counts() const;
  // The image the last record() wrote, in storage images: the next
  // record()'s history, and what the upscale reads.
  const PixelMirror& image() const { return *history_; }
  // The image it writes for the host (copied into image() as it is recorded).
  const GpuBuffer& output() const { return colour_; }
  const GpuBuffer& depth() const { return depth_; }

 private:
  ReprojectPass() = default;

  ComputePipeline pipeline_;
  GpuBuffer params_;
  std::pair<vk::Buffer, vk::Buffer> freshBuffers_;  // the cloud pass's output (its handles: the pass moves)
  std::optional<PixelMirror> fresh_;    // its copy, read by the shader
  std::optional<PixelMirror> history_;  // the last image written, read by the shader as the history
  GpuBuffer colour_;                    // the image it writes (read back by the host)
  GpuBuffer depth_;
  GpuBuffer outcomes_;  // uint per pixel: what became of it (kStat*)
  GpuBuffer drop_;      // uint per cell of the history-drop mask (history_drop.hpp)
  StorageSet set_;
  // The history from an image of another size (prepareDownsample).
  struct Downsample {
    ComputePipeline pipeline;
    GpuBuffer params;
    StorageSet set;  // bound to the last source prepared
  };
  std::optional<Downsample> downsample_;
  std::uint32_t width_ = 0, height_ = 0;
};

}  // namespace sky::render
