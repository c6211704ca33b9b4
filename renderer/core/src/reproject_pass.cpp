// Reprojection pass resources and recording (see reproject_pass.hpp).
#include "reproject_pass.hpp"

#include <algorithm>
#include <cstring>
#include <vector>

#include "sky/core/assert.hpp"

namespace sky::render {

Result<ReprojectPass> ReprojectPass::create(const GpuContext& ctx, std::uint32_t width, std::uint32_t height,
                                            const GpuBuffer& fresh, const GpuBuffer& freshDepth) {
  ReprojectPass pass;
  pass.width_ = width;
  pass.height_ = height;
  const auto& device = ctx.device();
  ComputePipelineBuilder builder("sky.reproject");
  for (std::uint32_t b : {gpu::kReprojectBindingParams, gpu::kReprojectBindingFresh, gpu::kReprojectBindingFreshDepth,
                          gpu::kReprojectBindingHistory, gpu::kReprojectBindingHistoryDepth, gpu::kReprojectBindingOut,
                          gpu::kReprojectBindingOutDepth, gpu::kReprojectBindingOutcomes})
    builder.binding(b, vk::DescriptorType::eStorageBuffer);
  builder.shader("reproject.comp.spv");
  auto pipeline = builder.build(ctx);
  if (!pipeline) return tl::unexpected(pipeline.error());
  pass.pipeline_ = std::move(*pipeline);

  const auto storage = vk::BufferUsageFlagBits::eStorageBuffer;
  const vk::DeviceSize pixels = vk::DeviceSize(width) * height;
  pass.params_ = createHostBuffer(ctx, sizeof(gpu::SkyReproject), storage, "sky.reproject.params");
  const char* colourNames[2] = {"sky.reproject.imageA", "sky.reproject.imageB"};
  const char* depthNames[2] = {"sky.reproject.depthA", "sky.reproject.depthB"};
  for (int k = 0; k < 2; ++k) {
    pass.colour_[k] = createHostBuffer(ctx, pixels * 4 * sizeof(float), storage, colourNames[k]);
    pass.depth_[k] = createHostBuffer(ctx, pixels * sizeof(float), storage, depthNames[k]);
    std::memset(pass.colour_[k].mapped, 0, pass.colour_[k].size);
    std::memset(pass.depth_[k].mapped, 0, pass.depth_[k].size);
  }
  pass.outcomes_ = createHostBuffer(ctx, pixels * sizeof(std::uint32_t), storage, "sky.reproject.outcomes");

  const vk::DescriptorPoolSize poolSize(vk::DescriptorType::eStorageBuffer, 16);
  pass.descriptorPool_ = vk::raii::DescriptorPool(
      device, vk::DescriptorPoolCreateInfo(vk::DescriptorPoolCreateFlagBits::eFreeDescriptorSet, 2, poolSize));
  ctx.name(pass.descriptorPool_, "sky.reproject.descriptorPool");
  const std::array<vk::DescriptorSetLayout, 2> layouts{*pass.pipeline_.setLayout, *pass.pipeline_.setLayout};
  vk::raii::DescriptorSets sets(device, vk::DescriptorSetAllocateInfo(*pass.descriptorPool_, layouts));
  for (int k = 0; k < 2; ++k) {
    pass.sets_[k] = std::move(sets[k]);
    ctx.name(pass.sets_[k], k == 0 ? "sky.reproject.setA" : "sky.reproject.setB");
    auto info = [](const GpuBuffer& b) { return vk::DescriptorBufferInfo(*b.buffer, 0, b.size); };
    const std::array infos{std::pair{gpu::kReprojectBindingParams, info(pass.params_)},
                           std::pair{gpu::kReprojectBindingFresh, info(fresh)},
                           std::pair{gpu::kReprojectBindingFreshDepth, info(freshDepth)},
                           std::pair{gpu::kReprojectBindingHistory, info(pass.colour_[1 - k])},
                           std::pair{gpu::kReprojectBindingHistoryDepth, info(pass.depth_[1 - k])},
                           std::pair{gpu::kReprojectBindingOut, info(pass.colour_[k])},
                           std::pair{gpu::kReprojectBindingOutDepth, info(pass.depth_[k])},
                           std::pair{gpu::kReprojectBindingOutcomes, info(pass.outcomes_)}};
    std::vector<vk::WriteDescriptorSet> writes;
    for (const auto& [binding, bufferInfo] : infos)
      writes.emplace_back(*pass.sets_[k], binding, 0, vk::DescriptorType::eStorageBuffer, nullptr, bufferInfo);
    device.updateDescriptorSets(writes, {});
  }
  pass.current_ = 1;  // the first record() writes set 0 and reads buffers 1 (zeros; unused: no history)
  return pass;
}

void ReprojectPass::record(const vk::raii::CommandBuffer& commands, GpuTimer& timer, const gpu::SkyReproject& params) {
  SKY_ASSERT(params.image.x == width_ && params.image.y == height_);
  current_ = 1 - current_;
  std::memcpy(params_.mapped, &params, sizeof params);
  const vk::MemoryBarrier cloudsWritten(vk::AccessFlagBits::eShaderWrite, vk::AccessFlagBits::eShaderRead);
  commands.pipelineBarrier(vk::PipelineStageFlagBits::eComputeShader, vk::PipelineStageFlagBits::eComputeShader, {},
                           cloudsWritten, {}, {});
  {
    const auto timed = timer.section(commands, "reproject");
    commands.bindPipeline(vk::PipelineBindPoint::eCompute, *pipeline_.pipeline);
    commands.bindDescriptorSets(vk::PipelineBindPoint::eCompute, *pipeline_.layout, 0, *sets_[current_], {});
    const std::uint32_t gx = gpu::kReprojectLocalSizeX, gy = gpu::kReprojectLocalSizeY;
    commands.dispatch((width_ + gx - 1) / gx, (height_ + gy - 1) / gy, 1);
  }
  const vk::MemoryBarrier toHost(vk::AccessFlagBits::eShaderWrite, vk::AccessFlagBits::eHostRead);
  commands.pipelineBarrier(vk::PipelineStageFlagBits::eComputeShader, vk::PipelineStageFlagBits::eHost, {}, toHost,
                           {}, {});
}

Image ReprojectPass::readBack() const { return readImage(colour_[current_], depth_[current_], width_, height_); }

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
