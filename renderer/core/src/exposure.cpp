// The exposure math (see exposure.hpp).
#include "sky/render/exposure.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

#include "sky/core/assert.hpp"

namespace sky::render {

namespace {
// Lagarde & de Rousiers 2014: L_max = 78 / (S q) x 2^EV100 with the ISO
// 12232 saturation constant 78, S = 100 and the lens and vignetting
// transmission q = 0.65: 78 / 65 = 1.2.
constexpr double kSaturationFactor = 78.0 / 65.0;
}  // namespace

const double kFixedDisplayEv100 = std::log2(kLuminanceUnit_cdm2 / kSaturationFactor);

double ev100FromMeanLogLuminance(double meanLnLuminance) {
  return (meanLnLuminance + std::log(100.0 / kMeterCalibrationK)) / std::numbers::ln2;
}

double exposureFromEv100(double ev100) { return 1.0 / (kSaturationFactor * std::exp2(ev100)); }

double displayExposure(double ev100, double compensation_ev) {
  return kLuminanceUnit_cdm2 * exposureFromEv100(ev100 - compensation_ev);
}

double meanLogLuminance(const Image& image) {
  double sum = 0;
  std::size_t n = 0;
  for (std::size_t i = 0; i + 3 < image.rgba.size(); i += 4) {
    const float* p = &image.rgba[i];
    if (!std::isfinite(p[0]) || !std::isfinite(p[1]) || !std::isfinite(p[2])) continue;
    // Rec. 709 luminance; negative radiance (none is drawn) counts as black.
    const double y = std::max(0.0, 0.2126 * p[0] + 0.7152 * p[1] + 0.0722 * p[2]);
    sum += std::log(y * kLuminanceUnit_cdm2 + kMeterFloor_cdm2);
    ++n;
  }
  return n > 0 ? sum / double(n) : std::log(kMeterFloor_cdm2);
}

ExposureAdaptation::ExposureAdaptation(double tau_s) : tau_s_(tau_s) { SKY_ASSERT(tau_s > 0); }

double ExposureAdaptation::update(double target_ev100, double time_s) {
  const double dt_s = time_s - time_s_;
  if (!started_ || !(dt_s >= 0) || dt_s > kSnapAfterTaus * tau_s_)
    ev100_ = target_ev100;
  else
    ev100_ += (target_ev100 - ev100_) * -std::expm1(-dt_s / tau_s_);
  started_ = true;
  time_s_ = time_s;
  return ev100_;
}

}  // namespace sky::render
