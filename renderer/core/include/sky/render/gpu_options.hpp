// What a front end asks of the renderer's Vulkan device beyond a compute
// queue: a window surface to present to (the windowed front end brings its
// window system's surface; the core stays free of any window library), and
// Khronos validation with its messages collected for the front end to log.
#pragma once

#include <chrono>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <string>
#include <utility>
#include <vector>

#include <vulkan/vulkan_core.h>

namespace sky::render {

struct WindowSurface {
  // Instance extensions the window system needs (GLFW: glfwGetRequiredInstanceExtensions).
  std::vector<std::string> instanceExtensions;
  // Creates the window's surface on this instance; VK_NULL_HANDLE on failure.
  // The renderer owns (and destroys) the surface it returns.
  std::function<VkSurfaceKHR(VkInstance)> createSurface;
  // The window's drawable size now, pixels.
  std::function<std::pair<std::uint32_t, std::uint32_t>()> framebufferSize;
};

struct GpuOptions {
  // nullptr: headless (no surface, no swapchain). Must outlive the renderer.
  const WindowSurface* window = nullptr;
  // Enable VK_LAYER_KHRONOS_validation (Unsupported when it is not installed)
  // and collect its messages (CloudRenderer::takeValidationMessages).
  bool validation = false;
  // How long one submitted frame may run before it is given up as hung and
  // fails with Timeout (the work is let finish before its resources are
  // freed). A minute is far past any preset's frame; `reference` at 640x360
  // takes longer on lavapipe, so the bench raises it. Must be positive.
  std::chrono::milliseconds frameTimeout{60'000};
};

struct ValidationCounts {
  std::size_t errors = 0, warnings = 0;
};

}  // namespace sky::render
