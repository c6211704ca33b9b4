// A frame loop's window, when it has one: shows each rendered frame through
// the renderer's swapchain and tells the loop when the user closed the window.
#pragma once

#include <cstdint>

#include "sky/app/glfw_window.hpp"
#include "sky/render/cloud_renderer.hpp"

namespace sky::app {

class WindowDisplay {
 public:
  // Both must outlive the display; the renderer was created on window's surface.
  WindowDisplay(render::CloudRenderer& renderer, GlfwWindow& window) : renderer_(renderer), window_(window) {}

  // Presents the frame at `exposure` (the PNG's display exposure, writePng)
  // (true if it reached the window) and handles window events. Errors from
  // CloudRenderer::present.
  Result<bool> show(const render::Image& image, double exposure) {
    auto shown = renderer_.present(image, exposure);
    if (shown && *shown) ++presented_;
    closed_ = closed_ || window_.pollClosed();
    return shown;
  }
  // Handles window events between frames (while a loop waits).
  void poll() { closed_ = closed_ || window_.pollClosed(); }
  bool closed() const { return closed_; }
  std::uint64_t presented() const { return presented_; }

 private:
  render::CloudRenderer& renderer_;
  GlfwWindow& window_;
  std::uint64_t presented_ = 0;
  bool closed_ = false;
};

}  // namespace sky::app
