// Swapchain and per-frame presentation (see presenter.hpp).
#include "presenter.hpp"

#include <algorithm>
#include <array>
#include <cstring>

#include "image_output.hpp"
#include "sky/core/assert.hpp"

namespace sky::render {

namespace {

// How long to wait for a swapchain image, ns: a window that cannot take a
// frame for this long is treated as not showing one this time.
constexpr std::uint64_t kAcquireTimeout_ns = 5'000'000'000ull;

// 8-bit formats whose bytes the display transform can fill directly, in the
// order preferred; for the sRGB ones the bytes are already sRGB-encoded (the
// copy does not convert), so both kinds show the PNG's values.
struct FormatChoice {
  vk::Format format;
  bool bgra;
};
constexpr std::array kFormats = {FormatChoice{vk::Format::eB8G8R8A8Unorm, true},
                                 FormatChoice{vk::Format::eR8G8B8A8Unorm, false},
                                 FormatChoice{vk::Format::eB8G8R8A8Srgb, true},
                                 FormatChoice{vk::Format::eR8G8B8A8Srgb, false}};

}  // namespace

Presenter::~Presenter() {
  // The last frame may still be presenting: nothing here may be destroyed
  // while the device uses it.
  if (device_ != nullptr && *swapchain_) (void)device_->getDispatcher()->vkDeviceWaitIdle(static_cast<VkDevice>(**device_));
}

Result<Presenter> Presenter::create(const GpuContext& ctx, const WindowSurface& window) {
  SKY_ASSERT(static_cast<bool>(*ctx.surface()));
  Presenter p;
  p.window_ = &window;
  p.device_ = &ctx.device();
  const auto formats = ctx.physicalDevice().getSurfaceFormatsKHR(*ctx.surface());
  bool found = false;
  for (const auto& want : kFormats) {
    for (const auto& f : formats)
      if (f.format == want.format && f.colorSpace == vk::ColorSpaceKHR::eSrgbNonlinear) {
        p.format_ = f;
        p.bgra_ = want.bgra;
        found = true;
        break;
      }
    if (found) break;
  }
  if (!found) return fail(ErrorCode::Unsupported, "the window surface offers no 8-bit RGBA or BGRA sRGB format");
  const auto caps = ctx.physicalDevice().getSurfaceCapabilitiesKHR(*ctx.surface());
  if (!(caps.supportedUsageFlags & vk::ImageUsageFlagBits::eTransferDst))
    return fail(ErrorCode::Unsupported, "the window's swapchain images cannot be copied to");

  p.timer_ = GpuTimer(ctx, 1, "sky.present.timer");
  p.commands_ = ctx.allocateCommandBuffer();
  ctx.name(p.commands_, "sky.present.commands");
  p.acquired_ = vk::raii::Semaphore(ctx.device(), vk::SemaphoreCreateInfo());
  ctx.name(p.acquired_, "sky.present.acquired");
  p.fence_ = vk::raii::Fence(ctx.device(), vk::FenceCreateInfo(vk::FenceCreateFlagBits::eSignaled));
  ctx.name(p.fence_, "sky.present.fence");
  if (auto ok = p.rebuild(ctx); !ok) return tl::unexpected(ok.error());
  return p;
}

Result<void> Presenter::rebuild(const GpuContext& ctx) {
  ctx.device().waitIdle();
  const auto caps = ctx.physicalDevice().getSurfaceCapabilitiesKHR(*ctx.surface());
  vk::Extent2D extent = caps.currentExtent;
  if (extent.width == 0xFFFFFFFFu) {
    // The surface takes its size from the swapchain: the window's drawable size.
    const auto [w, h] = window_->framebufferSize();
    extent = vk::Extent2D(std::clamp(w, caps.minImageExtent.width, caps.maxImageExtent.width),
                          std::clamp(h, caps.minImageExtent.height, caps.maxImageExtent.height));
  }
  extent_ = extent;
  stale_ = false;
  if (extent.width == 0 || extent.height == 0) {  // minimised: nothing to build until it comes back
    stale_ = true;
    return {};
  }
  std::uint32_t count = caps.minImageCount + 1;
  if (caps.maxImageCount > 0) count = std::min(count, caps.maxImageCount);
  vk::CompositeAlphaFlagBitsKHR alpha = vk::CompositeAlphaFlagBitsKHR::eOpaque;
  if (!(caps.supportedCompositeAlpha & alpha)) alpha = vk::CompositeAlphaFlagBitsKHR::eInherit;
  // FIFO is the one mode every implementation has; an image generator is
  // paced by its host, not by the display.
  const vk::SwapchainCreateInfoKHR info({}, *ctx.surface(), count, format_.format, format_.colorSpace, extent, 1,
                                        vk::ImageUsageFlagBits::eTransferDst, vk::SharingMode::eExclusive, {},
                                        caps.currentTransform, alpha, vk::PresentModeKHR::eFifo, VK_TRUE,
                                        *swapchain_);
  vk::raii::SwapchainKHR next(ctx.device(), info);
  swapchain_ = std::move(next);  // the old one goes once the new one exists (oldSwapchain above)
  ctx.name(swapchain_, "sky.swapchain");
  images_.clear();
  for (const VkImage image : swapchain_.getImages()) images_.push_back(vk::Image(image));
  copied_.clear();
  for (std::size_t i = 0; i < images_.size(); ++i) {
    copied_.emplace_back(ctx.device(), vk::SemaphoreCreateInfo());
    ctx.name(copied_.back(), "sky.present.copied");
  }
  staging_ = createHostBuffer(ctx, vk::DeviceSize(extent.width) * extent.height * 4,
                              vk::BufferUsageFlagBits::eTransferSrc, "sky.present.staging");
  return {};
}

Result<bool> Presenter::present(const GpuContext& ctx, const Image& image, double exposure) {
  SKY_ASSERT(image.width > 0 && image.height > 0 && image.rgba.size() == std::size_t(image.width) * image.height * 4);
  if (stale_) {
    if (auto ok = rebuild(ctx); !ok) return tl::unexpected(ok.error());
    if (stale_) return false;  // still minimised
  }

  // The previous frame's copy must be done before its staging buffer and
  // command buffer are reused.
  if (auto ok = ctx.wait(fence_); !ok) return tl::unexpected(ok.error());
  std::uint32_t index = 0;
  try {
    const auto [acquired, i] = swapchain_.acquireNextImage(kAcquireTimeout_ns, *acquired_);
    if (acquired == vk::Result::eTimeout || acquired == vk::Result::eNotReady) return false;
    if (acquired == vk::Result::eSuboptimalKHR) stale_ = true;  // still usable: show this one, rebuild after
    index = i;
  } catch (const vk::OutOfDateKHRError&) {
    stale_ = true;
    return false;
  }

  // The PNG's bytes, in the swapchain's byte order, scaled by nearest pixel.
  const std::vector<std::uint8_t> rgb = tonemapToSrgb8(image, exposure);
  auto* out = static_cast<std::uint8_t*>(staging_.mapped);
  for (std::uint32_t y = 0; y < extent_.height; ++y) {
    const std::uint32_t sy = std::uint32_t(std::uint64_t(y) * image.height / extent_.height);
    for (std::uint32_t x = 0; x < extent_.width; ++x) {
      const std::uint32_t sx = std::uint32_t(std::uint64_t(x) * image.width / extent_.width);
      const std::uint8_t* src = &rgb[(std::size_t(sy) * image.width + sx) * 3];
      std::uint8_t* dst = &out[(std::size_t(y) * extent_.width + x) * 4];
      dst[0] = bgra_ ? src[2] : src[0];
      dst[1] = src[1];
      dst[2] = bgra_ ? src[0] : src[2];
      dst[3] = 255;
    }
  }

  const vk::Image target = images_[index];
  const vk::ImageSubresourceRange range(vk::ImageAspectFlagBits::eColor, 0, 1, 0, 1);
  commands_.reset();
  commands_.begin(vk::CommandBufferBeginInfo(vk::CommandBufferUsageFlagBits::eOneTimeSubmit));
  timer_.begin(commands_);
  {
    const auto timed = timer_.section(commands_, "present");
    // Undefined -> transfer destination: the whole image is overwritten.
    const vk::ImageMemoryBarrier toCopy({}, vk::AccessFlagBits::eTransferWrite, vk::ImageLayout::eUndefined,
                                        vk::ImageLayout::eTransferDstOptimal, VK_QUEUE_FAMILY_IGNORED,
                                        VK_QUEUE_FAMILY_IGNORED, target, range);
    commands_.pipelineBarrier(vk::PipelineStageFlagBits::eTransfer, vk::PipelineStageFlagBits::eTransfer, {}, {}, {},
                              toCopy);
    const vk::BufferImageCopy region(0, 0, 0, vk::ImageSubresourceLayers(vk::ImageAspectFlagBits::eColor, 0, 0, 1),
                                     {0, 0, 0}, vk::Extent3D(extent_.width, extent_.height, 1));
    commands_.copyBufferToImage(*staging_.buffer, target, vk::ImageLayout::eTransferDstOptimal, region);
    const vk::ImageMemoryBarrier toPresent(vk::AccessFlagBits::eTransferWrite, {}, vk::ImageLayout::eTransferDstOptimal,
                                           vk::ImageLayout::ePresentSrcKHR, VK_QUEUE_FAMILY_IGNORED,
                                           VK_QUEUE_FAMILY_IGNORED, target, range);
    commands_.pipelineBarrier(vk::PipelineStageFlagBits::eTransfer, vk::PipelineStageFlagBits::eBottomOfPipe, {}, {},
                              {}, toPresent);
  }
  commands_.end();

  ctx.device().resetFences(*fence_);
  const vk::Semaphore wait = *acquired_, signal = *copied_[index];
  const vk::PipelineStageFlags waitStage = vk::PipelineStageFlagBits::eTransfer;
  const vk::CommandBuffer raw = *commands_;
  ctx.queue().submit(vk::SubmitInfo(wait, waitStage, raw, signal), *fence_);
  const vk::SwapchainKHR chain = *swapchain_;
  try {
    if (ctx.queue().presentKHR(vk::PresentInfoKHR(signal, chain, index)) == vk::Result::eSuboptimalKHR) stale_ = true;
  } catch (const vk::OutOfDateKHRError&) {
    stale_ = true;
  }
  // Blocking, like the render: the timestamps are read after this, and the
  // staging buffer is free for the next frame.
  if (auto ok = ctx.wait(fence_); !ok) return tl::unexpected(ok.error());
  ++presented_;
  return true;
}

}  // namespace sky::render
