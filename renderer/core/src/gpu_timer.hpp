// GPU time per pass: a timestamp query pool owned by one pass, and a scoped
// section that writes a timestamp when it opens and another when it closes,
// around the pass's commands. Every pass times itself through this type, so
// each frame reports the same names. On lavapipe timestamps tick in 1 ns and
// match fence wall time within 0.3 ms (reference/lavapipe.md).
#pragma once

#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include <vulkan/vulkan_raii.hpp>

#include "gpu_context.hpp"
#include "sky/render/cloud_renderer.hpp"

namespace sky::render {

class GpuTimer {
 public:
  class Section {
   public:
    Section(const Section&) = delete;
    Section& operator=(const Section&) = delete;
    Section(Section&& other) noexcept
        : timer_(std::exchange(other.timer_, nullptr)), commands_(other.commands_), query_(other.query_) {}
    Section& operator=(Section&&) = delete;
    // Writes the closing timestamp (bottom of pipe: after every command
    // recorded before it has finished).
    ~Section();

   private:
    friend class GpuTimer;
    Section(GpuTimer* timer, const vk::raii::CommandBuffer* commands, std::uint32_t query)
        : timer_(timer), commands_(commands), query_(query) {}
    GpuTimer* timer_;
    const vk::raii::CommandBuffer* commands_;
    std::uint32_t query_;
  };

  GpuTimer() = default;
  // A pool for up to maxSections sections per recording. A queue without
  // timestamps (timestampValidBits 0) gives a timer that records nothing.
  // Vulkan failures throw.
  GpuTimer(const GpuContext& ctx, std::uint32_t maxSections, const char* debugName);

  // Starts a recording: resets the pool's queries in `commands` and forgets
  // the previous sections. Call before the first section of a command buffer.
  void begin(const vk::raii::CommandBuffer& commands);

  // Opens a named section in `commands` (top of pipe timestamp); it closes
  // when the returned object goes out of scope. At most maxSections per
  // recording (asserted).
  [[nodiscard]] Section section(const vk::raii::CommandBuffer& commands, std::string pass);

  // After the recording's submission completed: each section's GPU time, in
  // the order opened. Empty for a timer without timestamps.
  std::vector<PassTime> results() const;

 private:
  // Destroyed with the timer; the pool must not be in use by the GPU then
  // (every pass waits for its fence before it is destroyed or re-recorded).
  vk::raii::QueryPool pool_{nullptr};
  std::uint32_t maxSections_ = 0;
  double period_ns_ = 0;     // ns per timestamp tick
  std::uint64_t validMask_ = 0;
  std::vector<std::string> names_;  // sections of the current recording
};

}  // namespace sky::render
