// Writes a channel's per-frame output: a PNG (the camera's exposure, then
// tonemapped sRGB) and an EXR (linear radiance in the renderer's units,
// cloud transmittance, cloud depth) per frame, optionally
// PFMs, and one JSON line of metadata per frame in frames.jsonl, the frames'
// sidecar: camera pose and its source, host frame, weather clock and version,
// the time of day and its source, the sun and the moon, the atmosphere, the settings in use (preset, resolution, field of view, noise
// seeds), GPU time per pass, image statistics, the renderer's units in W
// m^-2 sr^-1 and cd/m^2 and the PNG's EV100 and exposure, a path-traced
// frame's samples and standard error, and the files written.
#pragma once

#include <cstdint>
#include <fstream>
#include <optional>
#include <string>
#include <vector>

#include "sky/app/host_atmosphere.hpp"
#include "sky/app/host_clock.hpp"
#include "sky/app/host_locked_clock.hpp"
#include "sky/app/shared_state.hpp"
#include "sky/core/result.hpp"
#include "sky/render/auto_exposure.hpp"
#include "sky/render/cloud_renderer.hpp"

namespace sky::app {

// The preset (sky/render/presets.hpp) when --preset is not given: `high`,
// RenderSettings' default march.
inline constexpr const char* kDefaultPreset = "high";

struct FrameOutputs {
  bool png = true;
  bool exr = true;
  bool pfm = false;  // radiance and transmittance as PFM (--write-float)
};

// What stays the same for every frame of a run; written on every line so
// each line describes its frame on its own.
struct RunSettings {
  std::string preset = kDefaultPreset;
  render::RenderSettings render;
};

struct FrameRecord {
  std::uint64_t frame = 0;
  HostPose host;
  std::string source = "cigi";  // where the camera came from: "cigi", "fdm" (FlightGear) or "replay"
  double weatherClock_s = 0;
  // CIGI frames: the server's weather clock as this channel held it when the
  // host frame arrived; weatherClock_s is locked to the host's time instead
  // (host_locked_clock.hpp), and the two differ by at most half its grid.
  std::optional<double> serverClockAtArrival_s;
  // Where weatherClock_s came from: the server's offset for the host (the
  // same on every channel), this channel's own estimate, or no host time.
  HostClockSource weatherClockLock = HostClockSource::None;
  std::uint64_t weatherVersion = 0;  // this channel's count of weather updates applied (snapshots, deltas)
  bool weatherConnected = false;     // the stream to the server was up when the frame was drawn
  // What the weather drawn came from: "server", "file" (--weather-file) or
  // "clear" (live, before a server's weather; fallback_weather.hpp).
  std::string weatherSource = "server";
  std::size_t layerCount = 0;
  // The weather each area of interest brought (index 0 detailed, 1 coarse;
  // one entry without a coarse area): S2 level and tiles of the snapshot held.
  struct Area {
    int tileLevel = 0;
    std::size_t tiles = 0;
  };
  std::vector<Area> weatherAreas;
  double sunAzimuth_deg = 0, sunElevation_deg = 0;    // the sun the frame was lit by, local ENU
  double moonAzimuth_deg = 0, moonElevation_deg = -90;  // the moon, local ENU
  std::optional<double> utc_s;                        // when the sun came from the date (s since 1970)
  TimeSource utcSource = TimeSource::Fixed;           // where utc_s came from ("fixed": the --sun angles)
  HostAtmosphere atmosphere;                          // the host's atmosphere in force
  std::optional<double> visibility_m;                 // the haze drawn (FrameInputs::visibility_m)
  render::ImageStats stats;
  double render_ms = 0;     // wall time of CloudRenderer::render
  double cpu_ms = 0;        // process CPU time during it (all threads: lavapipe's workers too)
  std::vector<render::PassTime> gpu;  // GPU time per pass (timestamps), in submission order
  render::TemporalReport temporal;    // what the reprojection did (interleaved presets)
  render::SunMapReport sunMap;        // the sun map rebuilt or reused (map methods)
  render::NearPrecipReport nearPrecip;  // the drops drawn near the camera (in precipitation)
  double exposure_s = 0;                            // the exposure the frame stands for
  // The camera's exposure its PNG and window show it with (auto or fixed
  // EV100, auto_exposure.hpp); the EXR stays linear radiance.
  render::FrameExposure cameraExposure;
  // Whose exposure it is: "channel" (its --ev100) or "host" (the CIGI camera
  // exposure component in force).
  std::string exposureSource = "channel";
  std::vector<weather::LightningFlash> flashesLit;  // the flashes giving light over the frame's exposure
  render::WeatherMapReport weatherMap;  // what this frame changed in the weather map (per tile, or rebuilt and why)
  std::optional<bool> presented;      // windowed: whether the frame reached the window
  // With a frame budget (--frame-budget-ms): the level the frame was drawn
  // at and what the model expected of it.
  struct Budget {
    double target_ms = 0;
    std::size_t level = 0;
    std::string name;              // the level's name ("medium/2")
    double predicted_ms = 0;       // the model's time for it before the frame (0 for the first frame)
    double expectedPsnr_db = 0;    // its error against reference on the bench
    render::MarchSettings march;   // the march it drew with
    std::uint32_t interleave = 1;  // and the interleave and resolution divisor
    std::uint32_t divisor = 1;
  };
  std::optional<Budget> budget;
  // Transport delay: from the arrival of the host datagram whose pose the
  // frame draws (for a smoothed input, the newest) to the frame's completion
  // (image read back), and, windowed, to its presentation. Live frames only.
  std::optional<double> transportDelay_ms, presentDelay_ms;
  // The channel's view (CIGI View Definition / View Control) and the camera
  // it gave: the ownship pose (host) with the eyepoint composed on. Unset
  // where the camera is the pose itself (--replay).
  struct View {
    ChannelView view;
    geo::GeodeticPose camera;
  };
  std::optional<View> view;
  // A path-traced frame (--truth path, truth_frames.hpp): its samples and
  // their noise. The standard errors are of a pixel's rgb mean (R+G+B)/3, in
  // the radiance's units.
  struct Truth {
    std::uint32_t samplesPerPixel = 0;
    std::uint64_t seed = 0;
    std::uint32_t threads = 0;
    std::uint64_t majorantViolations = 0;  // density reads above the majorant (0: unbiased)
    std::uint64_t densityLookups = 0;
    double meanStandardError = 0, maxStandardError = 0;  // over the pixels
    double imageMeanStandardError = 0;     // of the image's mean
    double meanRelativeStandardError = 0;  // a pixel's over its mean (floor 1e-3 units), averaged
    std::vector<float> standardError;      // per pixel, top row first: the EXR's kExrTruthStandardError
  };
  std::optional<Truth> truth;
};

// The EXR channel of a path-traced frame's per-pixel standard error.
inline constexpr const char* kExrTruthStandardError = "truth.standard_error";

class FrameWriter {
 public:
  static Result<FrameWriter> open(const std::string& directory, const FrameOutputs& outputs,
                                  const RunSettings& run);
  Result<void> write(const render::Image& image, const FrameRecord& record);
  const std::string& directory() const { return directory_; }
  const FrameOutputs& outputs() const { return outputs_; }

 private:
  std::string directory_;
  FrameOutputs outputs_;
  RunSettings run_;
  std::ofstream metadata_;
};

// Portable float map (PFM, little-endian, bottom row first) of the linear
// radiance (colour, no tone mapping) or of the view-ray transmittance through
// the clouds (grey), for tests that check every value.
enum class PfmChannels { Radiance, Transmittance };
Result<void> writePfm(const render::Image& image, const std::string& path, PfmChannels channels);

}  // namespace sky::app
