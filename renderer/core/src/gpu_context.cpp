// Vulkan instance/device selection, validation messages and submission (see
// gpu_context.hpp).
#include "gpu_context.hpp"

#include <algorithm>
#include <cstdlib>
#include <cstring>
#include <optional>
#include <vector>

namespace sky::render {

namespace {

int typeRank(vk::PhysicalDeviceType type) {
  switch (type) {
    case vk::PhysicalDeviceType::eDiscreteGpu: return 4;
    case vk::PhysicalDeviceType::eIntegratedGpu: return 3;
    case vk::PhysicalDeviceType::eVirtualGpu: return 2;
    case vk::PhysicalDeviceType::eCpu: return 1;
    default: return 0;
  }
}

// Khronos validation (Debian: vulkan-validationlayers).
constexpr const char* kValidationLayer = "VK_LAYER_KHRONOS_validation";
// Validation messages kept for the front end between two drains.
constexpr std::size_t kMaxValidationMessages = 256;

// A family that computes and, when there is a surface, presents to it.
std::optional<std::uint32_t> queueFamilyFor(const vk::raii::PhysicalDevice& device, const vk::raii::SurfaceKHR& surface) {
  const auto families = device.getQueueFamilyProperties();
  for (std::uint32_t i = 0; i < families.size(); ++i) {
    if (!(families[i].queueFlags & vk::QueueFlagBits::eCompute)) continue;
    if (static_cast<bool>(*surface) && !device.getSurfaceSupportKHR(i, *surface)) continue;
    return i;
  }
  return std::nullopt;
}

// The validation layer's callback: counts and keeps the message; never
// prints (the front end decides where it goes).
VKAPI_ATTR VkBool32 VKAPI_CALL onValidationMessage(VkDebugUtilsMessageSeverityFlagBitsEXT severity,
                                                   VkDebugUtilsMessageTypeFlagsEXT,
                                                   const VkDebugUtilsMessengerCallbackDataEXT* data, void* user) {
  auto* log = static_cast<ValidationLog*>(user);
  const bool error = severity & VK_DEBUG_UTILS_MESSAGE_SEVERITY_ERROR_BIT_EXT;
  std::lock_guard lock(log->mutex);
  (error ? log->counts.errors : log->counts.warnings) += 1;
  if (log->messages.size() == kMaxValidationMessages) log->messages.pop_front();
  log->messages.push_back(std::string(error ? "error: " : "warning: ") +
                          (data && data->pMessage ? data->pMessage : "(no message)"));
  return VK_FALSE;
}

}  // namespace

Result<std::unique_ptr<GpuContext>> GpuContext::create(const GpuOptions& options) {
  // A frame past GpuOptions::frameTimeout is treated as hung: a 4K frame on
  // lavapipe takes seconds, the default minute leaves room for sanitizer builds.
  if (options.frameTimeout <= std::chrono::milliseconds::zero())
    return fail(ErrorCode::InvalidArgument,
                "GPU frame timeout must be positive, not " + std::to_string(options.frameTimeout.count()) + " ms");
  std::unique_ptr<GpuContext> ctx(new GpuContext());
  ctx->frameTimeout_ = options.frameTimeout;

  bool haveDebugUtils = false;
  for (const auto& ext : ctx->context_.enumerateInstanceExtensionProperties())
    if (std::strcmp(ext.extensionName, VK_EXT_DEBUG_UTILS_EXTENSION_NAME) == 0) haveDebugUtils = true;
  std::vector<std::string> extensionNames;
  if (haveDebugUtils) extensionNames.push_back(VK_EXT_DEBUG_UTILS_EXTENSION_NAME);
  if (options.window)
    for (const auto& e : options.window->instanceExtensions)
      if (std::find(extensionNames.begin(), extensionNames.end(), e) == extensionNames.end()) extensionNames.push_back(e);
  std::vector<const char*> extensions;
  for (const auto& e : extensionNames) extensions.push_back(e.c_str());

  std::vector<const char*> layers;
  if (options.validation) {
    if (!haveDebugUtils)
      return fail(ErrorCode::Unsupported, "Vulkan validation asked for, but VK_EXT_debug_utils is missing");
    bool found = false;
    for (const auto& l : ctx->context_.enumerateInstanceLayerProperties())
      if (std::strcmp(l.layerName, kValidationLayer) == 0) found = true;
    if (!found)
      return fail(ErrorCode::Unsupported,
                  std::string("Vulkan validation asked for, but ") + kValidationLayer +
                      " is not installed (Debian: vulkan-validationlayers)");
    layers.push_back(kValidationLayer);
  }

  const vk::ApplicationInfo app("skyshell-render", 1, "skyshell", 1, VK_API_VERSION_1_2);
  const vk::InstanceCreateInfo instanceInfo({}, &app, layers, extensions);
  try {
    ctx->instance_ = vk::raii::Instance(ctx->context_, instanceInfo);
  } catch (const vk::IncompatibleDriverError& e) {
    return fail(ErrorCode::NoDevice, std::string("no Vulkan driver: ") + e.what());
  } catch (const vk::InitializationFailedError& e) {
    return fail(ErrorCode::NoDevice, std::string("no Vulkan driver: ") + e.what());
  } catch (const vk::ExtensionNotPresentError& e) {
    return fail(ErrorCode::Unsupported, std::string("Vulkan instance extension missing: ") + e.what());
  }
  ctx->debugUtils_ = haveDebugUtils;
  if (options.validation) {
    ctx->validationLog_ = std::make_unique<ValidationLog>();
    using Severity = vk::DebugUtilsMessageSeverityFlagBitsEXT;
    using Type = vk::DebugUtilsMessageTypeFlagBitsEXT;
    const vk::DebugUtilsMessengerCreateInfoEXT info(
        {}, Severity::eWarning | Severity::eError, Type::eGeneral | Type::eValidation | Type::ePerformance,
        &onValidationMessage, ctx->validationLog_.get());
    ctx->messenger_ = vk::raii::DebugUtilsMessengerEXT(ctx->instance_, info);
  }
  if (options.window) {
    const VkSurfaceKHR raw = options.window->createSurface(static_cast<VkInstance>(*ctx->instance_));
    if (raw == VK_NULL_HANDLE) return fail(ErrorCode::Device, "the window system could not create a Vulkan surface");
    ctx->surface_ = vk::raii::SurfaceKHR(ctx->instance_, raw);
  }

  const char* wanted = std::getenv("SKY_VULKAN_DEVICE");
  vk::raii::PhysicalDevices devices(ctx->instance_);
  int bestRank = -1;
  std::size_t best = 0;
  std::uint32_t bestFamily = 0;
  std::string seen;
  for (std::size_t i = 0; i < devices.size(); ++i) {
    const auto props = devices[i].getProperties();
    const std::string deviceName = props.deviceName.data();
    seen += (seen.empty() ? "" : ", ") + deviceName;
    if (props.apiVersion < VK_API_VERSION_1_2) continue;
    const auto family = queueFamilyFor(devices[i], ctx->surface_);
    if (!family) continue;
    if (wanted != nullptr && deviceName.find(wanted) == std::string::npos) continue;
    const int rank = typeRank(props.deviceType);
    if (rank > bestRank) bestRank = rank, best = i, bestFamily = *family;
  }
  // No device at all is a missing dependency (NoDevice); devices that are
  // there but unfit, or not the one asked for, are not.
  if (bestRank < 0)
    return fail(seen.empty() ? ErrorCode::NoDevice : ErrorCode::Unsupported,
                std::string("no Vulkan 1.2 device with a compute queue") +
                    (options.window ? " that can present to the window" : "") +
                    (wanted ? std::string(" matching SKY_VULKAN_DEVICE=") + wanted : std::string()) +
                    " (devices: " + (seen.empty() ? "none" : seen) + ")");
  ctx->physical_ = std::move(devices[best]);
  const auto props = ctx->physical_.getProperties();
  ctx->deviceName_ = props.deviceName.data();
  ctx->queueFamily_ = bestFamily;
  ctx->timestampValidBits_ = ctx->physical_.getQueueFamilyProperties()[bestFamily].timestampValidBits;
  ctx->timestampPeriod_ns_ = props.limits.timestampPeriod;

  const float priority = 1.0f;
  const vk::DeviceQueueCreateInfo queueInfo({}, ctx->queueFamily_, 1, &priority);
  std::vector<const char*> deviceExtensions;
  if (options.window) deviceExtensions.push_back(VK_KHR_SWAPCHAIN_EXTENSION_NAME);
  const vk::DeviceCreateInfo deviceInfo({}, queueInfo, {}, deviceExtensions);
  ctx->device_ = vk::raii::Device(ctx->physical_, deviceInfo);
  ctx->queue_ = vk::raii::Queue(ctx->device_, ctx->queueFamily_, 0);
  ctx->commandPool_ = vk::raii::CommandPool(
      ctx->device_, vk::CommandPoolCreateInfo(vk::CommandPoolCreateFlagBits::eResetCommandBuffer, ctx->queueFamily_));
  ctx->name(ctx->device_, "sky.device");
  ctx->name(ctx->queue_, "sky.queue");
  ctx->name(ctx->commandPool_, "sky.commandPool");
  return ctx;
}

std::vector<std::string> GpuContext::takeValidationMessages() {
  if (!validationLog_) return {};
  std::lock_guard lock(validationLog_->mutex);
  std::vector<std::string> out(validationLog_->messages.begin(), validationLog_->messages.end());
  validationLog_->messages.clear();
  return out;
}

ValidationCounts GpuContext::validationCounts() {
  if (!validationLog_) return {};
  std::lock_guard lock(validationLog_->mutex);
  return validationLog_->counts;
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
  const vk::Result waited = device_.waitForFences(*fence, VK_TRUE, fenceTimeout_ns());
  if (waited == vk::Result::eTimeout) {
    // The work is still running and owns the command buffer and the
    // resources it reads: the caller may free them once it has the error
    // (a frame slower than the timeout freed them under lavapipe's running
    // threads and crashed the bench). lavapipe finishes what it started.
    device_.waitIdle();
    return fail(ErrorCode::Timeout, "GPU frame did not finish within " + timeoutText());
  }
  if (waited != vk::Result::eSuccess) return fail(ErrorCode::Device, "waitForFences: " + vk::to_string(waited));
  return {};
}

Result<void> GpuContext::wait(const vk::raii::Fence& fence) const {
  const vk::Result waited = device_.waitForFences(*fence, VK_TRUE, fenceTimeout_ns());
  if (waited == vk::Result::eTimeout) {
    device_.waitIdle();  // as in submitAndWait
    return fail(ErrorCode::Timeout, "GPU work did not finish within " + timeoutText());
  }
  if (waited != vk::Result::eSuccess) return fail(ErrorCode::Device, "waitForFences: " + vk::to_string(waited));
  return {};
}

}  // namespace sky::render
