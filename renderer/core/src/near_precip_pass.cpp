// Near-precipitation pass resources and recording (see near_precip_pass.hpp).
#include "near_precip_pass.hpp"

#include <cstring>
#include <vector>

#include "sky/core/assert.hpp"

namespace sky::render {

Result<NearPrecipPass> NearPrecipPass::create(const GpuContext& ctx, std::uint32_t width, std::uint32_t height,
                                              const GpuBuffer& image) {
  SKY_ASSERT(image.size >= vk::DeviceSize(width) * height * 4 * sizeof(float));
  NearPrecipPass pass;
  pass.width_ = width;
  pass.height_ = height;
  const auto build = [&](const char* name, const char* shader) {
    ComputePipelineBuilder builder(name);
    for (std::uint32_t b : {gpu::kNearPrecipBindingParams, gpu::kNearPrecipBindingImage, gpu::kNearPrecipBindingMean,
                            gpu::kNearPrecipBindingTiles, gpu::kNearPrecipBindingEntries,
                            gpu::kNearPrecipBindingStreaks})
      builder.binding(b, vk::DescriptorType::eStorageBuffer);
    builder.shader(shader);
    return builder.build(ctx);
  };
  auto mean = build("sky.near_precip.mean", "near_precip_mean.comp.spv");
  if (!mean) return tl::unexpected(mean.error());
  pass.meanPipeline_ = std::move(*mean);
  auto streaks = build("sky.near_precip", "near_precip.comp.spv");
  if (!streaks) return tl::unexpected(streaks.error());
  pass.streakPipeline_ = std::move(*streaks);

  const auto storage = vk::BufferUsageFlagBits::eStorageBuffer;
  const vk::DeviceSize tiles = vk::DeviceSize((width + gpu::kNearPrecipTile - 1) / gpu::kNearPrecipTile) *
                               ((height + gpu::kNearPrecipTile - 1) / gpu::kNearPrecipTile);
  pass.params_ = createHostBuffer(ctx, sizeof(gpu::SkyNearPrecip), storage, "sky.near_precip.params");
  pass.mean_ = createHostBuffer(ctx, 4 * sizeof(float), storage, "sky.near_precip.mean");
  pass.tiles_ = createHostBuffer(ctx, tiles * 2 * sizeof(std::uint32_t), storage, "sky.near_precip.tiles");
  pass.entries_ = createHostBuffer(ctx, vk::DeviceSize(kMaxNearEntries) * sizeof(std::uint32_t), storage,
                                   "sky.near_precip.entries");
  pass.streaks_ = createHostBuffer(ctx, vk::DeviceSize(kMaxNearDrops) * sizeof(gpu::SkyStreak), storage,
                                   "sky.near_precip.streaks");
  auto info = [](const GpuBuffer& b) { return vk::DescriptorBufferInfo(*b.buffer, 0, b.size); };
  const std::vector<std::pair<std::uint32_t, vk::DescriptorBufferInfo>> buffers{
      std::pair{gpu::kNearPrecipBindingParams, info(pass.params_)},
      std::pair{gpu::kNearPrecipBindingImage, vk::DescriptorBufferInfo(*image.buffer, 0, image.size)},
      std::pair{gpu::kNearPrecipBindingMean, info(pass.mean_)},
      std::pair{gpu::kNearPrecipBindingTiles, info(pass.tiles_)},
      std::pair{gpu::kNearPrecipBindingEntries, info(pass.entries_)},
      std::pair{gpu::kNearPrecipBindingStreaks, info(pass.streaks_)}};
  pass.meanSet_ = createStorageSet(ctx, pass.meanPipeline_, "sky.near_precip.mean", buffers, {});
  pass.streakSet_ = createStorageSet(ctx, pass.streakPipeline_, "sky.near_precip", buffers, {});
  return pass;
}

void NearPrecipPass::record(const vk::raii::CommandBuffer& commands, GpuTimer& timer, const NearPrecipFrame& frame) {
  SKY_ASSERT(!frame.streaks.empty() && frame.streaks.size() <= kMaxNearDrops);
  SKY_ASSERT(frame.entries.size() <= kMaxNearEntries);
  SKY_ASSERT(frame.tiles.size() * 2 * sizeof(std::uint32_t) == tiles_.size);
  gpu::SkyNearPrecip params{};
  params.size = gpu::uvec4(width_, height_, frame.tilesX, frame.tilesY);
  params.radiance = gpu::vec4(float(frame.population.radianceFactor), 0.0f, 0.0f, 0.0f);
  std::memcpy(params_.mapped, &params, sizeof params);
  std::memcpy(tiles_.mapped, frame.tiles.data(), frame.tiles.size() * sizeof frame.tiles[0]);
  std::memcpy(entries_.mapped, frame.entries.data(), frame.entries.size() * sizeof frame.entries[0]);
  std::memcpy(streaks_.mapped, frame.streaks.data(), frame.streaks.size() * sizeof frame.streaks[0]);
  const auto timed = timer.section(commands, "near-precip");
  // The image's writers (a compute pass) and its readers (the history's copy).
  const vk::MemoryBarrier before(vk::AccessFlagBits::eShaderWrite | vk::AccessFlagBits::eTransferRead,
                                 vk::AccessFlagBits::eShaderRead | vk::AccessFlagBits::eShaderWrite);
  commands.pipelineBarrier(vk::PipelineStageFlagBits::eComputeShader | vk::PipelineStageFlagBits::eTransfer,
                           vk::PipelineStageFlagBits::eComputeShader, {}, before, {}, {});
  commands.bindPipeline(vk::PipelineBindPoint::eCompute, *meanPipeline_.pipeline);
  commands.bindDescriptorSets(vk::PipelineBindPoint::eCompute, *meanPipeline_.layout, 0, *meanSet_.set, {});
  commands.dispatch(1, 1, 1);
  const vk::MemoryBarrier meanWritten(vk::AccessFlagBits::eShaderWrite, vk::AccessFlagBits::eShaderRead);
  commands.pipelineBarrier(vk::PipelineStageFlagBits::eComputeShader, vk::PipelineStageFlagBits::eComputeShader, {},
                           meanWritten, {}, {});
  commands.bindPipeline(vk::PipelineBindPoint::eCompute, *streakPipeline_.pipeline);
  commands.bindDescriptorSets(vk::PipelineBindPoint::eCompute, *streakPipeline_.layout, 0, *streakSet_.set, {});
  commands.dispatch(frame.tilesX, frame.tilesY, 1);
  const vk::MemoryBarrier toHost(vk::AccessFlagBits::eShaderWrite, vk::AccessFlagBits::eHostRead);
  commands.pipelineBarrier(vk::PipelineStageFlagBits::eComputeShader, vk::PipelineStageFlagBits::eHost, {}, toHost, {},
                           {});
}

}  // namespace sky::render
