// GLFW window for the windowed front end (see glfw_window.hpp).
#include "sky/app/glfw_window.hpp"

#include <algorithm>

#define GLFW_INCLUDE_VULKAN
#include <GLFW/glfw3.h>

namespace sky::app {

namespace {

// GLFW reports errors through a callback; the last one explains a failed call.
thread_local std::string gLastGlfwError;
void onGlfwError(int code, const char* text) {
  gLastGlfwError = "GLFW error " + std::to_string(code) + ": " + (text ? text : "");
}

std::string lastError() { return gLastGlfwError.empty() ? std::string("no reason given") : gLastGlfwError; }

}  // namespace

Result<std::unique_ptr<GlfwWindow>> GlfwWindow::open(std::uint32_t width, std::uint32_t height, const std::string& title) {
  glfwSetErrorCallback(onGlfwError);
  if (glfwInit() != GLFW_TRUE) return fail(ErrorCode::Unsupported, "cannot open a window: " + lastError());
  std::unique_ptr<GlfwWindow> w(new GlfwWindow());
  if (glfwVulkanSupported() != GLFW_TRUE) {
    glfwTerminate();
    return fail(ErrorCode::Unsupported, "cannot open a window: GLFW finds no Vulkan loader: " + lastError());
  }
  glfwWindowHint(GLFW_CLIENT_API, GLFW_NO_API);  // Vulkan draws, not OpenGL
  glfwWindowHint(GLFW_RESIZABLE, GLFW_FALSE);    // the render size is fixed at start
  w->window_ = glfwCreateWindow(int(width), int(height), title.c_str(), nullptr, nullptr);
  if (w->window_ == nullptr) {
    glfwTerminate();
    return fail(ErrorCode::Io, "cannot create a " + std::to_string(width) + "x" + std::to_string(height) +
                                   " window: " + lastError());
  }
  std::uint32_t count = 0;
  const char** names = glfwGetRequiredInstanceExtensions(&count);
  for (std::uint32_t i = 0; names != nullptr && i < count; ++i) w->surface_.instanceExtensions.emplace_back(names[i]);
  GLFWwindow* raw = w->window_;
  w->surface_.createSurface = [raw](VkInstance instance) {
    VkSurfaceKHR surface = VK_NULL_HANDLE;
    if (glfwCreateWindowSurface(instance, raw, nullptr, &surface) != VK_SUCCESS) return VkSurfaceKHR(VK_NULL_HANDLE);
    return surface;
  };
  w->surface_.framebufferSize = [raw] {
    int fw = 0, fh = 0;
    glfwGetFramebufferSize(raw, &fw, &fh);
    return std::pair<std::uint32_t, std::uint32_t>(std::uint32_t(std::max(fw, 0)), std::uint32_t(std::max(fh, 0)));
  };
  return w;
}

bool GlfwWindow::pollClosed() {
  glfwPollEvents();
  return glfwWindowShouldClose(window_) == GLFW_TRUE;
}

GlfwWindow::~GlfwWindow() {
  if (window_ != nullptr) glfwDestroyWindow(window_);
  glfwTerminate();
}

}  // namespace sky::app
