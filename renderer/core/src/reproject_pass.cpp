// Reprojection pass resources and recording (see reproject_pass.hpp).
#include "reproject_pass.hpp"

#include <algorithm>
#include <cstring>
#include <vector>

#include "fresh_edges.hpp"
#include "history_drop.hpp"
#include "sky/core/assert.hpp"

namespace sky::render {

Result<ReprojectPass> ReprojectPass::create(const GpuContext& ctx, std::uint32_t width, std::uint32_t height,
                                            const GpuBuffer& fresh, const GpuBuffer& freshDepth, bool historyClip,
                                            bool sharpHistory, bool freshEdges,
                                            const vk::DescriptorImageInfo& weather) {
  ReprojectPass pass;
  pass.width_ = width;
  pass.height_ = height;
  ComputePipelineBuilder builder("sky.reproject");
  for (std::uint32_t b : {gpu::kReprojectBindingParams, gpu::kReprojectBindingOut, gpu::kReprojectBindingOutDepth,
                          gpu::kReprojectBindingOutcomes, gpu::kReprojectBindingDrop})
    builder.binding(b, vk::DescriptorType::eStorageBuffer);
  // What it gathers from, as images (pixel_mirror.hpp).
  for (std::uint32_t b : {gpu::kReprojectBindingFresh, gpu::kReprojectBindingFreshDepth, gpu::kReprojectBindingHistory,
                          gpu::kReprojectBindingHistoryDepth})
    builder.binding(b, vk::DescriptorType::eStorageImage);
  builder.binding(gpu::kReprojectBindingWeather, vk::DescriptorType::eCombinedImageSampler);
  builder.shader("reproject.comp.spv");
  // The history clip's code only where it is used: lavapipe runs a branch
  // for every lane whatever the condition, so a uniform "off" still pays.
  builder.constants({historyClip ? 1u : 0u, sharpHistory ? 1u : 0u, freshEdges ? 1u : 0u});
  auto pipeline = builder.build(ctx);
  if (!pipeline) return tl::unexpected(pipeline.error());
  pass.pipeline_ = std::move(*pipeline);

  const auto storage = vk::BufferUsageFlagBits::eStorageBuffer;
  const vk::DeviceSize pixels = vk::DeviceSize(width) * height;
  pass.freshBuffers_ = {*fresh.buffer, *freshDepth.buffer};
  auto freshMirror = PixelMirror::create(ctx, width, height, "sky.reproject.fresh");
  if (!freshMirror) return tl::unexpected(freshMirror.error());
  pass.fresh_.emplace(std::move(*freshMirror));
  auto historyMirror = PixelMirror::create(ctx, width, height, "sky.reproject.history");
  if (!historyMirror) return tl::unexpected(historyMirror.error());
  pass.history_.emplace(std::move(*historyMirror));
  pass.params_ = createHostBuffer(ctx, sizeof(gpu::SkyReproject), storage, "sky.reproject.params");
  // Transfer sources: copied into the history images.
  const auto usage = storage | vk::BufferUsageFlagBits::eTransferSrc;
  pass.colour_ = createHostBuffer(ctx, pixels * 4 * sizeof(float), usage, "sky.reproject.image");
  pass.depth_ = createHostBuffer(ctx, pixels * sizeof(float), usage, "sky.reproject.depth");
  pass.outcomes_ = createHostBuffer(ctx, pixels * sizeof(std::uint32_t), storage, "sky.reproject.outcomes");
  const std::uint32_t cell = 1u << kHistoryDropCellShift;
  const vk::DeviceSize cells = vk::DeviceSize((width + cell - 1) / cell) * ((height + cell - 1) / cell);
  pass.drop_ = createHostBuffer(ctx, cells * sizeof(std::uint32_t), storage, "sky.reproject.drop");
  std::memset(pass.drop_.mapped, 0, pass.drop_.size);

  auto info = [](const GpuBuffer& b) { return vk::DescriptorBufferInfo(*b.buffer, 0, b.size); };
  const std::vector<std::pair<std::uint32_t, vk::DescriptorBufferInfo>> buffers{
      std::pair{gpu::kReprojectBindingParams, info(pass.params_)},
      std::pair{gpu::kReprojectBindingOut, info(pass.colour_)},
      std::pair{gpu::kReprojectBindingOutDepth, info(pass.depth_)},
      std::pair{gpu::kReprojectBindingOutcomes, info(pass.outcomes_)},
      std::pair{gpu::kReprojectBindingDrop, info(pass.drop_)}};
  // The history images hold zeros until the first record() (unused then: no history).
  const std::vector<std::pair<std::uint32_t, vk::DescriptorImageInfo>> images{
      std::pair{gpu::kReprojectBindingFresh, pass.fresh_->colourInfo()},
      std::pair{gpu::kReprojectBindingFreshDepth, pass.fresh_->depthInfo()},
      std::pair{gpu::kReprojectBindingHistory, pass.history_->colourInfo()},
      std::pair{gpu::kReprojectBindingHistoryDepth, pass.history_->depthInfo()}};
  pass.set_ = createStorageSet(ctx, pass.pipeline_, "sky.reproject", buffers, images,
                               {std::pair{gpu::kReprojectBindingWeather, weather}});
  return pass;
}

void ReprojectPass::record(const vk::raii::CommandBuffer& commands, GpuTimer& timer, const gpu::SkyReproject& params,
                           std::span<const std::uint32_t> dropCells) {
  SKY_ASSERT(params.image.x == width_ && params.image.y == height_);
  std::memcpy(params_.mapped, &params, sizeof params);
  if (params.drop.w != 0) {
    SKY_ASSERT(params.drop.z == kHistoryDropCellShift);
    SKY_ASSERT(dropCells.size() == std::size_t(params.drop.x) * params.drop.y);
    SKY_ASSERT(dropCells.size_bytes() <= drop_.size);
    std::memcpy(drop_.mapped, dropCells.data(), dropCells.size_bytes());
  }
  // The pixels the cloud pass drew, packed n x n (n = params.image.z), then
  // the fresh edges' in the rows after them.
  const std::uint32_t n = std::max(params.image.z, 1u);
  const std::uint32_t packedW = params.phase.z;
  const std::uint32_t edgePixels =
      FreshEdges{}.freshEdgeCount(glm::uvec4(params.freshEdges), glm::uvec2(width_, height_));
  const std::uint32_t rows = (height_ + n - 1) / n + (edgePixels + packedW - 1) / packedW;
  SKY_ASSERT(rows <= height_);
  {
    const auto timed = timer.section(commands, "reproject");
    fresh_->record(commands, freshBuffers_.first, freshBuffers_.second, packedW, rows);
    commands.bindPipeline(vk::PipelineBindPoint::eCompute, *pipeline_.pipeline);
    commands.bindDescriptorSets(vk::PipelineBindPoint::eCompute, *pipeline_.layout, 0, *set_.set, {});
    const std::uint32_t gx = gpu::kReprojectLocalSizeX, gy = gpu::kReprojectLocalSizeY;
    commands.dispatch((width_ + gx - 1) / gx, (height_ + gy - 1) / gy, 1);
    // This frame's image is the next frame's history (and the upscale's source).
    history_->record(commands, *colour_.buffer, *depth_.buffer, width_, height_);
  }
  const vk::MemoryBarrier toHost(vk::AccessFlagBits::eShaderWrite, vk::AccessFlagBits::eHostRead);
  commands.pipelineBarrier(vk::PipelineStageFlagBits::eComputeShader, vk::PipelineStageFlagBits::eHost, {}, toHost, {},
                           {});
}

Result<void> ReprojectPass::prepareDownsample(const GpuContext& ctx, const GpuBuffer& colour, const GpuBuffer& depth,
                                              std::uint32_t fullWidth, std::uint32_t fullHeight, std::uint32_t box) {
  SKY_ASSERT(box >= 1 && (fullWidth + box - 1) / box == width_ && (fullHeight + box - 1) / box == height_);
  SKY_ASSERT(colour.size >= vk::DeviceSize(fullWidth) * fullHeight * 4 * sizeof(float));
  SKY_ASSERT(depth.size >= vk::DeviceSize(fullWidth) * fullHeight * sizeof(float));
  if (!downsample_) {
    ComputePipelineBuilder builder("sky.history_downsample");
    for (std::uint32_t b : {gpu::kDownsampleBindingParams, gpu::kDownsampleBindingSource,
                            gpu::kDownsampleBindingSourceDepth})
      builder.binding(b, vk::DescriptorType::eStorageBuffer);
    for (std::uint32_t b : {gpu::kDownsampleBindingHistory, gpu::kDownsampleBindingHistoryDepth})
      builder.binding(b, vk::DescriptorType::eStorageImage);
    builder.shader("history_downsample.comp.spv");
    auto pipeline = builder.build(ctx);
    if (!pipeline) return tl::unexpected(pipeline.error());
    downsample_.emplace(Downsample{std::move(*pipeline),
                                   createHostBuffer(ctx, sizeof(gpu::SkyHistoryDownsample),
                                                    vk::BufferUsageFlagBits::eStorageBuffer,
                                                    "sky.history_downsample.params"),
                                   {}});
  }
  gpu::SkyHistoryDownsample p{};
  p.size = gpu::uvec4(width_, height_, fullWidth, fullHeight);
  p.mode = gpu::uvec4(box, 0u, 0u, 0u);
  std::memcpy(downsample_->params.mapped, &p, sizeof p);
  auto info = [](const GpuBuffer& b) { return vk::DescriptorBufferInfo(*b.buffer, 0, b.size); };
  // A new set for this source (a change of level is rare; the old set is
  // unused once the last run's fence was waited for).
  downsample_->set = createStorageSet(ctx, downsample_->pipeline, "sky.history_downsample",
                                      {std::pair{gpu::kDownsampleBindingParams, info(downsample_->params)},
                                       std::pair{gpu::kDownsampleBindingSource, info(colour)},
                                       std::pair{gpu::kDownsampleBindingSourceDepth, info(depth)}},
                                      {std::pair{gpu::kDownsampleBindingHistory, history_->colourInfo()},
                                       std::pair{gpu::kDownsampleBindingHistoryDepth, history_->depthInfo()}});
  return {};
}

void ReprojectPass::recordDownsample(const vk::raii::CommandBuffer& commands) {
  SKY_ASSERT(downsample_.has_value());
  commands.bindPipeline(vk::PipelineBindPoint::eCompute, *downsample_->pipeline.pipeline);
  commands.bindDescriptorSets(vk::PipelineBindPoint::eCompute, *downsample_->pipeline.layout, 0,
                              *downsample_->set.set, {});
  const std::uint32_t g = gpu::kDownsampleLocalSize;
  commands.dispatch((width_ + g - 1) / g, (height_ + g - 1) / g, 1);
  // The history images are read by this frame's reprojection.
  const vk::MemoryBarrier written(vk::AccessFlagBits::eShaderWrite, vk::AccessFlagBits::eShaderRead);
  commands.pipelineBarrier(vk::PipelineStageFlagBits::eComputeShader, vk::PipelineStageFlagBits::eComputeShader, {},
                           written, {}, {});
}

Image ReprojectPass::readBack() const { return readImage(colour_, depth_, width_, height_); }

TemporalReport ReprojectPass::counts() const {
  std::uint64_t c[gpu::kReprojectStatCount + 1] = {};
  const auto* outcomes = static_cast<const std::uint32_t*>(outcomes_.mapped);
  for (std::size_t i = 0, n = std::size_t(width_) * height_; i < n; ++i)
    ++c[std::min<std::uint32_t>(outcomes[i], gpu::kReprojectStatCount)];
  TemporalReport r;
  r.drawn = c[gpu::kStatFresh];
  r.reused = c[gpu::kStatReused];
  r.offscreen = c[gpu::kStatOffscreen];
  r.disoccluded = c[gpu::kStatDisoccluded];
  return r;
}

}  // namespace sky::render
