// skyshell-render --replay: renders a recorded flight headless (or shows it
// in a window), one frame per fixed step of flight time, with the weather the
// server streams, then writes an MP4 (ffmpeg), a contact sheet and a JSON
// report next to the frames. With --truth path the frames are path-traced on
// the CPU instead (runTruthReplay, truth_frames.hpp).
//
// Deterministic: frame i shows the flight at t0 + i × step and the weather at
// clock base + i × step × rate (base: --weather-clock, else the server's clock
// when the first snapshot arrived; rate: the server's); after every
// re-subscription the next frame waits for the answering snapshot. Without a
// server, --weather-file renders a scenario file's layers on its clock. So the same
// flight, options and server weather give byte-identical PNGs. (The server's
// snapshots carry the weather clock they were made at, and their coverage is
// advected from it: a server whose clock runs hands out a different input at
// every start; one with a frozen clock, or the same state, does not.)
#pragma once

#include <atomic>
#include <cstdint>
#include <optional>
#include <string>

#include "sky/app/frame_writer.hpp"
#include "sky/app/truth_frames.hpp"
#include "sky/app/window_display.hpp"
#include "sky/flight/clean.hpp"
#include "sky/flight/flight.hpp"
#include "sky/render/cloud_renderer.hpp"
#include "sky/render/frame_budget.hpp"

namespace sky::app {

struct ReplayOptions {
  std::string flightPath;  // .csv (ours or ADS-B), .igc or .gpx
  flight::ReadOptions read;  // for an ADS-B file: the aircraft, the altitude unit
  bool clean = true;         // clean the track first (flight/clean.hpp); false: --no-clean
  flight::CleanOptions cleanOptions;
  double step_s = 1.0 / 30.0;           // flight seconds per frame, (0, 3600]
  double start_s = 0;                   // offset into the flight, s
  std::optional<double> end_s;          // offset into the flight, s (default: its end)
  std::size_t maxFrames = 0;            // stop after this many frames (0: no limit)
  // Weather clock of the first frame. Default: from --weather-file, the
  // file's own clock (its start, so that two runs draw the same frames);
  // from a server, the server's clock when the first frame is drawn (the
  // report says which, and this pins it).
  std::optional<double> weatherClock_s;
  std::string weatherFile;  // a scenario TOML instead of a server (its layers, uniform; its clock)
  std::string serverHost;
  unsigned short serverPort = 0;
  double weatherTimeout_s = 30;  // for the first snapshot and after each re-subscription
  std::string outDir;
  FrameOutputs outputs;          // per frame: PNG, EXR, PFM; frames.jsonl always
  bool video = true;             // MP4 through ffmpeg from the PNGs (skipped with a warning if ffmpeg is missing)
  double sunAzimuth_deg = 135, sunElevation_deg = 40;  // when the flight has no date, or fixedSun
  bool fixedSun = false;  // ignore the flight's recorded date (IGC, GPX) for the sun
  std::string preset = kDefaultPreset;  // recorded in the report and every frame's metadata
  // Flight seconds per wall second: a frame is not rendered before its time
  // (so a weather change timed in flight seconds lands on the frames it
  // should). 0: as fast as the renderer goes.
  double pace = 0;
  // Windowed: every frame is also shown here; closing the window ends the
  // replay (exit code 0, report written). Not owned.
  WindowDisplay* display = nullptr;
  double exposure_s = render::kDefaultExposure_s;  // --exposure-ms: each frame's exposure
  // The camera's exposure of the PNGs, the window and the contact sheet
  // (--ev100), adapting over the flight's time. Not owned; null: fixed 1.
  render::AutoExposure* cameraExposure = nullptr;
  // Holds the frames to a time budget (--frame-budget-ms); the report
  // counts the frames per level. Not owned; null: none.
  render::FrameBudget* budget = nullptr;
  // With a range (m): each frame's weather radar picture round the camera
  // (radar_image.hpp), frames/radar_NNNNNN.png.
  std::optional<double> radarRange_m;
};

// Runs the replay to the end (or until *stop turns true, or the window is
// closed). Returns the process exit code: 0 done (or window closed), 2 bad
// input (flight file, output folder), 3 render failure, 4 no weather in time.
int runHeadlessReplay(const ReplayOptions& options, render::CloudRenderer& renderer, const std::atomic<bool>* stop);

// The same replay with every frame path-traced by `truth` instead of drawn
// by the GPU (--truth path): the same poses, sun, weather and exposure;
// no window and no frame budget (options.display and options.budget null).
// A progress line every few seconds gives the frame's rows and the time left.
int runTruthReplay(const ReplayOptions& options, TruthFrames& truth, const std::atomic<bool>* stop);

}  // namespace sky::app
