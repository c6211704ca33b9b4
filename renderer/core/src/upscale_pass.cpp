// Upscale pass resources and recording (see upscale_pass.hpp).
#include "upscale_pass.hpp"

#include <array>
#include <cstring>
#include <vector>

#include "sky/core/assert.hpp"

namespace sky::render {

Result<UpscalePass> UpscalePass::create(const GpuContext& ctx, std::uint32_t smallWidth, std::uint32_t smallHeight,
                                        std::uint32_t width, std::uint32_t height, const Input& input) {
  SKY_ASSERT(smallWidth <= width && smallHeight <= height);
  SKY_ASSERT(input.images != nullptr || (input.buffers.first != nullptr && input.buffers.second != nullptr));
  UpscalePass pass;
  pass.width_ = width;
  pass.height_ = height;
  pass.smallWidth_ = smallWidth;
  pass.smallHeight_ = smallHeight;
  ComputePipelineBuilder builder("sky.upscale");
  for (std::uint32_t b : {gpu::kUpscaleBindingParams, gpu::kUpscaleBindingOut, gpu::kUpscaleBindingOutDepth})
    builder.binding(b, vk::DescriptorType::eStorageBuffer);
  for (std::uint32_t b : {gpu::kUpscaleBindingSource, gpu::kUpscaleBindingSourceDepth})
    builder.binding(b, vk::DescriptorType::eStorageImage);
  builder.shader("upscale.comp.spv");
  auto pipeline = builder.build(ctx);
  if (!pipeline) return tl::unexpected(pipeline.error());
  pass.pipeline_ = std::move(*pipeline);

  const auto storage = vk::BufferUsageFlagBits::eStorageBuffer;
  const vk::DeviceSize pixels = vk::DeviceSize(pass.width_) * pass.height_;
  pass.params_ = createHostBuffer(ctx, sizeof(gpu::SkyUpscale), storage, "sky.upscale.params");
  pass.colour_ = createHostBuffer(ctx, pixels * 4 * sizeof(float), storage, "sky.upscale.image");
  pass.depth_ = createHostBuffer(ctx, pixels * sizeof(float), storage, "sky.upscale.depth");
  const PixelMirror* source = input.images;
  if (source == nullptr) {
    pass.sourceBuffers_ = {*input.buffers.first->buffer, *input.buffers.second->buffer};
    auto mirror = PixelMirror::create(ctx, smallWidth, smallHeight, "sky.upscale.source");
    if (!mirror) return tl::unexpected(mirror.error());
    source = &pass.ownImages_.emplace(std::move(*mirror));
  }
  SKY_ASSERT(source->width() == smallWidth && source->height() == smallHeight);

  auto info = [](const GpuBuffer& b) { return vk::DescriptorBufferInfo(*b.buffer, 0, b.size); };
  const std::vector<std::pair<std::uint32_t, vk::DescriptorBufferInfo>> buffers{
      std::pair{gpu::kUpscaleBindingParams, info(pass.params_)}, std::pair{gpu::kUpscaleBindingOut, info(pass.colour_)},
      std::pair{gpu::kUpscaleBindingOutDepth, info(pass.depth_)}};
  const std::vector<std::pair<std::uint32_t, vk::DescriptorImageInfo>> images{
      std::pair{gpu::kUpscaleBindingSource, source->colourInfo()},
      std::pair{gpu::kUpscaleBindingSourceDepth, source->depthInfo()}};
  pass.set_ = createStorageSet(ctx, pass.pipeline_, "sky.upscale", buffers, images);
  return pass;
}

void UpscalePass::record(const vk::raii::CommandBuffer& commands, GpuTimer& timer, const gpu::SkyUpscale& params) {
  SKY_ASSERT(params.size.x == smallWidth_ && params.size.y == smallHeight_);
  SKY_ASSERT(params.size.z == width_ && params.size.w == height_);
  std::memcpy(params_.mapped, &params, sizeof params);
  {
    const auto timed = timer.section(commands, "upscale");
    if (ownImages_)
      ownImages_->record(commands, sourceBuffers_.first, sourceBuffers_.second, smallWidth_, smallHeight_);
    commands.bindPipeline(vk::PipelineBindPoint::eCompute, *pipeline_.pipeline);
    commands.bindDescriptorSets(vk::PipelineBindPoint::eCompute, *pipeline_.layout, 0, *set_.set, {});
    const std::uint32_t gx = gpu::kUpscaleLocalSizeX, gy = gpu::kUpscaleLocalSizeY;
    const std::uint32_t cellsX = params.size.x + 1, cellsY = params.size.y + 1;
    commands.dispatch((cellsX + gx - 1) / gx, (cellsY + gy - 1) / gy, 1);
  }
  const vk::MemoryBarrier toHost(vk::AccessFlagBits::eShaderWrite, vk::AccessFlagBits::eHostRead);
  commands.pipelineBarrier(vk::PipelineStageFlagBits::eComputeShader, vk::PipelineStageFlagBits::eHost, {}, toHost, {},
                           {});
}

Image UpscalePass::readBack() const { return readImage(colour_, depth_, width_, height_); }

gpu::SkyUpscale upscaleParams(const gpu::SkyFrame& frame, const ResolutionSettings& resolution, std::uint32_t width,
                              std::uint32_t height) {
  gpu::SkyUpscale u{};
  u.camForward = frame.camForward;
  u.camRight = frame.camRight;
  u.camDown = frame.camDown;
  u.frustum = frame.frustum;
  u.earth = gpu::vec4(frame.earth.x, frame.earth.z, frame.raster.x, frame.raster.y);
  u.size = gpu::uvec4(frame.image.x, frame.image.y, width, height);
  u.mode = gpu::uvec4(resolution.divisor, resolution.depthAware ? 1u : 0u, 0u, 0u);
  return u;
}

}  // namespace sky::render
