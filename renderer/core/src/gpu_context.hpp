// The Vulkan context of the renderer: instance (with Khronos validation and a
// message collector when asked), the chosen physical device, a logical device
// with one queue that computes (and presents to the window surface, when
// there is one), and a command pool. Every other GPU object borrows the
// device from here, so a context lives behind a unique_ptr (stable address)
// and outlives them.
#pragma once

#include <chrono>
#include <cstdint>
#include <deque>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include <vulkan/vulkan_raii.hpp>

#include "sky/core/result.hpp"
#include "sky/render/gpu_options.hpp"

namespace sky::render {

// Validation messages, filled by the layer's callback (on whichever thread
// called Vulkan), drained by the front end.
struct ValidationLog {
  std::mutex mutex;
  ValidationCounts counts;
  std::deque<std::string> messages;  // newest kept; bounded
};

class GpuContext {
 public:
  // Errors: Unsupported when no Vulkan driver, no device with a compute queue
  // (that can present to the window, if any) and Vulkan 1.2, or validation
  // asked for and not installed; Device for other Vulkan failures.
  // SKY_VULKAN_DEVICE=<substring> picks a device by name; otherwise a
  // discrete GPU is preferred over integrated, virtual, then CPU (lavapipe).
  static Result<std::unique_ptr<GpuContext>> create(const GpuOptions& options = {});

  const vk::raii::Instance& instance() const { return instance_; }
  const vk::raii::Device& device() const { return device_; }
  const vk::raii::PhysicalDevice& physicalDevice() const { return physical_; }
  const vk::raii::Queue& queue() const { return queue_; }
  std::uint32_t queueFamily() const { return queueFamily_; }
  const vk::raii::CommandPool& commandPool() const { return commandPool_; }
  const std::string& deviceName() const { return deviceName_; }
  // The window's surface; null (*surface() == VK_NULL_HANDLE) when headless.
  const vk::raii::SurfaceKHR& surface() const { return surface_; }

  // Timestamps on the queue: valid bits (0 = none) and ns per tick.
  std::uint32_t timestampValidBits() const { return timestampValidBits_; }
  double timestampPeriod_ns() const { return timestampPeriod_ns_; }

  // Index of a memory type allowed by typeBits with all of the flags; throws
  // vk::SystemError (caught at the module edge) when none exists.
  std::uint32_t memoryType(std::uint32_t typeBits, vk::MemoryPropertyFlags flags) const;

  vk::raii::CommandBuffer allocateCommandBuffer() const;

  // Submits and waits for completion. Errors: Timeout, Device.
  Result<void> submitAndWait(const vk::raii::CommandBuffer& commands, const vk::raii::Fence& fence) const;
  // Waits for a fence of an earlier submission. Errors: Timeout, Device.
  Result<void> wait(const vk::raii::Fence& fence) const;

  // Validation messages since the last call (empty without validation).
  std::vector<std::string> takeValidationMessages();
  ValidationCounts validationCounts();

  // Debug name for any vk::raii handle (a no-op without VK_EXT_debug_utils).
  template <class RaiiHandle>
  void name(const RaiiHandle& handle, const char* text) const {
    if (!debugUtils_) return;
    using CType = typename RaiiHandle::CType;
    const vk::DebugUtilsObjectNameInfoEXT info(
        RaiiHandle::objectType, reinterpret_cast<std::uint64_t>(static_cast<CType>(*handle)), text);
    device_.setDebugUtilsObjectNameEXT(info);
  }

 private:
  GpuContext() = default;
  std::uint64_t fenceTimeout_ns() const {
    return std::uint64_t(std::chrono::duration_cast<std::chrono::nanoseconds>(frameTimeout_).count());
  }
  std::string timeoutText() const {  // "60 s", "1500 ms"
    const auto ms = frameTimeout_.count();
    return ms % 1000 == 0 ? std::to_string(ms / 1000) + " s" : std::to_string(ms) + " ms";
  }

  // Members are destroyed in reverse order: the pool before the device, the
  // device before the surface and the messenger, those before the instance,
  // the instance before the loader context; the log outlives the messenger
  // that writes to it.
  std::unique_ptr<ValidationLog> validationLog_;
  vk::raii::Context context_;
  vk::raii::Instance instance_{nullptr};
  vk::raii::DebugUtilsMessengerEXT messenger_{nullptr};
  vk::raii::SurfaceKHR surface_{nullptr};
  vk::raii::PhysicalDevice physical_{nullptr};
  vk::raii::Device device_{nullptr};
  vk::raii::Queue queue_{nullptr};
  vk::raii::CommandPool commandPool_{nullptr};
  std::uint32_t queueFamily_ = 0;
  std::uint32_t timestampValidBits_ = 0;
  double timestampPeriod_ns_ = 0;
  std::string deviceName_;
  bool debugUtils_ = false;
  std::chrono::milliseconds frameTimeout_{60'000};  // GpuOptions::frameTimeout
};

}  // namespace sky::render
