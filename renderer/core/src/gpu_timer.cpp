// Timestamp queries around passes (see gpu_timer.hpp).
#include "gpu_timer.hpp"

#include "sky/core/assert.hpp"

namespace sky::render {

GpuTimer::GpuTimer(const GpuContext& ctx, std::uint32_t maxSections, const char* debugName)
    : maxSections_(maxSections) {
  SKY_ASSERT(maxSections > 0);
  const std::uint32_t bits = ctx.timestampValidBits();
  if (bits == 0) return;
  validMask_ = bits >= 64 ? ~std::uint64_t(0) : (std::uint64_t(1) << bits) - 1;
  period_ns_ = ctx.timestampPeriod_ns();
  pool_ = vk::raii::QueryPool(ctx.device(),
                              vk::QueryPoolCreateInfo({}, vk::QueryType::eTimestamp, 2 * maxSections));
  ctx.name(pool_, debugName);
}

void GpuTimer::begin(const vk::raii::CommandBuffer& commands) {
  names_.clear();
  if (validMask_ == 0) return;
  commands.resetQueryPool(*pool_, 0, 2 * maxSections_);
}

GpuTimer::Section GpuTimer::section(const vk::raii::CommandBuffer& commands, std::string pass) {
  SKY_ASSERT(names_.size() < maxSections_);
  const auto query = static_cast<std::uint32_t>(2 * names_.size());
  names_.push_back(std::move(pass));
  if (validMask_ == 0) return Section(nullptr, &commands, query);
  commands.writeTimestamp(vk::PipelineStageFlagBits::eTopOfPipe, *pool_, query);
  return Section(this, &commands, query);
}

GpuTimer::Section::~Section() {
  if (timer_ == nullptr) return;
  commands_->writeTimestamp(vk::PipelineStageFlagBits::eBottomOfPipe, *timer_->pool_, query_ + 1);
}

std::vector<PassTime> GpuTimer::results() const {
  std::vector<PassTime> out;
  if (validMask_ == 0 || names_.empty()) return out;
  const auto count = static_cast<std::uint32_t>(2 * names_.size());
  // The submission has completed (the caller waited for its fence), so
  // eWait returns at once; 64-bit values, masked to the valid bits.
  const auto [result, ticks] = pool_.getResults<std::uint64_t>(
      0, count, count * sizeof(std::uint64_t), sizeof(std::uint64_t),
      vk::QueryResultFlagBits::e64 | vk::QueryResultFlagBits::eWait);
  if (result != vk::Result::eSuccess) return out;
  for (std::size_t i = 0; i < names_.size(); ++i) {
    const std::uint64_t t0 = ticks[2 * i] & validMask_, t1 = ticks[2 * i + 1] & validMask_;
    // Wrap-around of a counter narrower than 64 bits.
    const std::uint64_t elapsed = (t1 - t0) & validMask_;
    out.push_back({names_[i], double(elapsed) * period_ns_ * 1e-6});
  }
  return out;
}

}  // namespace sky::render
