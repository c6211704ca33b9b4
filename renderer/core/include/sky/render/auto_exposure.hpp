// A channel's camera exposure per frame: fixed at an EV100, or automatic,
// metered on the HOST's boresight view (the ownship pose without the
// channel's view offset: the centre channel's view) drawn tiny by the CPU
// reference, then adapted over time (exposure.hpp). Every channel of a
// multi-channel display computes the same numbers from the same host pose,
// weather and time, so they share one exposure without talking.
#pragma once

#include <cstdint>
#include <optional>
#include <string>

#include "sky/render/cloud_renderer.hpp"
#include "sky/render/cpu_reference.hpp"
#include "sky/render/exposure.hpp"

namespace sky::render {

// The meter's view: 32 x 18 pixels over a 60 deg vertical field of view
// (skyshell-render's default --fov), 16:9. Its 576 rays of the realtime
// march read an overcast and sunlit cumulus tops within 0.01 EV of a 64 x 36
// picture at the default march (exposure_test.cpp), for 13 ms of one core.
inline constexpr std::uint32_t kMeterWidth = 32, kMeterHeight = 18;
inline constexpr double kMeterVerticalFov_deg = 60;

struct ExposureSettings {
  bool automatic = true;                  // false: fixedEv100 on every frame
  double fixedEv100 = kFixedDisplayEv100;  // used when !automatic
  double compensation_ev = 0;             // added to the exposure (positive: brighter), EV
  double adaptationTau_s = kDefaultAdaptationTau_s;  // > 0
  // Host time between meterings, s, on a grid of the time (not of frame
  // counts), so channels that miss different frames still meter in the same
  // periods. 0.25 s: half the adaptation's time constant, so a metering's
  // step is followed smoothly; at 30 Hz one frame in 7-8 pays the meter.
  double meterPeriod_s = 0.25;
  // Meter at once, between periods, when the boresight turned further than
  // this since the last metering (deg: a sixth of the meter's field) or
  // moved further (m: a layer's scale; a teleport).
  double meterTurn_deg = 10;
  double meterMove_m = 1000;
};

// What a frame was exposed with (frames.jsonl "camera_exposure").
struct FrameExposure {
  bool automatic = false;
  double ev100 = kFixedDisplayEv100;  // the frame's EV100, before the compensation
  double compensation_ev = 0;
  double exposure = kFixedDisplayExposure;  // displayExposure(ev100, compensation_ev): radiance units into the tonemap
  std::optional<double> meteredEv100;  // auto: the latest metering's EV100, clamped to [kMinAutoEv100, kMaxAutoEv100]
  bool meteredNow = false;             // this frame metered
  double meter_ms = 0;                 // wall time of this frame's metering, ms
};

class AutoExposure {
 public:
  // Builds the meter's CPU reference (its noise and atmosphere tables, from
  // noiseSeed: the channel's, the same on every channel) when automatic;
  // the noise from the disk cache in noiseCacheDir when it holds it (the
  // renderer's RenderSettings::noiseCacheDir; empty: generated).
  // Errors: InvalidArgument for a tau or period <= 0 or a non-finite EV.
  static Result<AutoExposure> create(const ExposureSettings& settings, std::uint32_t noiseSeed,
                                     const std::string& noiseCacheDir = {});

  // The exposure of the frame drawn from `frame` (its weather, clock, sun,
  // flashes and haze are metered; its camera and frustum are not) with the
  // host's ownship pose `boresight` at time_s (s, the host-locked clock every
  // channel shares). Errors: those of CpuReference::render.
  Result<FrameExposure> expose(const FrameInputs& frame, const geo::GeodeticPose& boresight, double time_s);

  // The mean log luminance's EV100 of the boresight view (unclamped), what
  // expose meters: for tests and tools.
  Result<double> meter(const FrameInputs& frame, const geo::GeodeticPose& boresight) const;

  const ExposureSettings& settings() const { return settings_; }

 private:
  AutoExposure(const ExposureSettings& settings, std::optional<CpuReference> meter);
  ExposureSettings settings_;
  std::optional<CpuReference> meter_;  // automatic only
  ExposureAdaptation adaptation_;
  std::optional<double> target_;       // the latest metering, clamped
  std::int64_t meteredPeriod_ = 0;     // floor(time_s / meterPeriod_s) of the latest metering
  geo::GeodeticPose meteredPose_;
};

}  // namespace sky::render
