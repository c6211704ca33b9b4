// One CloudRenderer per image size for the whole test program (creating a
// Vulkan device and compiling the pass costs more than a frame). Tests skip,
// never pass, when no Vulkan device exists. The shared renderers live until
// the process ends, on purpose: destroying the last Vulkan instance unloads
// the driver, and LeakSanitizer could then no longer attribute the driver's
// own leaks to it (see lsan.supp). Destruction is tested on its own.
#pragma once

#include <map>
#include <memory>
#include <utility>

#include <gtest/gtest.h>

#include "sky/render/cloud_renderer.hpp"

namespace sky::test {

// nullptr with *skipReason set when there is no device; fails the test on any
// other error.
inline render::CloudRenderer* sharedRenderer(std::uint32_t width, std::uint32_t height, std::string* skipReason) {
  using Map = std::map<std::pair<std::uint32_t, std::uint32_t>, std::unique_ptr<render::CloudRenderer>>;
  static Map& renderers = *new Map;  // never destroyed: reachable, so not a leak
  static std::string noDevice;
  if (!noDevice.empty()) {
    *skipReason = noDevice;
    return nullptr;
  }
  auto& slot = renderers[{width, height}];
  if (!slot) {
    render::RenderSettings settings;
    settings.width = width;
    settings.height = height;
    auto created = render::CloudRenderer::create(settings);
    if (!created) {
      if (created.error().code == ErrorCode::NoDevice) {
        noDevice = "no Vulkan device: " + describe(created.error());
        *skipReason = noDevice;
        return nullptr;
      }
      ADD_FAILURE() << describe(created.error());
      return nullptr;
    }
    slot = std::move(*created);
  }
  return slot.get();
}

}  // namespace sky::test

// Declares `renderer` (CloudRenderer&) or skips/fails the current test.
#define SKY_RENDERER(renderer, width, height)                                              \
  std::string renderer##SkipReason;                                                        \
  auto* renderer##Ptr = ::sky::test::sharedRenderer(width, height, &renderer##SkipReason); \
  if (renderer##Ptr == nullptr) {                                                          \
    if (!renderer##SkipReason.empty()) GTEST_SKIP() << renderer##SkipReason;               \
    return;                                                                                \
  }                                                                                        \
  ::sky::render::CloudRenderer& renderer = *renderer##Ptr
