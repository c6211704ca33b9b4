// Buffers and sampled images with their own device memory (one allocation per
// object: the skeleton has a handful), and a blocking staged upload into an
// image. Throws vk::SystemError; callers convert at the module edge.
#pragma once

#include <cstdint>
#include <span>

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
// atmosphere tables, sampler2D); in eShaderReadOnlyOptimal after the first upload.
GpuImage createSampledImage(const GpuContext& ctx, vk::ImageType type, vk::Format format, vk::Extent3D extent,
                            std::uint32_t layers, const char* debugName);

class GpuTimer;

// Copies texels (tightly packed, all layers) into the whole image and leaves it
// in eShaderReadOnlyOptimal. Previous contents are discarded. Blocking. With
// a timer, the copy is timed as the section `pass`.
Result<void> uploadImage(const GpuContext& ctx, GpuImage& image, std::span<const std::byte> texels,
                         GpuTimer* timer = nullptr, const char* pass = nullptr);

}  // namespace sky::render
