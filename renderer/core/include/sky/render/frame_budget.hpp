// Holding a frame time: a ladder of settings from a preset's own down to
// cheaper ones, each with its cost relative to the first and its expected
// error (both measured with skyshell-bench), and a controller that picks,
// frame by frame, the most accurate level whose predicted time fits the
// budget. The prediction is the ladder's relative cost times this machine's
// and this scene's milliseconds per unit of cost, learnt from the frames
// drawn so far. A level changes the march (steps, light steps, early exit),
// the interleave and its history, and the resolution divisor; the air
// table and the sun map stay the preset's (the renderer is built with them).
#pragma once

#include <cstddef>
#include <string>
#include <vector>

#include "sky/core/result.hpp"
#include "sky/render/presets.hpp"

namespace sky::render {

struct BudgetLevel {
  // "high", "high/1.5": the preset and the march's step factor; a cheaper
  // preset's way of drawing as a level of this one: "medium", "realtime/1.5".
  std::string name;
  MarchSettings march;
  TemporalSettings temporal;
  ResolutionSettings resolution;
  double relativeCost = 1;     // the level's frame time over the first level's (skyshell-bench)
  double expectedPsnr_db = 0;  // against reference, mean over the bench's scenes and camera paths (skyshell-bench)
};

// The ladder for preset p (not reference): its own march, then marches
// with fewer samples (even placement: primarySteps over 1.5, 2, 3, 4; in
// metres: the steps and their growth times those), fewer light steps and an
// earlier exit, then the cheaper presets' ways of drawing (their march,
// interleave and history, resolution divisor) with p's air table and sun
// map, each as far as it was measured to save time on the bench for less
// accuracy. Errors: InvalidArgument for reference (the ground truth has no
// cheaper level) and for a preset with no measured ladder.
Result<std::vector<BudgetLevel>> budgetLadder(const Preset& p);

// Whether a frame's time is what its level costs, for FrameBudget::update:
// not for a frame of an interleaved level drawn whole (the first, one after
// a change to another size, a teleport), which costs several of its frames.
inline bool timesLevel(const BudgetLevel& level, const TemporalReport& drawn) {
  return level.temporal.interleave <= 1 || !drawn.drawnWhole;
}

class FrameBudget {
 public:
  // target_ms > 0; ladder not empty, relative costs falling.
  FrameBudget(double target_ms, std::vector<BudgetLevel> ladder);

  // The level the next frame is drawn at.
  std::size_t level() const { return level_; }
  const BudgetLevel& current() const { return ladder_[level_]; }
  const std::vector<BudgetLevel>& ladder() const { return ladder_; }
  double target_ms() const { return target_ms_; }
  // The time the model predicts for level i, ms (0 before the first frame).
  double predicted_ms(std::size_t i) const { return msPerCost_ * ladder_[i].relativeCost; }

  // After a frame drawn at level(): its time, ms. Learns the machine's speed
  // and moves to the most accurate level predicted to fit: to a cheaper one
  // when the current one does not fit (at once when it is 10 % over, else
  // after two frames over in a row), to a dearer one only when that fits
  // with 5 % to spare (so two levels next to the budget do not alternate).
  // Returns the level for the next frame. representative false (timesLevel):
  // the frame's time is not learnt from, and the level stays.
  std::size_t update(double frame_ms, bool representative = true);

 private:
  double target_ms_;
  std::vector<BudgetLevel> ladder_;
  std::size_t level_ = 0;
  double msPerCost_ = 0;  // ms per unit of relative cost, smoothed
  std::size_t frames_ = 0;
  std::size_t over_ = 0;  // frames in a row the current level was predicted over the budget
};

}  // namespace sky::render
