// A pass's output buffers (radiance + transmittance, vec4 per pixel; cloud
// depth, float per pixel) copied into two storage images for the passes that
// gather from them (the reprojection and the upscale). llvmpipe compiles a
// storage-buffer load with a per-lane index as a loop over the 8 lanes with
// a branch and a bounds check per component, and runs it whenever any lane
// of the 8 takes that path; an image load fetches each lane's texel whole,
// without branches. The passes time their copies with their own work.
#pragma once

#include <cstdint>

#include <vulkan/vulkan_raii.hpp>

#include "gpu_context.hpp"
#include "gpu_memory.hpp"
#include "sky/core/result.hpp"

namespace sky::render {

class PixelMirror {
 public:
  // width x height texels; rgba32f and r32f storage images, cleared to 0 and
  // kept in eGeneral. Blocking (one submission). Vulkan failures throw.
  static Result<PixelMirror> create(const GpuContext& ctx, std::uint32_t width, std::uint32_t height,
                                    const char* debugName);

  // Records the copy of the first `rows` rows of `columns` pixels (packed:
  // row stride `columns`) of the two buffers into the images' top-left
  // corner, between barriers: after the shader writes of the buffers and the
  // shader reads of the images, before the next shader reads of the images.
  // The buffers are passed by handle: they must hold columns * rows entries.
  void record(const vk::raii::CommandBuffer& commands, vk::Buffer colour, vk::Buffer depth, std::uint32_t columns,
              std::uint32_t rows);

  vk::DescriptorImageInfo colourInfo() const { return {nullptr, *colour_.view, vk::ImageLayout::eGeneral}; }
  vk::DescriptorImageInfo depthInfo() const { return {nullptr, *depth_.view, vk::ImageLayout::eGeneral}; }
  std::uint32_t width() const { return colour_.extent.width; }
  std::uint32_t height() const { return colour_.extent.height; }

 private:
  PixelMirror() = default;

  GpuImage colour_;
  GpuImage depth_;
};

}  // namespace sky::render
