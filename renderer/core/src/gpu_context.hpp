// The Vulkan context of a headless renderer: instance, the chosen physical
// device, a logical device with one compute queue, and a command pool. No
// surface. Every other GPU object borrows the device from here, so a context
// lives behind a unique_ptr (stable address) and outlives them.
#pragma once

#include <cstdint>
#include <memory>
#include <string>

#include <vulkan/vulkan_raii.hpp>

#include "sky/core/result.hpp"

namespace sky::render {

class GpuContext {
 public:
  // Errors: Unsupported when no Vulkan driver or no device with a compute
  // queue and Vulkan 1.2 exists; Device for other Vulkan failures.
  // SKY_VULKAN_DEVICE=<substring> picks a device by name; otherwise a
  // discrete GPU is preferred over integrated, virtual, then CPU (lavapipe).
  static Result<std::unique_ptr<GpuContext>> create();

  const vk::raii::Device& device() const { return device_; }
  const vk::raii::PhysicalDevice& physicalDevice() const { return physical_; }
  const vk::raii::Queue& queue() const { return queue_; }
  const vk::raii::CommandPool& commandPool() const { return commandPool_; }
  const std::string& deviceName() const { return deviceName_; }

  // Index of a memory type allowed by typeBits with all of the flags; throws
  // vk::SystemError (caught at the module edge) when none exists.
  std::uint32_t memoryType(std::uint32_t typeBits, vk::MemoryPropertyFlags flags) const;

  vk::raii::CommandBuffer allocateCommandBuffer() const;

  // Submits and waits for completion. Errors: Timeout, Device.
  Result<void> submitAndWait(const vk::raii::CommandBuffer& commands, const vk::raii::Fence& fence) const;

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

  // Members are destroyed in reverse order: the pool before the device, the
  // device before the instance, the instance before the loader context.
  vk::raii::Context context_;
  vk::raii::Instance instance_{nullptr};
  vk::raii::PhysicalDevice physical_{nullptr};
  vk::raii::Device device_{nullptr};
  vk::raii::Queue queue_{nullptr};
  vk::raii::CommandPool commandPool_{nullptr};
  std::uint32_t queueFamily_ = 0;
  std::string deviceName_;
  bool debugUtils_ = false;
};

}  // namespace sky::render
