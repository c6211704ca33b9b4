// Vulkan instance/device selection and submission (see gpu_context.hpp).
#include "gpu_context.hpp"

#include <cstdlib>
#include <cstring>
#include <optional>
#include <vector>

namespace sky::render {

namespace {

// A frame that takes longer than this is treated as a lost device, ns. A
// 4K frame on lavapipe takes seconds; 60 s leaves room for sanitizer builds.
constexpr std::uint64_t kFenceTimeout_ns = 60'000'000'000ull;

int typeRank(vk::PhysicalDeviceType type) {
  switch (type) {
    case vk::PhysicalDeviceType::eDiscreteGpu: return 4;
    case vk::PhysicalDeviceType::eIntegratedGpu: return 3;
    case vk::PhysicalDeviceType::eVirtualGpu: return 2;
    case vk::PhysicalDeviceType::eCpu: return 1;
    default: return 0;
  }
}

std::optional<std::uint32_t> computeFamily(const vk::raii::PhysicalDevice& device) {
  const auto families = device.getQueueFamilyProperties();
  for (std::uint32_t i = 0; i < families.size(); ++i)
    if (families[i].queueFlags & vk::QueueFlagBits::eCompute) return i;
  return std::nullopt;
}

}  // namespace

Result<std::unique_ptr<GpuContext>> GpuContext::create() {
  std::unique_ptr<GpuContext> ctx(new GpuContext());

  bool haveDebugUtils = false;
  for (const auto& ext : ctx->context_.enumerateInstanceExtensionProperties())
    if (std::strcmp(ext.extensionName, VK_EXT_DEBUG_UTILS_EXTENSION_NAME) == 0) haveDebugUtils = true;
  std::vector<const char*> extensions;
  if (haveDebugUtils) extensions.push_back(VK_EXT_DEBUG_UTILS_EXTENSION_NAME);

  const vk::ApplicationInfo app("skyshell-render", 1, "skyshell", 1, VK_API_VERSION_1_2);
  const vk::InstanceCreateInfo instanceInfo({}, &app, {}, extensions);
  try {
    ctx->instance_ = vk::raii::Instance(ctx->context_, instanceInfo);
  } catch (const vk::IncompatibleDriverError& e) {
    return fail(ErrorCode::Unsupported, std::string("no Vulkan driver: ") + e.what());
  } catch (const vk::InitializationFailedError& e) {
    return fail(ErrorCode::Unsupported, std::string("no Vulkan driver: ") + e.what());
  }
  ctx->debugUtils_ = haveDebugUtils;

  const char* wanted = std::getenv("SKY_VULKAN_DEVICE");
  vk::raii::PhysicalDevices devices(ctx->instance_);
  int bestRank = -1;
  std::size_t best = 0;
  std::string seen;
  for (std::size_t i = 0; i < devices.size(); ++i) {
    const auto props = devices[i].getProperties();
    const std::string deviceName = props.deviceName.data();
    seen += (seen.empty() ? "" : ", ") + deviceName;
    if (props.apiVersion < VK_API_VERSION_1_2 || !computeFamily(devices[i])) continue;
    if (wanted != nullptr && deviceName.find(wanted) == std::string::npos) continue;
    const int rank = typeRank(props.deviceType);
    if (rank > bestRank) bestRank = rank, best = i;
  }
  if (bestRank < 0)
    return fail(ErrorCode::Unsupported,
                "no Vulkan 1.2 device with a compute queue" +
                    (wanted ? std::string(" matching SKY_VULKAN_DEVICE=") + wanted : std::string()) +
                    " (devices: " + (seen.empty() ? "none" : seen) + ")");
  ctx->physical_ = std::move(devices[best]);
  ctx->deviceName_ = ctx->physical_.getProperties().deviceName.data();
  ctx->queueFamily_ = *computeFamily(ctx->physical_);

  const float priority = 1.0f;
  const vk::DeviceQueueCreateInfo queueInfo({}, ctx->queueFamily_, 1, &priority);
  const vk::DeviceCreateInfo deviceInfo({}, queueInfo);
  ctx->device_ = vk::raii::Device(ctx->physical_, deviceInfo);
  ctx->queue_ = vk::raii::Queue(ctx->device_, ctx->queueFamily_, 0);
  ctx->commandPool_ = vk::raii::CommandPool(
      ctx->device_, vk::CommandPoolCreateInfo(vk::CommandPoolCreateFlagBits::eResetCommandBuffer, ctx->queueFamily_));
  ctx->name(ctx->device_, "sky.device");
  ctx->name(ctx->queue_, "sky.computeQueue");
  ctx->name(ctx->commandPool_, "sky.commandPool");
  return ctx;
}

std::uint32_t GpuContext::memoryType(std::uint32_t typeBits, vk::MemoryPropertyFlags flags) const {
  const auto props = physical_.getMemoryProperties();
  for (std::uint32_t i = 0; i < props.memoryTypeCount; ++i)
    if ((typeBits & (1u << i)) && (props.memoryTypes[i].propertyFlags & flags) == flags) return i;
  throw vk::OutOfDeviceMemoryError("no memory type with the required properties");
}

vk::raii::CommandBuffer GpuContext::allocateCommandBuffer() const {
  vk::raii::CommandBuffers buffers(
      device_, vk::CommandBufferAllocateInfo(*commandPool_, vk::CommandBufferLevel::ePrimary, 1));
  return std::move(buffers.front());
}

Result<void> GpuContext::submitAndWait(const vk::raii::CommandBuffer& commands, const vk::raii::Fence& fence) const {
  device_.resetFences(*fence);
  const vk::CommandBuffer raw = *commands;
  queue_.submit(vk::SubmitInfo({}, {}, raw), *fence);
  const vk::Result waited = device_.waitForFences(*fence, VK_TRUE, kFenceTimeout_ns);
  if (waited == vk::Result::eTimeout) return fail(ErrorCode::Timeout, "GPU frame did not finish within 60 s");
  if (waited != vk::Result::eSuccess) return fail(ErrorCode::Device, "waitForFences: " + vk::to_string(waited));
  return {};
}

}  // namespace sky::render
