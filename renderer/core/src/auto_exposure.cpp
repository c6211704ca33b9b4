// A channel's exposure per frame, metered on the host's boresight (see
// auto_exposure.hpp).
#include "sky/render/auto_exposure.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <numbers>

#include "sky/core/assert.hpp"
#include "sky/geo/geodetic.hpp"
#include "sky/render/presets.hpp"

namespace sky::render {

namespace {

// The meter's march: the realtime preset's steps (the cheapest; the mean
// log luminance of 576 rays does not need more), with the sun's light marched
// per sample and the air per pixel: a shadow map or an air table built for
// 576 rays would cost more than the rays.
RenderSettings meterSettings(std::uint32_t noiseSeed, const std::string& noiseCacheDir) {
  RenderSettings s;
  s.noiseCacheDir = noiseCacheDir;
  s.width = kMeterWidth;
  s.height = kMeterHeight;
  s.verticalFov_deg = kMeterVerticalFov_deg;
  s.noiseSeed = noiseSeed;
  if (auto realtime = findPreset("realtime")) s.march = realtime->march;
  s.march.sunShadow = SunMapSettings{};
  s.march.airTable.enabled = false;
  return s;
}

double turn_deg(const geo::GeodeticPose& a, const geo::GeodeticPose& b) {
  const double c = geo::dot(geo::bodyAxes(a).forward, geo::bodyAxes(b).forward);
  return std::acos(std::clamp(c, -1.0, 1.0)) * 180.0 / std::numbers::pi;
}

}  // namespace

AutoExposure::AutoExposure(const ExposureSettings& settings, std::optional<CpuReference> meter)
    : settings_(settings), meter_(std::move(meter)), adaptation_(settings.adaptationTau_s) {}

Result<AutoExposure> AutoExposure::create(const ExposureSettings& settings, std::uint32_t noiseSeed,
                                          const std::string& noiseCacheDir) {
  if (!(settings.adaptationTau_s > 0) || !(settings.meterPeriod_s > 0) || !std::isfinite(settings.fixedEv100) ||
      !std::isfinite(settings.compensation_ev))
    return fail(ErrorCode::InvalidArgument, "exposure: tau and meter period must be > 0, EV100 and compensation finite");
  if (!settings.automatic) return AutoExposure(settings, std::nullopt);
  auto meter = CpuReference::create(meterSettings(noiseSeed, noiseCacheDir));
  if (!meter) return tl::unexpected(meter.error());
  return AutoExposure(settings, std::move(*meter));
}

Result<double> AutoExposure::meter(const FrameInputs& frame, const geo::GeodeticPose& boresight) const {
  SKY_ASSERT(meter_);
  FrameInputs in = frame;
  in.camera = boresight;
  in.frustum.reset();  // the meter's own symmetric view
  in.patternIndex.reset();
  auto image = meter_->render(in);
  if (!image) return tl::unexpected(image.error());
  return ev100FromMeanLogLuminance(meanLogLuminance(*image));
}

Result<FrameExposure> AutoExposure::expose(const FrameInputs& frame, const geo::GeodeticPose& boresight,
                                           double time_s) {
  FrameExposure out;
  out.automatic = settings_.automatic;
  out.compensation_ev = settings_.compensation_ev;
  if (!settings_.automatic) {
    out.ev100 = settings_.fixedEv100;
    out.exposure = displayExposure(out.ev100, out.compensation_ev);
    return out;
  }
  const auto period = static_cast<std::int64_t>(std::floor(time_s / settings_.meterPeriod_s));
  const bool due = !target_ || period != meteredPeriod_ || turn_deg(boresight, meteredPose_) > settings_.meterTurn_deg ||
                   geo::length(geo::toEcef(boresight.position) - geo::toEcef(meteredPose_.position)) >
                       settings_.meterMove_m;
  if (due) {
    const auto started = std::chrono::steady_clock::now();
    auto ev = meter(frame, boresight);
    if (!ev) return tl::unexpected(ev.error());
    out.meter_ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - started).count();
    out.meteredNow = true;
    target_ = std::clamp(*ev, kMinAutoEv100, kMaxAutoEv100);
    meteredPeriod_ = period;
    meteredPose_ = boresight;
  }
  out.meteredEv100 = target_;
  out.ev100 = adaptation_.update(*target_, time_s);
  out.exposure = displayExposure(out.ev100, out.compensation_ev);
  return out;
}

}  // namespace sky::render
