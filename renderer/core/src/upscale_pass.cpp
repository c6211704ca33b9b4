// Upscale pass resources and recording (see upscale_pass.hpp).
#include "upscale_pass.hpp"

#include <array>
#include <cstring>

#include "sky/core/assert.hpp"

namespace sky::render {

Result<UpscalePass> UpscalePass::create(const GpuContext& ctx, std::uint32_t smallWidth, std::uint32_t smallHeight,
                                        std::uint32_t width, std::uint32_t height, const std::vector<Source>& sources) {
  SKY_ASSERT(!sources.empty() && smallWidth <= width && smallHeight <= height);
  UpscalePass pass;
  pass.width_ = width;
  pass.height_ = height;
  const auto& device = ctx.device();
  ComputePipelineBuilder builder("sky.upscale");
  for (std::uint32_t b : {gpu::kUpscaleBindingParams, gpu::kUpscaleBindingSource, gpu::kUpscaleBindingSourceDepth,
                          gpu::kUpscaleBindingOut, gpu::kUpscaleBindingOutDepth})
    builder.binding(b, vk::DescriptorType::eStorageBuffer);
  builder.shader("upscale.comp.spv");
  auto pipeline = builder.build(ctx);
  if (!pipeline) return tl::unexpected(pipeline.error());
  pass.pipeline_ = std::move(*pipeline);

  const auto storage = vk::BufferUsageFlagBits::eStorageBuffer;
  const vk::DeviceSize pixels = vk::DeviceSize(pass.width_) * pass.height_;
  pass.params_ = createHostBuffer(ctx, sizeof(gpu::SkyUpscale), storage, "sky.upscale.params");
  pass.colour_ = createHostBuffer(ctx, pixels * 4 * sizeof(float), storage, "sky.upscale.image");
  pass.depth_ = createHostBuffer(ctx, pixels * sizeof(float), storage, "sky.upscale.depth");

  const auto count = static_cast<std::uint32_t>(sources.size());
  const vk::DescriptorPoolSize poolSize(vk::DescriptorType::eStorageBuffer, 5 * count);
  pass.descriptorPool_ = vk::raii::DescriptorPool(
      device, vk::DescriptorPoolCreateInfo(vk::DescriptorPoolCreateFlagBits::eFreeDescriptorSet, count, poolSize));
  ctx.name(pass.descriptorPool_, "sky.upscale.descriptorPool");
  const std::vector<vk::DescriptorSetLayout> layouts(count, *pass.pipeline_.setLayout);
  vk::raii::DescriptorSets sets(device, vk::DescriptorSetAllocateInfo(*pass.descriptorPool_, layouts));
  auto info = [](const GpuBuffer& b) { return vk::DescriptorBufferInfo(*b.buffer, 0, b.size); };
  for (std::uint32_t k = 0; k < count; ++k) {
    pass.sets_.push_back(std::move(sets[k]));
    ctx.name(pass.sets_.back(), "sky.upscale.set");
    const std::array infos{std::pair{gpu::kUpscaleBindingParams, info(pass.params_)},
                           std::pair{gpu::kUpscaleBindingSource, info(*sources[k].first)},
                           std::pair{gpu::kUpscaleBindingSourceDepth, info(*sources[k].second)},
                           std::pair{gpu::kUpscaleBindingOut, info(pass.colour_)},
                           std::pair{gpu::kUpscaleBindingOutDepth, info(pass.depth_)}};
    std::vector<vk::WriteDescriptorSet> writes;
    for (const auto& [binding, bufferInfo] : infos)
      writes.emplace_back(*pass.sets_.back(), binding, 0, vk::DescriptorType::eStorageBuffer, nullptr, bufferInfo);
    device.updateDescriptorSets(writes, {});
  }
  return pass;
}

void UpscalePass::record(const vk::raii::CommandBuffer& commands, GpuTimer& timer, std::size_t source,
                         const gpu::SkyUpscale& params) {
  SKY_ASSERT(source < sets_.size());
  SKY_ASSERT(params.size.z == width_ && params.size.w == height_);
  std::memcpy(params_.mapped, &params, sizeof params);
  const vk::MemoryBarrier sourceWritten(vk::AccessFlagBits::eShaderWrite, vk::AccessFlagBits::eShaderRead);
  commands.pipelineBarrier(vk::PipelineStageFlagBits::eComputeShader, vk::PipelineStageFlagBits::eComputeShader, {},
                           sourceWritten, {}, {});
  {
    const auto timed = timer.section(commands, "upscale");
    commands.bindPipeline(vk::PipelineBindPoint::eCompute, *pipeline_.pipeline);
    commands.bindDescriptorSets(vk::PipelineBindPoint::eCompute, *pipeline_.layout, 0, *sets_[source], {});
    const std::uint32_t gx = gpu::kUpscaleLocalSizeX, gy = gpu::kUpscaleLocalSizeY;
    const std::uint32_t cellsX = params.size.x + 1, cellsY = params.size.y + 1;
    commands.dispatch((cellsX + gx - 1) / gx, (cellsY + gy - 1) / gy, 1);
  }
  const vk::MemoryBarrier toHost(vk::AccessFlagBits::eShaderWrite, vk::AccessFlagBits::eHostRead);
  commands.pipelineBarrier(vk::PipelineStageFlagBits::eComputeShader, vk::PipelineStageFlagBits::eHost, {}, toHost,
                           {}, {});
}

Image UpscalePass::readBack() const { return readImage(colour_, depth_, width_, height_); }

gpu::SkyUpscale upscaleParams(const gpu::SkyFrame& frame, const ResolutionSettings& resolution, std::uint32_t width,
                              std::uint32_t height) {
  gpu::SkyUpscale u{};
  u.camForward = frame.camForward;
  u.camRight = frame.camRight;
  u.camDown = frame.camDown;
  u.earth = gpu::vec4(frame.earth.x, frame.earth.z, frame.raster.x, frame.raster.y);
  u.size = gpu::uvec4(frame.image.x, frame.image.y, width, height);
  u.mode = gpu::uvec4(resolution.divisor, resolution.depthAware ? 1u : 0u, 0u, 0u);
  return u;
}

}  // namespace sky::render
