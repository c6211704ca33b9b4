// The cloud pass: one compute dispatch over the image (shaders/clouds.comp)
// with its uniform block, shape-noise texture, samplers, output buffers
// (radiance + transmittance, cloud depth), descriptor set and command buffer. Blocking: run() returns the read-back image.
#pragma once

#include <cstdint>

#include "compute_pipeline.hpp"
#include "gpu_context.hpp"
#include "gpu_memory.hpp"
#include "gpu_timer.hpp"
#include "noise_volume.hpp"
#include "sky/render/cloud_renderer.hpp"
#include "sky_shared.h"
#include "weather_texture.hpp"

namespace sky::render {

class CloudPass {
 public:
  // weather must outlive the pass (its image view is bound once here).
  // Errors: Io/Malformed for the SPIR-V, Device from the noise upload; other
  // Vulkan failures throw.
  static Result<CloudPass> create(const GpuContext& ctx, std::uint32_t width, std::uint32_t height,
                                  const NoiseVolume& noise, const WeatherTexture& weather);

  // Dispatches one frame and reads it back. Errors: Timeout, Device.
  Result<Image> run(const GpuContext& ctx, const gpu::SkyFrame& frame);
  // GPU time of the last run's dispatch ("clouds").
  std::vector<PassTime> lastTimes() const { return timer_.results(); }

 private:
  CloudPass() = default;

  // Destroyed in reverse order: fence and command buffer first, the
  // descriptor set before its pool, buffers and images before the samplers
  // and pipeline that reference them in the set layout.
  ComputePipeline pipeline_;
  vk::raii::Sampler noiseSampler_{nullptr};
  vk::raii::Sampler weatherSampler_{nullptr};
  GpuImage noise_;
  GpuBuffer uniforms_;
  GpuBuffer output_;
  GpuBuffer depth_;
  vk::raii::DescriptorPool descriptorPool_{nullptr};
  vk::raii::DescriptorSet descriptorSet_{nullptr};
  GpuTimer timer_;
  vk::raii::CommandBuffer commands_{nullptr};
  vk::raii::Fence fence_{nullptr};
  std::uint32_t width_ = 0, height_ = 0;
};

}  // namespace sky::render
