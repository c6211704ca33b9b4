// Buffers copied into storage images for gathering passes (see pixel_mirror.hpp).
#include "pixel_mirror.hpp"

#include <array>

#include "sky/core/assert.hpp"

namespace sky::render {

Result<PixelMirror> PixelMirror::create(const GpuContext& ctx, std::uint32_t width, std::uint32_t height,
                                        const char* debugName) {
  PixelMirror m;
  m.colour_ = createStorageImage(ctx, vk::Format::eR32G32B32A32Sfloat, width, height, debugName);
  m.depth_ = createStorageImage(ctx, vk::Format::eR32Sfloat, width, height, debugName);
  // Undefined -> general, cleared: a pass may bind them before the first copy.
  const vk::ImageSubresourceRange range(vk::ImageAspectFlagBits::eColor, 0, 1, 0, 1);
  vk::raii::CommandBuffer cmd = ctx.allocateCommandBuffer();
  cmd.begin(vk::CommandBufferBeginInfo(vk::CommandBufferUsageFlagBits::eOneTimeSubmit));
  for (const GpuImage* image : {&m.colour_, &m.depth_}) {
    const vk::ImageMemoryBarrier toGeneral({}, vk::AccessFlagBits::eTransferWrite, vk::ImageLayout::eUndefined,
                                           vk::ImageLayout::eGeneral, VK_QUEUE_FAMILY_IGNORED, VK_QUEUE_FAMILY_IGNORED,
                                           *image->image, range);
    cmd.pipelineBarrier(vk::PipelineStageFlagBits::eTopOfPipe, vk::PipelineStageFlagBits::eTransfer, {}, {}, {},
                        toGeneral);
    cmd.clearColorImage(*image->image, vk::ImageLayout::eGeneral, vk::ClearColorValue(0.0f, 0.0f, 0.0f, 0.0f), range);
  }
  const vk::MemoryBarrier cleared(vk::AccessFlagBits::eTransferWrite, vk::AccessFlagBits::eShaderRead);
  cmd.pipelineBarrier(vk::PipelineStageFlagBits::eTransfer, vk::PipelineStageFlagBits::eComputeShader, {}, cleared, {},
                      {});
  cmd.end();
  const vk::raii::Fence fence(ctx.device(), vk::FenceCreateInfo());
  if (auto ok = ctx.submitAndWait(cmd, fence); !ok) return tl::unexpected(ok.error());
  return m;
}

void PixelMirror::record(const vk::raii::CommandBuffer& commands, vk::Buffer colour, vk::Buffer depth,
                         std::uint32_t columns, std::uint32_t rows) {
  SKY_ASSERT(columns > 0 && rows > 0 && columns <= width() && rows <= height());
  const vk::ImageSubresourceRange range(vk::ImageAspectFlagBits::eColor, 0, 1, 0, 1);
  // General (what the shaders read) -> transfer destination -> general.
  auto barrier = [&](const GpuImage& image, bool toTransfer) {
    return toTransfer ? vk::ImageMemoryBarrier(vk::AccessFlagBits::eShaderRead, vk::AccessFlagBits::eTransferWrite,
                                               vk::ImageLayout::eGeneral, vk::ImageLayout::eTransferDstOptimal,
                                               VK_QUEUE_FAMILY_IGNORED, VK_QUEUE_FAMILY_IGNORED, *image.image, range)
                      : vk::ImageMemoryBarrier(vk::AccessFlagBits::eTransferWrite, vk::AccessFlagBits::eShaderRead,
                                               vk::ImageLayout::eTransferDstOptimal, vk::ImageLayout::eGeneral,
                                               VK_QUEUE_FAMILY_IGNORED, VK_QUEUE_FAMILY_IGNORED, *image.image, range);
  };
  const std::array before{barrier(colour_, true), barrier(depth_, true)};
  const vk::MemoryBarrier buffersWritten(vk::AccessFlagBits::eShaderWrite, vk::AccessFlagBits::eTransferRead);
  commands.pipelineBarrier(vk::PipelineStageFlagBits::eComputeShader, vk::PipelineStageFlagBits::eTransfer, {},
                           buffersWritten, {}, before);
  const vk::ImageSubresourceLayers layers(vk::ImageAspectFlagBits::eColor, 0, 0, 1);
  const vk::BufferImageCopy region(0, columns, rows, layers, {0, 0, 0}, vk::Extent3D(columns, rows, 1));
  commands.copyBufferToImage(colour, *colour_.image, vk::ImageLayout::eTransferDstOptimal, region);
  commands.copyBufferToImage(depth, *depth_.image, vk::ImageLayout::eTransferDstOptimal, region);
  const std::array after{barrier(colour_, false), barrier(depth_, false)};
  commands.pipelineBarrier(vk::PipelineStageFlagBits::eTransfer, vk::PipelineStageFlagBits::eComputeShader, {}, {}, {},
                           after);
}

}  // namespace sky::render
