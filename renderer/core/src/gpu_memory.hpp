// Buffers and sampled images with their own device memory (one allocation per
// object: the skeleton has a handful), and a blocking staged upload into an
// image. Throws vk::SystemError; callers convert at the module edge.
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include <vulkan/vulkan_raii.hpp>

#include "gpu_context.hpp"
#include "sky/render/cloud_renderer.hpp"

namespace sky::render {

struct GpuBuffer {
  // Destroyed in reverse order: the buffer before the memory bound to it.
  vk::raii::DeviceMemory memory{nullptr};
  vk::raii::Buffer buffer{nullptr};
  vk::DeviceSize size = 0;
  void* mapped = nullptr;  // host-visible buffers stay mapped for their lifetime
};

// A buffer in host-visible, host-coherent memory (lavapipe has no other kind
// that matters; on a discrete GPU these are the uniform and readback buffers).
GpuBuffer createHostBuffer(const GpuContext& ctx, vk::DeviceSize size, vk::BufferUsageFlags usage,
                           const char* debugName);

// A width x height image out of the host-visible buffers a pass wrote
// (radiance + transmittance, vec4 per pixel; cloud depth, float per pixel).
Image readImage(const GpuBuffer& colour, const GpuBuffer& depth, std::uint32_t width, std::uint32_t height);

struct GpuImage {
  // Destroyed in reverse order: view, image, then memory.
  vk::raii::DeviceMemory memory{nullptr};
  vk::raii::Image image{nullptr};
  vk::raii::ImageView view{nullptr};
  vk::Format format = vk::Format::eUndefined;
  vk::Extent3D extent{};
  std::uint32_t layers = 1;
};

// A device-local sampled image, viewed as 3D (type e3D), a 2D array (e2D with
// layers > 1: the weather map, sampler2DArray) or 2D (e2D with one layer: the
// atmosphere tables, sampler2D); in eShaderReadOnlyOptimal after the first
// upload. It can be a transfer source (downloadImage reads it back).
GpuImage createSampledImage(const GpuContext& ctx, vk::ImageType type, vk::Format format, vk::Extent3D extent,
                            std::uint32_t layers, const char* debugName);

// A device-local 2D storage image (one layer) that can be a transfer
// destination; in eUndefined until the caller moves it.
GpuImage createStorageImage(const GpuContext& ctx, vk::Format format, std::uint32_t width, std::uint32_t height,
                            const char* debugName);

// A device-local 3D image that a pass writes (storage) and a later pass
// samples, both in eGeneral; in eUndefined until the writer moves it.
GpuImage createStorageVolume(const GpuContext& ctx, vk::Format format, vk::Extent3D extent, const char* debugName);

// A device-local 2D array image that a pass writes (storage) and a later
// pass samples, both in eGeneral; in eUndefined until the writer moves it.
GpuImage createStorageArray(const GpuContext& ctx, vk::Format format, std::uint32_t width, std::uint32_t height,
                            std::uint32_t layers, const char* debugName);

class GpuTimer;

// Copies texels (tightly packed, all layers) into the whole image and leaves it
// in eShaderReadOnlyOptimal. Previous contents are discarded. Blocking. With
// a timer, the copy is timed as the section `pass`.
Result<void> uploadImage(const GpuContext& ctx, GpuImage& image, std::span<const std::byte> texels,
                         GpuTimer* timer = nullptr, const char* pass = nullptr);

// One rectangle of one array layer of an image, its texels tightly packed
// (row after row) in a caller's byte span from byteOffset on.
struct ImageRegion {
  std::uint32_t layer = 0;
  std::uint32_t x = 0, y = 0;           // texels
  std::uint32_t width = 0, height = 0;  // texels, > 0
  std::size_t byteOffset = 0;
};

// Copies texels into these regions of an image already uploaded whole once
// (in eShaderReadOnlyOptimal), keeping everything else it holds, and leaves
// it in eShaderReadOnlyOptimal. Blocking. With a timer, the copy is timed
// as the section `pass`.
Result<void> uploadImageRegions(const GpuContext& ctx, GpuImage& image, std::span<const std::byte> texels,
                                std::span<const ImageRegion> regions, GpuTimer* timer = nullptr,
                                const char* pass = nullptr);

// The whole image (all layers) read back, tightly packed as uploadImage takes
// it, bytesPerTexel per texel. The image must be in eShaderReadOnlyOptimal
// and stays so. Blocking. For tests: what the shaders sample, byte for byte.
Result<std::vector<std::byte>> downloadImage(const GpuContext& ctx, const GpuImage& image,
                                             std::size_t bytesPerTexel);

}  // namespace sky::render
