// One frame of a channel (see channel_frame.hpp).
#include "sky/app/channel_frame.hpp"

#include <chrono>
#include <vector>

#include <spdlog/fmt/ranges.h>
#include <spdlog/spdlog.h>

#include "sky/app/drawable_weather.hpp"
#include "sky/app/timed_render.hpp"
#include "sky/render/exposure.hpp"

namespace sky::app {

tl::expected<DrawnFrame, FrameFailure> ChannelFrames::draw(const FrameRequest& r) {
  const WeatherView& view = *r.weather;
  std::vector<std::uint32_t> dropped;
  const auto drawable = drawableWeather(view.snapshot, render::kMaxLayers, &dropped);
  if (!dropped.empty() && view.version != droppedWarnedAt_) {
    droppedWarnedAt_ = view.version;
    spdlog::warn("weather has {} layers, this channel draws {}: leaving out layer(s) {}", view.snapshot.layers.size(),
                 render::kMaxLayers, fmt::join(dropped, ", "));
  }
  const auto coarse = view.coarse ? std::optional(drawableCoarse(*view.coarse, drawable)) : std::nullopt;
  render::FrameInputs in;
  in.camera = r.camera;
  in.frustum = r.frustum;
  in.weather = &drawable;
  in.coarseWeather = coarse ? &*coarse : nullptr;
  if (drawnVersion_ == 0 || r.weatherSource != versionSource_ || view.version != sourceVersion_) {
    versionSource_ = r.weatherSource;
    sourceVersion_ = view.version;
    ++drawnVersion_;
  }
  in.weatherVersion = drawnVersion_;
  in.weatherClock_s = r.weatherClock_s;
  in.flashes = view.flashes;
  in.exposure_s = exposure_s_;
  in.patternIndex = r.patternIndex;
  in.sunAzimuth_deg = r.sunAzimuth_deg;
  in.sunElevation_deg = r.sunElevation_deg;
  in.utc_s = r.utc_s;
  in.visibility_m = r.atmosphere.hazeVisibility_m();
  in.frameIndex = r.frameIndex;

  DrawnFrame out;
  FrameRecord& record = out.record;
  const std::string frameName = "frame " + std::to_string(r.frameIndex) + ": ";
  if (budget_ && budget_->level() != appliedLevel_) {
    const render::BudgetLevel& level = budget_->current();
    if (auto ok = renderer_->setLevel(level.march, level.temporal, level.resolution); !ok)
      return tl::unexpected(FrameFailure{3, frameName + "frame budget: " + describe(ok.error())});
    appliedLevel_ = budget_->level();
  }
  auto image = truth_ ? truth_->render(in, record) : timedRender(*renderer_, in, record);
  if (!image) return tl::unexpected(FrameFailure{3, frameName + describe(image.error())});
  if (budget_) {
    const render::BudgetLevel& level = budget_->current();
    record.budget = FrameRecord::Budget{budget_->target_ms(), budget_->level(), level.name,
                                        budget_->predicted_ms(budget_->level()), level.expectedPsnr_db, level.march,
                                        level.temporal.interleave, level.resolution.divisor};
    budget_->update(record.render_ms, render::timesLevel(level, record.temporal));
  }
  out.image = std::move(*image);
  // The camera meters the host's boresight, not this channel's view. The
  // host's setting, when it sent one, replaces the channel's own: a fixed
  // EV100, or the meter with the host's compensation.
  const cigi::CameraExposureControl* host = r.hostExposure ? &*r.hostExposure : nullptr;
  if (host && host->mode == cigi::ExposureMode::Fixed) {
    render::FrameExposure& e = record.cameraExposure;
    e = render::FrameExposure{};
    e.automatic = false;
    e.ev100 = host->ev100;
    e.compensation_ev = host->compensation_ev;
    e.exposure = render::displayExposure(host->ev100, host->compensation_ev);
    record.exposureSource = "host";
  } else if (render::AutoExposure* meter = host && hostMeter_ ? hostMeter_ : cameraExposure_) {
    auto exposed = meter->expose(in, r.host.pose, r.hostTime_s);
    if (!exposed) return tl::unexpected(FrameFailure{3, frameName + "exposure: " + describe(exposed.error())});
    record.cameraExposure = *exposed;
    if (host && hostMeter_) {
      record.cameraExposure.compensation_ev = host->compensation_ev;
      record.cameraExposure.exposure = render::displayExposure(exposed->ev100, host->compensation_ev);
      record.exposureSource = "host";
    }
  }
  const auto delay_ms = [&] {
    return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - r.host.receivedAt).count();
  };
  if (r.live) record.transportDelay_ms = delay_ms();
  mirrorImage(out.image, r.mirror);
  record.frame = r.frameIndex;
  record.host = r.host;
  record.view = r.view;
  record.source = r.source;
  record.utcSource = r.utcSource;
  record.atmosphere = r.atmosphere;
  record.weatherClock_s = r.weatherClock_s;
  record.exposure_s = in.exposure_s;
  for (const weather::LightningFlash& f : view.flashes)
    if (weather::flashPower_w(f, r.weatherClock_s - in.exposure_s, r.weatherClock_s) > 0) record.flashesLit.push_back(f);
  record.serverClockAtArrival_s = r.serverClockAtArrival_s;
  record.weatherClockLock = r.weatherClockLock;
  record.weatherVersion = view.version;
  record.weatherConnected = r.weatherConnected;
  record.weatherSource = r.weatherSource;
  record.layerCount = view.snapshot.layers.size();
  record.weatherAreas = {{view.snapshot.tileLevel, view.snapshot.tiles.size()}};
  if (view.coarse) record.weatherAreas.push_back({view.coarse->tileLevel, view.coarse->tiles.size()});
  if (display_) {
    auto shown = display_->show(out.image, record.cameraExposure.exposure);
    if (!shown) return tl::unexpected(FrameFailure{3, frameName + describe(shown.error())});
    record.presented = *shown;
    if (r.live) record.presentDelay_ms = delay_ms();
    for (const auto& pass : renderer_->lastPassTimes())
      if (pass.pass == "present") record.gpu.push_back(pass);
  }
  if (renderer_) logValidationMessages(*renderer_);
  if (auto ok = writer_.write(out.image, record); !ok) return tl::unexpected(FrameFailure{2, describe(ok.error())});
  return out;
}

}  // namespace sky::app
