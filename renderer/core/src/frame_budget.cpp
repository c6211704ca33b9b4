// The frame-time budget's ladder and controller (see frame_budget.hpp).
#include "sky/render/frame_budget.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>

#include "sky/core/assert.hpp"

namespace sky::render {

namespace {

// How much less each level marches: its samples (or step lengths) over the
// first level's.
constexpr std::array<double, 5> kStepFactors = {1.0, 1.5, 2.0, 3.0, 4.0};

// Each preset's ladder measured with skyshell-bench on this machine (2-core
// AMD EPYC VM, lavapipe, Release; 2026-12-04): frame time over the first
// level's (the sums over the scenes) and the mean PSNR against reference
// (the sun's column marched), 320x180, the still scenes cumulus-midday,
// sunset-backlit, cumulonimbus, godrays and overcast-below:
//   skyshell-bench --scenes cumulus-midday,sunset-backlit,cumulonimbus,godrays,overcast-below
//     --configs "P-0:base=P,budget=0;...;P-4:base=P,budget=4" --resolution 320x180 --warmup 1 --repeats 3
// A ladder ends where the next level saved less than 2 % of the time (or
// cost more: medium's third level measured 0.955 after its second's 0.918,
// low's third 0.924 after 0.941). With the sun from a map the samples are
// a smaller part of a frame than they were with the light march: the map's
// reads by the air table and the ground, the reprojection and the upscale
// do not scale with them, so only high has a ladder of any range. The
// controller learns the absolute scale while it runs; these give the shape.
struct Measured {
  const char* preset;
  std::size_t levels;
  std::array<double, kStepFactors.size()> relativeCost;
  std::array<double, kStepFactors.size()> psnr_db;
};
constexpr std::array<Measured, 4> kMeasured = {{
    // high measured again on all five scenes after the wind field's code
    // went into a pipeline variant of its own (a frame without a wind field
    // holds none of it): sums 371.3, 321.9, 288.2, 266.3, 251.8 ms, the
    // noisy cumulus-midday's levels 3 and 4 the mean of two runs (50.9 and
    // 65.6, 62.7 and 48.2 ms). FrameBudget's uniform deck gave 0.83, 0.74,
    // 0.66, 0.62 the same day.
    {"high", 5, {1.0, 0.867, 0.776, 0.717, 0.678}, {39.8, 37.7, 35.7, 32.7, 30.3}},
    {"medium", 2, {1.0, 0.918, 0, 0, 0}, {42.0, 41.4, 0, 0, 0}},
    {"low", 2, {1.0, 0.941, 0, 0, 0}, {40.2, 40.4, 0, 0, 0}},
    {"realtime", 2, {1.0, 0.957, 0, 0, 0}, {36.1, 36.3, 0, 0, 0}},
}};

MarchSettings cheaper(const MarchSettings& m0, std::size_t k) {
  const double f = kStepFactors[k];
  MarchSettings m = m0;
  if (m.cloudStep_m > 0) {
    m.cloudStep_m = std::min(m0.cloudStep_m * f, 10000.0);
    m.emptyStep_m = std::min(m0.emptyStep_m * f, 20000.0);
    m.stepGrowth = std::min(m0.stepGrowth * f, 1.0);
  } else {
    m.primarySteps = std::max<std::uint32_t>(8, std::uint32_t(std::lround(m0.primarySteps / f)));
  }
  if (k >= 2) m.lightSteps = std::max<std::uint32_t>(2, m0.lightSteps - 1);
  m.minTransmittance = k == 0 ? m0.minTransmittance : std::max(m0.minTransmittance, 0.01 * f);
  return m;
}

}  // namespace

Result<std::vector<BudgetLevel>> budgetLadder(const Preset& p) {
  const auto measured = std::find_if(kMeasured.begin(), kMeasured.end(),
                                     [&](const Measured& m) { return p.name == m.preset; });
  if (measured == kMeasured.end())
    return fail(ErrorCode::InvalidArgument, "frame budget: preset '" + p.name +
                                                "' has no measured ladder (high, medium, low or realtime)");
  std::vector<BudgetLevel> ladder;
  for (std::size_t k = 0; k < measured->levels; ++k) {
    char name[64];
    if (k == 0)
      std::snprintf(name, sizeof name, "%s", p.name.c_str());
    else
      std::snprintf(name, sizeof name, "%s/%g", p.name.c_str(), kStepFactors[k]);
    ladder.push_back({name, cheaper(p.march, k), measured->relativeCost[k], measured->psnr_db[k]});
  }
  return ladder;
}

FrameBudget::FrameBudget(double target_ms, std::vector<BudgetLevel> ladder)
    : target_ms_(target_ms), ladder_(std::move(ladder)) {
  SKY_ASSERT(target_ms_ > 0 && !ladder_.empty());
  for (std::size_t i = 1; i < ladder_.size(); ++i) SKY_ASSERT(ladder_[i].relativeCost < ladder_[i - 1].relativeCost);
}

std::size_t FrameBudget::update(double frame_ms) {
  if (!(frame_ms > 0) || !std::isfinite(frame_ms)) return level_;
  // A frame's time over its level's cost is this machine's speed on this
  // scene; a mean over the last few frames (weight 1/4 for the newest) rides
  // out single slow frames but follows a change of scene within a second.
  const double sample = frame_ms / ladder_[level_].relativeCost;
  msPerCost_ = frames_ == 0 ? sample : 0.75 * msPerCost_ + 0.25 * sample;
  ++frames_;
  // Over the budget: cheaper at once when far over (10 %), else after two
  // frames over in a row, so one slow frame moves nothing.
  const double current = predicted_ms(level_);
  over_ = current > target_ms_ ? over_ + 1 : 0;
  if (current > target_ms_ && (current > 1.1 * target_ms_ || over_ >= 2)) {
    while (level_ + 1 < ladder_.size() && predicted_ms(level_) > target_ms_) ++level_;
    over_ = 0;
    return level_;
  }
  // Under it: the most accurate dearer level that fits with 5 % to spare.
  for (std::size_t i = 0; i < level_; ++i)
    if (predicted_ms(i) <= 0.95 * target_ms_) {
      level_ = i;
      break;
    }
  return level_;
}

}  // namespace sky::render
