// The windowed front end's window: GLFW (X11 here; works under Xvfb), one
// non-resizable window the size of the render, and the WindowSurface the
// renderer builds its swapchain on. GLFW lives as long as the window; only
// one exists per process, and it is used from the main thread only (GLFW's
// rule for window and event calls).
#pragma once

#include <memory>
#include <string>

#include "sky/core/result.hpp"
#include "sky/render/gpu_options.hpp"

struct GLFWwindow;

namespace sky::app {

class GlfwWindow {
 public:
  // Errors: Unsupported when GLFW cannot start (no display: DISPLAY unset or
  // the X server unreachable) or has no Vulkan; Io when the window cannot be
  // created. GLFW's own message is in the detail.
  static Result<std::unique_ptr<GlfwWindow>> open(std::uint32_t width, std::uint32_t height, const std::string& title);

  // What the renderer needs to present here; valid as long as the window.
  const render::WindowSurface& surface() const { return surface_; }

  // Handles pending window events; true once the user asked to close it.
  bool pollClosed();

  GlfwWindow(const GlfwWindow&) = delete;
  GlfwWindow& operator=(const GlfwWindow&) = delete;
  ~GlfwWindow();

 private:
  GlfwWindow() = default;
  GLFWwindow* window_ = nullptr;  // destroyed, then GLFW terminated, in the destructor
  render::WindowSurface surface_;
};

}  // namespace sky::app
