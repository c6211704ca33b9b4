// Buffer/image creation and the staged image upload (see gpu_memory.hpp).
#include "gpu_memory.hpp"

#include <cstring>
#include <optional>

#include "sky/core/assert.hpp"

#include "gpu_timer.hpp"

namespace sky::render {

GpuBuffer createHostBuffer(const GpuContext& ctx, vk::DeviceSize size, vk::BufferUsageFlags usage,
                           const char* debugName) {
  const auto& device = ctx.device();
  GpuBuffer b;
  b.size = size;
  b.buffer = vk::raii::Buffer(device, vk::BufferCreateInfo({}, size, usage, vk::SharingMode::eExclusive));
  const vk::MemoryRequirements req = b.buffer.getMemoryRequirements();
  b.memory = vk::raii::DeviceMemory(
      device, vk::MemoryAllocateInfo(req.size, ctx.memoryType(req.memoryTypeBits,
                                                              vk::MemoryPropertyFlagBits::eHostVisible |
                                                                  vk::MemoryPropertyFlagBits::eHostCoherent)));
  b.buffer.bindMemory(*b.memory, 0);
  b.mapped = b.memory.mapMemory(0, size);
  ctx.name(b.buffer, debugName);
  ctx.name(b.memory, debugName);
  return b;
}

namespace {

// A device-local image with its memory and a view of viewType over all layers.
GpuImage createImage(const GpuContext& ctx, vk::ImageType type, vk::ImageViewType viewType, vk::Format format,
                     vk::Extent3D extent, std::uint32_t layers, vk::ImageUsageFlags usage, const char* debugName) {
  const auto& device = ctx.device();
  GpuImage img;
  img.format = format;
  img.extent = extent;
  img.layers = layers;
  const vk::ImageCreateInfo info({}, type, format, extent, 1, layers, vk::SampleCountFlagBits::e1,
                                 vk::ImageTiling::eOptimal, usage);
  img.image = vk::raii::Image(device, info);
  const vk::MemoryRequirements req = img.image.getMemoryRequirements();
  img.memory = vk::raii::DeviceMemory(
      device, vk::MemoryAllocateInfo(req.size, ctx.memoryType(req.memoryTypeBits,
                                                              vk::MemoryPropertyFlagBits::eDeviceLocal)));
  img.image.bindMemory(*img.memory, 0);
  img.view = vk::raii::ImageView(
      device, vk::ImageViewCreateInfo({}, *img.image, viewType, format, {},
                                      vk::ImageSubresourceRange(vk::ImageAspectFlagBits::eColor, 0, 1, 0, layers)));
  ctx.name(img.image, debugName);
  ctx.name(img.memory, debugName);
  ctx.name(img.view, debugName);
  return img;
}

}  // namespace

GpuImage createSampledImage(const GpuContext& ctx, vk::ImageType type, vk::Format format, vk::Extent3D extent,
                            std::uint32_t layers, const char* debugName) {
  // A view's type must match the shader's sampler (sampler2D, sampler2DArray).
  const vk::ImageViewType viewType = type == vk::ImageType::e3D ? vk::ImageViewType::e3D
                                     : layers > 1               ? vk::ImageViewType::e2DArray
                                                                : vk::ImageViewType::e2D;
  return createImage(ctx, type, viewType, format, extent, layers,
                     vk::ImageUsageFlagBits::eSampled | vk::ImageUsageFlagBits::eTransferDst |
                         vk::ImageUsageFlagBits::eTransferSrc,
                     debugName);
}

GpuImage createStorageImage(const GpuContext& ctx, vk::Format format, std::uint32_t width, std::uint32_t height,
                            const char* debugName) {
  return createImage(ctx, vk::ImageType::e2D, vk::ImageViewType::e2D, format, vk::Extent3D(width, height, 1), 1,
                     vk::ImageUsageFlagBits::eStorage | vk::ImageUsageFlagBits::eTransferDst, debugName);
}

GpuImage createStorageVolume(const GpuContext& ctx, vk::Format format, vk::Extent3D extent, const char* debugName) {
  return createImage(ctx, vk::ImageType::e3D, vk::ImageViewType::e3D, format, extent, 1,
                     vk::ImageUsageFlagBits::eStorage | vk::ImageUsageFlagBits::eSampled, debugName);
}

GpuImage createStorageArray(const GpuContext& ctx, vk::Format format, std::uint32_t width, std::uint32_t height,
                            std::uint32_t layers, const char* debugName) {
  return createImage(ctx, vk::ImageType::e2D, vk::ImageViewType::e2DArray, format, vk::Extent3D(width, height, 1),
                     layers, vk::ImageUsageFlagBits::eStorage | vk::ImageUsageFlagBits::eSampled, debugName);
}

namespace {

// Copies texels (staged whole) into the image by `copies`, timed as `pass`,
// between barriers from `from` (with the accesses that had it) to the layout
// the shaders read.
Result<void> copyIntoImage(const GpuContext& ctx, GpuImage& image, std::span<const std::byte> texels,
                           std::span<const vk::BufferImageCopy> copies, vk::ImageLayout from,
                           vk::AccessFlags fromAccess, GpuTimer* timer, const char* pass) {
  GpuBuffer staging = createHostBuffer(ctx, texels.size(), vk::BufferUsageFlagBits::eTransferSrc, "sky.staging");
  std::memcpy(staging.mapped, texels.data(), texels.size());
  const vk::ImageSubresourceRange range(vk::ImageAspectFlagBits::eColor, 0, 1, 0, image.layers);
  vk::raii::CommandBuffer cmd = ctx.allocateCommandBuffer();
  cmd.begin(vk::CommandBufferBeginInfo(vk::CommandBufferUsageFlagBits::eOneTimeSubmit));
  if (timer) timer->begin(cmd);
  std::optional<GpuTimer::Section> timed;
  if (timer) timed.emplace(timer->section(cmd, pass ? pass : "upload"));
  const vk::ImageMemoryBarrier toTransfer(fromAccess, vk::AccessFlagBits::eTransferWrite, from,
                                          vk::ImageLayout::eTransferDstOptimal, VK_QUEUE_FAMILY_IGNORED,
                                          VK_QUEUE_FAMILY_IGNORED, *image.image, range);
  cmd.pipelineBarrier(vk::PipelineStageFlagBits::eComputeShader, vk::PipelineStageFlagBits::eTransfer, {}, {}, {},
                      toTransfer);
  cmd.copyBufferToImage(*staging.buffer, *image.image, vk::ImageLayout::eTransferDstOptimal, copies);
  const vk::ImageMemoryBarrier toShader(vk::AccessFlagBits::eTransferWrite, vk::AccessFlagBits::eShaderRead,
                                        vk::ImageLayout::eTransferDstOptimal, vk::ImageLayout::eShaderReadOnlyOptimal,
                                        VK_QUEUE_FAMILY_IGNORED, VK_QUEUE_FAMILY_IGNORED, *image.image, range);
  cmd.pipelineBarrier(vk::PipelineStageFlagBits::eTransfer, vk::PipelineStageFlagBits::eComputeShader, {}, {}, {},
                      toShader);
  timed.reset();
  cmd.end();
  const vk::raii::Fence fence(ctx.device(), vk::FenceCreateInfo());
  return ctx.submitAndWait(cmd, fence);
}

}  // namespace

Result<void> uploadImage(const GpuContext& ctx, GpuImage& image, std::span<const std::byte> texels,
                         GpuTimer* timer, const char* pass) {
  const vk::BufferImageCopy whole(0, 0, 0, vk::ImageSubresourceLayers(vk::ImageAspectFlagBits::eColor, 0, 0, image.layers),
                                  {0, 0, 0}, image.extent);
  // Undefined -> transfer destination: discards what the image held; the
  // source stage covers an earlier frame's shader reads.
  return copyIntoImage(ctx, image, texels, std::span(&whole, 1), vk::ImageLayout::eUndefined, {}, timer, pass);
}

Result<void> uploadImageRegions(const GpuContext& ctx, GpuImage& image, std::span<const std::byte> texels,
                                std::span<const ImageRegion> regions, GpuTimer* timer, const char* pass) {
  if (regions.empty()) return {};
  std::vector<vk::BufferImageCopy> copies;
  copies.reserve(regions.size());
  for (const ImageRegion& r : regions) {
    SKY_ASSERT(r.layer < image.layers && r.width > 0 && r.height > 0 && r.x + r.width <= image.extent.width &&
               r.y + r.height <= image.extent.height);
    copies.emplace_back(r.byteOffset, 0, 0, vk::ImageSubresourceLayers(vk::ImageAspectFlagBits::eColor, 0, r.layer, 1),
                        vk::Offset3D(std::int32_t(r.x), std::int32_t(r.y), 0), vk::Extent3D(r.width, r.height, 1));
  }
  // From the layout the shaders read (not eUndefined, which would let the
  // driver discard the texels outside the regions); the source access covers
  // an earlier frame's reads.
  return copyIntoImage(ctx, image, texels, copies, vk::ImageLayout::eShaderReadOnlyOptimal,
                       vk::AccessFlagBits::eShaderRead, timer, pass);
}

Result<std::vector<std::byte>> downloadImage(const GpuContext& ctx, const GpuImage& image,
                                             std::size_t bytesPerTexel) {
  const std::size_t bytes = std::size_t(image.extent.width) * image.extent.height * image.extent.depth *
                            image.layers * bytesPerTexel;
  GpuBuffer readback = createHostBuffer(ctx, bytes, vk::BufferUsageFlagBits::eTransferDst, "sky.readback");
  const vk::ImageSubresourceRange range(vk::ImageAspectFlagBits::eColor, 0, 1, 0, image.layers);
  vk::raii::CommandBuffer cmd = ctx.allocateCommandBuffer();
  cmd.begin(vk::CommandBufferBeginInfo(vk::CommandBufferUsageFlagBits::eOneTimeSubmit));
  const vk::ImageMemoryBarrier toTransfer(vk::AccessFlagBits::eShaderRead | vk::AccessFlagBits::eTransferWrite,
                                          vk::AccessFlagBits::eTransferRead, vk::ImageLayout::eShaderReadOnlyOptimal,
                                          vk::ImageLayout::eTransferSrcOptimal, VK_QUEUE_FAMILY_IGNORED,
                                          VK_QUEUE_FAMILY_IGNORED, *image.image, range);
  cmd.pipelineBarrier(vk::PipelineStageFlagBits::eComputeShader | vk::PipelineStageFlagBits::eTransfer,
                      vk::PipelineStageFlagBits::eTransfer, {}, {}, {}, toTransfer);
  const vk::BufferImageCopy region(0, 0, 0,
                                   vk::ImageSubresourceLayers(vk::ImageAspectFlagBits::eColor, 0, 0, image.layers),
                                   {0, 0, 0}, image.extent);
  cmd.copyImageToBuffer(*image.image, vk::ImageLayout::eTransferSrcOptimal, *readback.buffer, region);
  const vk::ImageMemoryBarrier toShader(vk::AccessFlagBits::eTransferRead, vk::AccessFlagBits::eShaderRead,
                                        vk::ImageLayout::eTransferSrcOptimal, vk::ImageLayout::eShaderReadOnlyOptimal,
                                        VK_QUEUE_FAMILY_IGNORED, VK_QUEUE_FAMILY_IGNORED, *image.image, range);
  const vk::BufferMemoryBarrier toHost(vk::AccessFlagBits::eTransferWrite, vk::AccessFlagBits::eHostRead,
                                       VK_QUEUE_FAMILY_IGNORED, VK_QUEUE_FAMILY_IGNORED, *readback.buffer, 0, bytes);
  cmd.pipelineBarrier(vk::PipelineStageFlagBits::eTransfer,
                      vk::PipelineStageFlagBits::eComputeShader | vk::PipelineStageFlagBits::eHost, {}, {}, toHost,
                      toShader);
  cmd.end();
  const vk::raii::Fence fence(ctx.device(), vk::FenceCreateInfo());
  if (auto ok = ctx.submitAndWait(cmd, fence); !ok) return tl::unexpected(ok.error());
  std::vector<std::byte> out(bytes);
  std::memcpy(out.data(), readback.mapped, bytes);
  return out;
}

Image readImage(const GpuBuffer& colour, const GpuBuffer& depth, std::uint32_t width, std::uint32_t height) {
  Image image;
  image.width = width;
  image.height = height;
  image.rgba.resize(std::size_t(width) * height * 4);
  image.cloudDepth_m.resize(std::size_t(width) * height);
  SKY_ASSERT(colour.size >= image.rgba.size() * sizeof(float) && depth.size >= image.cloudDepth_m.size() * sizeof(float));
  std::memcpy(image.rgba.data(), colour.mapped, image.rgba.size() * sizeof(float));
  std::memcpy(image.cloudDepth_m.data(), depth.mapped, image.cloudDepth_m.size() * sizeof(float));
  return image;
}

}  // namespace sky::render
