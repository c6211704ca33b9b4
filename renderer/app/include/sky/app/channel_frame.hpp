// One frame of a channel, from a pose and the weather to draw to a finished
// image and its record in frames.jsonl: the work every loop of a channel
// shares (the live loop of skyshell-render, whatever its pose source, and
// the headless replay of a flight file, drawn by the GPU or path-traced). The loops differ only in where the
// pose, the time and the weather clock come from and when a frame is due.
#pragma once

#include <cstdint>
#include <optional>
#include <string>

#include "sky/app/frame_writer.hpp"
#include "sky/app/shared_state.hpp"
#include "sky/app/truth_frames.hpp"
#include "sky/app/view_state.hpp"
#include "sky/app/window_display.hpp"
#include "sky/core/assert.hpp"
#include "sky/render/auto_exposure.hpp"
#include "sky/render/cloud_renderer.hpp"
#include "sky/render/frame_budget.hpp"

namespace sky::app {

// What a loop decided about a frame.
struct FrameRequest {
  HostPose host;                 // the pose drawn, as the source gave it
  std::string source;            // "cigi", "fdm", "foreflight" or "replay"
  geo::GeodeticPose camera;      // the eye: the host pose through the channel's view
  std::optional<FrameRecord::View> view;           // the channel's view, when it has one
  std::optional<render::ViewFrustum> frustum;      // unset: the settings' symmetric one
  const WeatherView* weather = nullptr;            // drawn (never null)
  std::string weatherSource = "server";            // "server", "file" or "clear"
  bool weatherConnected = false;
  double weatherClock_s = 0;
  std::optional<double> serverClockAtArrival_s;    // CIGI frames (host_locked_clock.hpp)
  HostClockSource weatherClockLock = HostClockSource::None;
  std::optional<std::uint64_t> patternIndex;       // CIGI frames: the host frame
  double sunAzimuth_deg = 135, sunElevation_deg = 40;
  std::optional<double> utc_s;
  TimeSource utcSource = TimeSource::Fixed;
  HostAtmosphere atmosphere;
  std::uint64_t frameIndex = 0;
  // The host's time of the frame, s (the CIGI timestamp when the host sends
  // one, the flight's time in a replay): what the auto exposure adapts over
  // and meters on the grid of, the same on every channel of the host.
  double hostTime_s = 0;
  // The host's camera exposure (CIGI camera exposure component), when it
  // set one: it replaces the channel's own.
  std::optional<cigi::CameraExposureControl> hostExposure;
  MirrorMode mirror = MirrorMode::None;
  bool live = false;  // record the transport delay from host.receivedAt
};

// Why a frame could not be finished, and the exit code that says so (3: the
// GPU or the window, 2: the output files).
struct FrameFailure {
  int exitCode = 3;
  std::string message;
};

struct DrawnFrame {
  render::Image image;
  FrameRecord record;
};

class ChannelFrames {
 public:
  // Frames of the GPU renderer. display: the window, or none (headless).
  // All must outlive this.
  ChannelFrames(render::CloudRenderer& renderer, FrameWriter& writer, WindowDisplay* display)
      : renderer_(&renderer), writer_(writer), display_(display) {}
  // Frames of the path-traced truth (headless, no budget: each frame takes
  // as long as its samples do). Both must outlive this.
  ChannelFrames(const TruthFrames& truth, FrameWriter& writer) : truth_(&truth), writer_(writer), display_(nullptr) {}

  // Draws the frame: the layers this channel can draw (warning once per
  // weather version about those left out), the frame inputs, the render,
  // the window, the record, the files.
  tl::expected<DrawnFrame, FrameFailure> draw(const FrameRequest& request);

  // Holds the GPU's frames to a time budget: each frame is drawn at the
  // budget's level, and its time moves the budget on. Not owned; null: none.
  void setBudget(render::FrameBudget* budget) {
    SKY_ASSERT(budget == nullptr || renderer_ != nullptr);
    budget_ = budget;
    appliedLevel_ = kNoLevel;
  }
  // The exposure each frame stands for (s, > 0): what a flash lights in it,
  // and how long the drops near the camera streak.
  void setExposure(double exposure_s) { exposure_s_ = exposure_s; }
  // The camera's exposure of the PNG and the window, metered on the host's
  // pose (FrameRequest::host) at FrameRequest::hostTime_s. Not owned; null:
  // the fixed exposure 1 (kFixedDisplayExposure).
  void setCameraExposure(render::AutoExposure* exposure) { cameraExposure_ = exposure; }
  // The meter a host's "auto" exposes with (FrameRequest::hostExposure):
  // the channel's own when it is automatic. Not owned; null: a host's auto
  // falls back to the channel's own exposure.
  void setHostMeter(render::AutoExposure* meter) { hostMeter_ = meter; }

 private:
  // One of the two draws the frames.
  render::CloudRenderer* renderer_ = nullptr;
  const TruthFrames* truth_ = nullptr;
  FrameWriter& writer_;
  WindowDisplay* display_;
  render::FrameBudget* budget_ = nullptr;
  render::AutoExposure* cameraExposure_ = nullptr;
  render::AutoExposure* hostMeter_ = nullptr;
  double exposure_s_ = render::kDefaultExposure_s;
  // The budget level the renderer was last set to; none yet, so the first
  // frame sets it too (the renderer then follows every frame for a later
  // level's history: CloudRenderer::setLevel).
  static constexpr std::size_t kNoLevel = ~std::size_t(0);
  std::size_t appliedLevel_ = kNoLevel;
  std::uint64_t droppedWarnedAt_ = 0;
  // The renderer's weather version (FrameInputs::weatherVersion): a new one
  // whenever the source ("server", "file", "clear") or its version changes,
  // since the sources count their versions apart.
  std::string versionSource_;
  std::uint64_t sourceVersion_ = 0, drawnVersion_ = 0;
};

}  // namespace sky::app
