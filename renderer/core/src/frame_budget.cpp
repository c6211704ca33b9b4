// The frame-time budget's ladder and controller (see frame_budget.hpp).
#include "sky/render/frame_budget.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <cstring>

#include "sky/core/assert.hpp"

namespace sky::render {

namespace {

// How much less each level marches: its samples (or step lengths) over the
// first level's.
constexpr std::array<double, 5> kStepFactors = {1.0, 1.5, 2.0, 3.0, 4.0};

// Each preset's ladder measured with skyshell-bench on this machine (2-core
// AMD EPYC VM, lavapipe, LP_NUM_THREADS=2, Release; 2026-12-06): a level's
// frame time over the first level's (the sums of the scenes' median frame
// times) and its mean PSNR against reference (the sun's column marched),
// 320x180, over the still scenes cumulus-midday, sunset-backlit,
// cumulonimbus, godrays and overcast-below and the camera paths fast-turn
// and glider-thermal (each path's mean over its frames: the interleaved
// ways are judged in motion too, where their history lags):
//   skyshell-bench --scenes cumulus-midday,sunset-backlit,cumulonimbus,godrays,overcast-below,fast-turn,glider-thermal
//     --configs "P-0:base=P,budget=0;...;P-K:base=P,budget=K" --resolution 320x180 --warmup 1 --repeats 3
// run with every candidate in the ladder: the preset's march over 1, 1.5,
// 2, 3 and 4 (high), or 1 and 1.5 (the others), then each cheaper preset's
// way at its marches over 1 and 1.5 (and realtime's at 1/4 size). A second
// run (the same scenes, with high, medium and low as anchors) measured the
// cheaper full-size ways at half size, for the gap between low/1.5 and
// realtime/1.5: of medium, medium/1.5, low and low/1.5 at 1/2 size only
// low/1.5 is on the front (0.143 of high, 34.08 dB; medium at half size
// costs 0.300 for 36.39 dB, more than low/1.5 at full size for less). A
// third run (2026-12-07, the same scenes and reference, low/1.5 as the
// anchor) measured realtime/1.5 at full size: 0.776 of low/1.5's time
// (0.202 of high's) for 36.57 dB, between low/1.5 (37.28) and low/1.5 at
// half size (34.08), on the front. Its cost is the stills': on the two
// paths it takes 0.90 and 0.99 of low/1.5's time (its turns are drawn
// densely from 1 pixel a frame, realtime's threshold at half size) for
// 0.6-0.8 dB less. The medium and low ladders take its time scaled by
// low/1.5's there. A ladder keeps the preset's own way first and, of the
// rest, those no other candidate beats on both time and error (the Pareto
// front), less accurate than the first. Dropped that way: high's cheaper
// marches (medium's way is more accurate at under half their time: 40.72
// dB at 0.457 against 38.48 dB at 0.895 for high/1.5); realtime's own march as a level
// of the others (high's: 0.086, 33.74 dB) behind realtime/1.5 (0.076,
// 33.86 dB: its longer steps cost nothing in error on these scenes); and in
// realtime's own ladder realtime/1.5 (0.806, 33.54 dB), which is not less
// accurate than realtime (33.43 dB).
struct Step {
  const char* preset;      // whose way of drawing (march, interleave, divisor, air table)
  std::size_t marchLevel;  // its march over kStepFactors[marchLevel]
  double relativeCost;
  double psnr_db;
  std::uint32_t divisor = 0;  // the resolution divisor; 0: the preset's
};
struct Measured {
  const char* preset;
  std::vector<Step> steps;
};
const std::vector<Measured>& measuredLadders() {
  static const std::vector<Measured> all = {
      {"high",
       {{"high", 0, 1.000, 40.82},
        {"medium", 0, 0.457, 40.72},
        {"medium", 1, 0.397, 37.70},
        {"low", 0, 0.276, 37.29},
        {"low", 1, 0.260, 37.28},
        {"realtime", 1, 0.202, 36.57, 1},
        {"low", 1, 0.143, 34.08, 2},
        {"realtime", 1, 0.076, 33.86}}},
      {"medium",
       {{"medium", 0, 1.000, 40.72},
        {"medium", 1, 0.870, 37.70},
        {"low", 0, 0.591, 37.29},
        {"low", 1, 0.562, 37.28},
        {"realtime", 1, 0.436, 36.57, 1},
        {"low", 1, 0.312, 34.08, 2},
        {"realtime", 1, 0.161, 33.86}}},
      {"low",
       {{"low", 0, 1.000, 37.29},
        {"low", 1, 0.921, 37.28},
        {"realtime", 1, 0.714, 36.57, 1},
        {"low", 1, 0.493, 34.08, 2},
        {"realtime", 1, 0.275, 33.86}}},
      {"realtime", {{"realtime", 0, 1.000, 33.43}, {"realtime", 1, 0.507, 31.29, 4}}},
  };
  return all;
}

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
  const auto& ladders = measuredLadders();
  const auto measured =
      std::find_if(ladders.begin(), ladders.end(), [&](const Measured& m) { return p.name == m.preset; });
  if (measured == ladders.end())
    return fail(ErrorCode::InvalidArgument, "frame budget: preset '" + p.name +
                                                "' has no measured ladder (high, medium, low or realtime)");
  std::vector<BudgetLevel> ladder;
  for (const Step& step : measured->steps) {
    auto way = findPreset(step.preset);
    SKY_ASSERT(way);
    // The renderer keeps the preset's sun map (a new size would build a new
    // map whole at the change); the rest, the air table's size too, is the
    // cheaper preset's.
    MarchSettings m = way->march;
    m.sunShadow = p.march.sunShadow;
    ResolutionSettings resolution = way->resolution;
    if (step.divisor != 0) resolution.divisor = step.divisor;
    char name[64];
    std::snprintf(name, sizeof name, "%s", step.preset);
    if (step.marchLevel != 0)
      std::snprintf(name + std::strlen(name), sizeof name - std::strlen(name), "/%g", kStepFactors[step.marchLevel]);
    if (step.divisor == 1)
      std::snprintf(name + std::strlen(name), sizeof name - std::strlen(name), " at full size");
    else if (step.divisor != 0)
      std::snprintf(name + std::strlen(name), sizeof name - std::strlen(name), " at 1/%u size", step.divisor);
    ladder.push_back({name, cheaper(m, step.marchLevel), way->temporal, resolution, step.relativeCost,
                      step.psnr_db});
  }
  return ladder;
}

FrameBudget::FrameBudget(double target_ms, std::vector<BudgetLevel> ladder)
    : target_ms_(target_ms), ladder_(std::move(ladder)) {
  SKY_ASSERT(target_ms_ > 0 && !ladder_.empty());
  for (std::size_t i = 1; i < ladder_.size(); ++i) SKY_ASSERT(ladder_[i].relativeCost < ladder_[i - 1].relativeCost);
}

std::size_t FrameBudget::update(double frame_ms, bool representative) {
  if (!representative || !(frame_ms > 0) || !std::isfinite(frame_ms)) return level_;
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
