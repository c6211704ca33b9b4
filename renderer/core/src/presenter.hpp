// Shows rendered frames in a window: a swapchain on the context's surface,
// and per frame the display transform of the PNG (image_output.hpp) copied
// into the acquired swapchain image, then presented. The copy goes through a
// host-visible staging buffer (the frames are read back for the metadata
// anyway, and on lavapipe all memory is host memory); a window of another
// size than the render gets the frame scaled by nearest pixel. The swapchain
// is rebuilt when the surface changes (out of date, suboptimal, resized).
#pragma once

#include <cstdint>
#include <vector>

#include <vulkan/vulkan_raii.hpp>

#include "gpu_context.hpp"
#include "gpu_memory.hpp"
#include "gpu_timer.hpp"
#include "sky/render/cloud_renderer.hpp"

namespace sky::render {

class Presenter {
 public:
  // Errors: Unsupported when the surface offers no 8-bit RGBA/BGRA format or
  // no transfer-destination use; Vulkan failures throw.
  static Result<Presenter> create(const GpuContext& ctx, const WindowSurface& window);

  // Shows the image through the PNG's display transform at `exposure` (the
  // multiplier of the radiance units, tonemapToSrgb8). Returns false when
  // nothing could be shown this time (a minimised window, a swapchain being
  // rebuilt). Errors: Timeout, Device.
  Result<bool> present(const GpuContext& ctx, const Image& image, double exposure);

  // GPU time of the last presented frame's copy ("present").
  std::vector<PassTime> lastTimes() const { return timer_.results(); }
  std::uint64_t presented() const { return presented_; }

  Presenter(Presenter&&) noexcept = default;
  Presenter& operator=(Presenter&&) noexcept = default;
  ~Presenter();

 private:
  Presenter() = default;
  Result<void> rebuild(const GpuContext& ctx);

  const WindowSurface* window_ = nullptr;
  vk::SurfaceFormatKHR format_{};
  bool bgra_ = true;  // byte order of format_
  // Destroyed in reverse order after a device wait (~Presenter): fence,
  // semaphores and command buffer, then the staging buffer, then the
  // swapchain (whose images die with it).
  vk::raii::SwapchainKHR swapchain_{nullptr};
  std::vector<vk::Image> images_;
  vk::Extent2D extent_{};
  GpuBuffer staging_;
  GpuTimer timer_;
  vk::raii::CommandBuffer commands_{nullptr};
  vk::raii::Semaphore acquired_{nullptr};
  std::vector<vk::raii::Semaphore> copied_;  // one per swapchain image: waited by its present
  vk::raii::Fence fence_{nullptr};
  const vk::raii::Device* device_ = nullptr;
  std::uint64_t presented_ = 0;
  bool stale_ = false;  // rebuild before the next frame
};

}  // namespace sky::render
