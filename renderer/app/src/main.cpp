// skyshell-render: one image-generator channel. Takes its camera from a CIGI
// host over UDP (or, with --fdm-port, from FlightGear's --native-fdm stream, or with
// --foreflight-port from ForeFlight XGPS/XATT lines, as X-Plane sends them;
// smoothed), its weather from skyshell-weatherd over TCP, and renders the
// clouds on Vulkan. Headless: writes a PNG, an EXR and metadata per frame;
// windowed: shows the frames in a GLFW window (and writes their metadata).
#include <atomic>
#include <charconv>
#include <cmath>
#include <csignal>
#include <limits>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <thread>

#include <CLI/CLI.hpp>
#include <boost/asio.hpp>
#include <spdlog/sinks/stdout_color_sinks.h>
#include <spdlog/spdlog.h>

#include "sky/app/area_of_interest.hpp"
#include "sky/app/cigi_listener.hpp"
#include "sky/app/channel_frame.hpp"
#include "sky/app/fallback_weather.hpp"
#include "sky/app/fdm_listener.hpp"
#include "sky/app/foreflight_listener.hpp"
#include "sky/app/frame_writer.hpp"
#include "sky/app/glfw_window.hpp"
#include "sky/app/pose_source.hpp"
#include "sky/app/headless_replay.hpp"
#include "sky/app/host_clock.hpp"
#include "sky/app/host_locked_clock.hpp"
#include "sky/app/latency_histogram.hpp"
#include "sky/app/view_state.hpp"
#include "sky/render/presets.hpp"
#include "sky/app/timed_render.hpp"
#include "sky/app/truth_frames.hpp"
#include "sky/app/weather_client.hpp"
#include "sky/app/window_display.hpp"
#include "sky/flight/clean.hpp"
#include "sky/flight/utf8_text.hpp"
#include "sky/geo/geodetic.hpp"
#include "sky/render/auto_exposure.hpp"
#include "sky/render/cloud_renderer.hpp"
#include "sky/render/noise_cache.hpp"

namespace asio = boost::asio;
using Clock = std::chrono::steady_clock;

namespace {

struct Options {
  std::string server = "127.0.0.1:47800";
  std::string cigiAddress = "127.0.0.1";
  std::string cigiHost;  // empty: the first sender of a valid host datagram
  unsigned cigiPort = 8004;
  std::string portFile;
  bool cigiSync = false;
  std::string fdmAddress = "127.0.0.1";
  int fdmPort = -1;  // -1: no FlightGear input
  std::string fdmPortFile;
  double fdmFrameRate_hz = 30;
  std::string foreflightAddress = "127.0.0.1";
  int foreflightPort = -1;  // -1: no ForeFlight input
  std::string foreflightPortFile;
  std::string outDir = "skyshell-frames";
  bool headless = false;
  bool window = false;
  bool validation = false;
  std::string cacheDir = sky::render::defaultCacheDirectory().string();
  bool noNoiseCache = false;
  bool writeFloat = false;
  bool noExr = false;
  unsigned width = 320, height = 180;
  double fov_deg = 60;
  unsigned viewId = 0;
  std::string preset = sky::app::kDefaultPreset;
  double frameBudget_ms = 0;  // --frame-budget-ms; 0: none
  std::string sunShadow;      // --sun-shadow; empty: the preset's
  double sunAzimuth_deg = 135, sunElevation_deg = 40;
  std::uint64_t maxFrames = 0;
  double idleExit_s = 0;
  double weatherTimeout_s = 30;
  // --replay: headless replay of a flight file instead of listening to a host.
  std::string replayFlight;
  double replayStep_s = 1.0 / 30.0;
  double replayPace = 0;
  double radarRange_km = 0;
  double replayStart_s = 0;
  double replayEnd_s = -1;
  double replayWeatherClock_s = std::numeric_limits<double>::quiet_NaN();
  sky::flight::ReadOptions replayRead;  // --icao24, --altitude-unit (ADS-B files), --track (KML/KMZ)
  double exposure_ms = 1000.0 * sky::render::kDefaultExposure_s;
  std::string ev100 = "auto";  // --ev100: auto or a fixed EV100
  double evCompensation = 0;
  double evAdaptation_s = sky::render::kDefaultAdaptationTau_s;
  std::string replayAltitudeUnit;
  bool noClean = false;                   // --no-clean
  std::string maxSpeed;                   // --max-speed
  sky::flight::CleanOptions cleanOptions;  // --max-gap, --long-gap
  std::string longGap = "hold";
  bool noVideo = false;
  bool fixedSun = false;
  std::string utc;  // --utc: the time of day at the host's first datagram
  std::string weatherFile;
  std::string channel;  // name in the operator console; empty: render@<host>
  std::string truth;    // --truth: "path", or empty (the GPU draws)
  std::string spp;      // --spp, as given (parsed by parseTruthSettings)
  unsigned truthThreads = 0;
};

// Set by SIGINT/SIGTERM during a --replay (which runs no io_context of its own
// on this thread to catch them with).
std::atomic<bool> gReplayStop{false};
extern "C" void onReplaySignal(int) { gReplayStop = true; }

// A command-line value as an error message may quote it (ill-formed UTF-8
// and control characters replaced, cut at 200 bytes).
std::string shown(const std::string& value) { return sky::flight::messageText(value); }

// The camera's exposure from --ev100 (auto or a number), --ev-compensation
// and --ev-adaptation-s; none for an --ev100 that is neither.
std::optional<sky::render::ExposureSettings> exposureSettings(const Options& o) {
  sky::render::ExposureSettings s;
  s.compensation_ev = o.evCompensation;
  s.adaptationTau_s = o.evAdaptation_s;
  if (o.ev100 == "auto") return s;
  double ev = 0;
  const auto [end, ec] = std::from_chars(o.ev100.data(), o.ev100.data() + o.ev100.size(), ev);
  if (ec != std::errc() || end != o.ev100.data() + o.ev100.size() || !(ev >= -10 && ev <= 30)) return std::nullopt;
  s.automatic = false;
  s.fixedEv100 = ev;
  return s;
}

// The replay of --replay as the options say (its camera exposure, window
// and budget are the caller's).
sky::app::ReplayOptions replayOptions(const Options& o, const sky::app::FrameOutputs& outputs,
                                      const std::string& serverHost, unsigned serverPort) {
  sky::app::ReplayOptions r;
  r.flightPath = o.replayFlight;
  r.read = o.replayRead;
  r.exposure_s = o.exposure_ms / 1000.0;
  if (!o.replayAltitudeUnit.empty())
    r.read.altitudeUnit = o.replayAltitudeUnit == "ft" ? sky::flight::AltitudeUnit::Feet : sky::flight::AltitudeUnit::Metres;
  r.step_s = o.replayStep_s;
  r.pace = o.replayPace;
  r.start_s = o.replayStart_s;
  if (o.replayEnd_s >= 0) r.end_s = o.replayEnd_s;
  r.maxFrames = o.maxFrames;
  if (std::isfinite(o.replayWeatherClock_s)) r.weatherClock_s = o.replayWeatherClock_s;
  r.serverHost = serverHost;
  r.serverPort = static_cast<unsigned short>(serverPort);
  r.weatherTimeout_s = o.weatherTimeout_s;
  r.outDir = o.outDir;
  r.outputs = outputs;
  r.video = !o.noVideo;
  r.clean = !o.noClean;
  r.cleanOptions = o.cleanOptions;
  r.cleanOptions.longGap = o.longGap == "end" ? sky::flight::LongGap::End : sky::flight::LongGap::Hold;
  r.sunAzimuth_deg = o.sunAzimuth_deg;
  r.sunElevation_deg = o.sunElevation_deg;
  r.fixedSun = o.fixedSun;
  r.preset = o.preset;
  r.weatherFile = o.weatherFile;
  if (o.radarRange_km > 0) r.radarRange_m = o.radarRange_km * 1000.0;
  return r;
}

// Why --truth cannot go with the other options given (empty: it can). The
// truth is drawn offline, seconds to minutes a frame, by the path tracer,
// which takes the light itself and the view ray's air from the reference
// preset's march.
std::string truthConflict(const Options& o, const CLI::App& app) {
  if (o.replayFlight.empty()) return "--truth path draws the frames of a --replay flight, not a live channel's";
  if (o.window) return "--truth path cannot show its frames in a --window (they take seconds to minutes each); use --headless";
  if (app.count("--frame-budget-ms") > 0) return "--frame-budget-ms does not apply to --truth path (a frame takes as long as its samples)";
  if (app.count("--preset") > 0) return "--preset does not apply to --truth path (the path tracer takes the light itself; its view-ray air is the reference preset's march)";
  if (app.count("--sun-shadow") > 0) return "--sun-shadow does not apply to --truth path (the path tracer finds the sun's shadow by ratio tracking)";
  return {};
}

bool writePortFile(const std::string& path, unsigned port) {
  const std::string tmp = path + ".tmp";
  {
    std::ofstream f(tmp, std::ios::trunc);
    f << port << '\n';
    if (!f) return false;
  }
  std::error_code ec;
  std::filesystem::rename(tmp, path, ec);
  return !ec;
}


}  // namespace

int main(int argc, char** argv) {
  Options o;
  CLI::App app{"skyshell-render: a Skyshell image generator channel"};
  app.add_option("--server", o.server, "weather server HOST:PORT");
  app.add_option("--channel", o.channel,
                 "this channel's name in the operator console (at most 64 bytes; default render@<host>)");
  app.add_option("--cigi-address", o.cigiAddress, "address to receive CIGI on");
  app.add_option("--cigi-port", o.cigiPort, "UDP port to receive CIGI on (0 = any free port)")
      ->check(CLI::Range(0, 65535));
  app.add_option("--cigi-host", o.cigiHost,
                 "the only CIGI host this channel answers, ADDR[:PORT] ([ADDR]:PORT for IPv6; without PORT, any "
                 "port of ADDR). Default: the address of the first valid host datagram's sender (any port). "
                 "Datagrams from any other sender are dropped, counted and never answered");
  app.add_option("--port-file", o.portFile, "write the CIGI port here once listening");
  app.add_flag("--cigi-sync", o.cigiSync,
               "synchronous CIGI: Start of Frame for a host frame goes only once its frame is drawn, so a host "
               "that waits for it draws exactly one frame per host frame (default: asynchronous, answered at once)");
  app.add_option("--fdm-port", o.fdmPort,
                 "take the camera from FlightGear --native-fdm datagrams on this UDP port (0 = any free port) "
                 "instead of from CIGI")
      ->check(CLI::Range(0, 65535));
  app.add_option("--fdm-address", o.fdmAddress, "address to receive FlightGear native FDM on");
  app.add_option("--fdm-port-file", o.fdmPortFile, "write the FlightGear FDM port here once listening");
  app.add_option("--fdm-frame-rate", o.fdmFrameRate_hz,
                 "with --fdm-port or --foreflight-port: render at most this many frames per second (the camera "
                 "is smoothed, so frames are not tied to packets)")
      ->check(CLI::Range(0.1, 1000.0));
  app.add_option("--foreflight-port", o.foreflightPort,
                 "take the camera from ForeFlight XGPS/XATT lines on this UDP port (X-Plane 11/12 'Send to "
                 "ForeFlight', FlightGear foreflight-xgps; the format's port is 49002; 0 = any free port) "
                 "instead of from CIGI")
      ->check(CLI::Range(0, 65535));
  app.add_option("--foreflight-address", o.foreflightAddress, "address to receive ForeFlight lines on");
  app.add_option("--foreflight-port-file", o.foreflightPortFile, "write the ForeFlight port here once listening");
  app.add_flag("--headless", o.headless, "render off-screen and write frames (PNG, EXR, metadata) to --out");
  app.add_flag("--window", o.window,
               "show the frames in a window (X11: DISPLAY; works under Xvfb); with --headless, also write them");
  app.add_option("--out", o.outDir, "output folder for frames and their metadata (frames.jsonl)");
  app.add_flag("--vulkan-validation", o.validation,
               "enable VK_LAYER_KHRONOS_validation and log its messages (Debian: vulkan-validationlayers)");
  app.add_option("--cache-dir", o.cacheDir, "folder for cached noise textures")->capture_default_str();
  app.add_flag("--no-noise-cache", o.noNoiseCache, "generate the noise textures at start, do not cache them");
  app.add_flag("--write-float", o.writeFloat, "also write each frame's linear radiance and transmittance as .pfm");
  app.add_flag("--no-exr", o.noExr,
               "headless: skip the per-frame EXR (linear radiance, cloud transmittance, cloud depth)");
  app.add_option("--width", o.width)->check(CLI::Range(16, 8192));
  app.add_option("--height", o.height)->check(CLI::Range(16, 8192));
  app.add_option("--fov", o.fov_deg,
                 "vertical field of view, deg (symmetric; a View Definition for --view-id replaces the half-angles "
                 "it enables)")
      ->check(CLI::Range(1.0, 170.0));
  app.add_option("--view-id", o.viewId,
                 "the CIGI view this channel draws: View Definition (frustum) and View Control (eyepoint offset and "
                 "rotation on the ownship) for this view id are applied, those for other views ignored (counted)")
      ->check(CLI::Range(0, 65535))
      ->capture_default_str();
  app.add_option("--preset", o.preset,
                 "quality preset: reference, high, medium, low, realtime (docs/rendering.md, \"Quality presets\")")
      ->capture_default_str();
  app.add_option("--frame-budget-ms", o.frameBudget_ms,
                 "hold frames to this many ms: each frame drawn at the most accurate of the preset's cheaper "
                 "marches predicted to fit (frame_budget.hpp; every frame's metadata says which)")
      ->check(CLI::Range(0.1, 1e6));
  app.add_option("--sun-shadow", o.sunShadow,
                 "how clouds are shadowed from the sun: march (the preset's light march), column, esm, bsm, fom, "
                 "deep (a sun-space map, also shadowing the ground and the air: light shafts; "
                 "docs/light-transport.md)")
      ->check(CLI::IsMember({"march", "column", "esm", "bsm", "fom", "deep"}));
  app.add_option("--sun-azimuth", o.sunAzimuth_deg, "deg from true north");
  app.add_option("--sun-elevation", o.sunElevation_deg, "deg above the horizon");
  app.add_option("--utc", o.utc,
                 "YYYY-MM-DDTHH:MM:SSZ: the time of day (sun and moon by ephemeris) from the host's first datagram "
                 "on, advanced by the host's time, until a CIGI Celestial Sphere Control sets one (FlightGear "
                 "always sends its own). Without it and without a host time: the --sun-azimuth/--sun-elevation angles");
  app.add_option("--max-frames", o.maxFrames, "stop after this many frames (0 = no limit)");
  app.add_option("--idle-exit", o.idleExit_s,
                 "stop when no pose (CIGI or FDM) arrived for this many seconds after the first (0 = never)");
  app.add_option("--weather-timeout", o.weatherTimeout_s,
                 "live: seconds a connected server may send no weather before the channel draws clear sky or "
                 "--weather-file (with no server it does so after 1 s, and switches to the server's weather when "
                 "it comes); --replay: seconds to wait for the first weather");
  app.add_option("--replay", o.replayFlight,
                 "render this flight file (.csv, .igc, .gpx) headless, one frame per --step of flight time, "
                 "then write a video, a contact sheet and report.json into --out");
  app.add_option("--step", o.replayStep_s, "with --replay: flight seconds per frame")->check(CLI::Range(1e-3, 3600.0));
  app.add_option("--replay-pace", o.replayPace,
                 "with --replay: flight seconds per wall second; no frame is rendered before its time "
                 "(default 0: as fast as it renders)")
      ->check(CLI::Range(0.0, 3600.0));
  app.add_option("--radar", o.radarRange_km,
                 "with --replay: also write each frame's weather radar picture round the camera, this many km "
                 "(frames/radar_NNNNNN.png: dBZ from the drawn weather's precipitation, a beam level with the camera)")
      ->check(CLI::Range(1.0, 300.0));
  app.add_option("--exposure-ms", o.exposure_ms,
                 "each frame's exposure, ms: what a lightning flash lights in it and how long the drops near the "
                 "camera streak (shorter: shorter, brighter streaks)")
      ->check(CLI::Range(0.1, 1000.0));
  app.add_option("--ev100", o.ev100,
                 "the camera's exposure of the PNGs and the window (the EXR stays linear radiance): auto, metered "
                 "on the host's boresight (the same on every channel) and adapting, or a fixed EV100 in [-10, 30] "
                 "for every channel started with it (12.38 is the fixed exposure of before; sunny daylight ~15)")
      ->capture_default_str();
  app.add_option("--ev-compensation", o.evCompensation, "exposure compensation, EV (+1: twice as bright)")
      ->check(CLI::Range(-10.0, 10.0));
  app.add_option("--ev-adaptation-s", o.evAdaptation_s,
                 "with --ev100 auto: the adaptation's time constant, s (63 % of a change of the scene after it)")
      ->check(CLI::Range(0.01, 60.0))
      ->capture_default_str();
  app.add_option("--icao24", o.replayRead.icao24,
                 "with --replay of an ADS-B .csv holding several aircraft: this one (ICAO 24-bit address, hex)");
  app.add_option("--track", o.replayRead.track,
                 "with --replay of a KML/KMZ holding several tracks: this one, by its name (the error without it "
                 "lists them)");
  app.add_option("--altitude-unit", o.replayAltitudeUnit,
                 "with --replay of an ADS-B .csv: unit of its altitude columns, ft or m (default: as each column's "
                 "name says)")
      ->check(CLI::IsMember({"ft", "m"}));
  app.add_option("--replay-start", o.replayStart_s, "with --replay: start offset into the flight, s")
      ->check(CLI::NonNegativeNumber);
  app.add_option("--replay-end", o.replayEnd_s, "with --replay: end offset into the flight, s (default: its end)")
      ->check(CLI::NonNegativeNumber);
  app.add_option("--weather-clock", o.replayWeatherClock_s,
                 "with --replay: weather clock of the first frame, s (default: a --weather-file's own clock, else "
                 "the server's at the first frame, which report.json gives); pin it for byte-identical re-renders "
                 "from a server");
  app.add_flag("--no-video", o.noVideo, "with --replay: skip the MP4");
  app.add_flag("--no-clean", o.noClean,
               "with --replay: the track as read: no sorting, no dropping of repeats, speed glitches or spoofed "
               "jumps, gaps interpolated whatever their length");
  app.add_option("--max-speed", o.maxSpeed,
                 "with --replay: cleaning's fastest ground speed, m/s or with a unit ('680kt', '350m/s'); a fix "
                 "implying more is dropped (default 350 m/s: an airliner with a jet-stream tailwind)");
  app.add_option("--max-gap", o.cleanOptions.maxGap_s,
                 "with --replay: longest gap between fixes flown through in a straight line, s; longer gaps are "
                 "held or end the replay (--long-gap)")
      ->check(CLI::Range(1.0, 1e7));
  app.add_option("--long-gap", o.longGap,
                 "with --replay, at a gap longer than --max-gap: hold (stay at the last fix, then jump to the next) "
                 "or end")
      ->check(CLI::IsMember({"hold", "end"}));
  app.add_option("--weather-file", o.weatherFile,
                 "a scenario file (deploy/scenarios/*.toml): with --replay, the weather rendered instead of asking "
                 "--server; live, the weather drawn until the server's comes (default: clear sky)");
  app.add_option("--truth", o.truth,
                 "with --replay --headless: path (the only mode): path-trace every frame on the CPU (the physical "
                 "ground truth, docs/ground-truth.md) instead of drawing it on the GPU; slow: seconds a frame at "
                 "32x18, minutes at 160x90");
  app.add_option("--spp", o.spp,
                 "with --truth path: samples per pixel, 2-65536 (default 16); each frame records its per-pixel "
                 "standard error (frames.jsonl truth, the EXR's truth.standard_error)");
  app.add_option("--truth-threads", o.truthThreads, "with --truth path: threads (0 = every hardware thread)")
      ->capture_default_str();
  app.add_flag("--fixed-sun", o.fixedSun,
               "with --replay: light from --sun-azimuth/--sun-elevation even when the flight has a date");
  app.set_config("--config", "", "config file (TOML keys named like the long options)");
  CLI11_PARSE(app, argc, argv);
  spdlog::set_default_logger(spdlog::stderr_color_mt("render"));

  if (!o.headless && !o.window) {
    std::fprintf(stderr, "skyshell-render: choose --headless (frames to files), --window (frames to a window), or both\n");
    return 2;
  }
  const auto colon = o.server.rfind(':');
  if (colon == std::string::npos) {
    std::fprintf(stderr, "skyshell-render: --server '%s' must be HOST:PORT\n", shown(o.server).c_str());
    return 2;
  }
  const std::string serverHost = o.server.substr(0, colon);
  unsigned serverPort = 0;
  {
    const std::string portText = o.server.substr(colon + 1);
    const auto [end, ec] = std::from_chars(portText.data(), portText.data() + portText.size(), serverPort);
    if (ec != std::errc() || end != portText.data() + portText.size() || serverPort == 0 || serverPort > 65535) {
      std::fprintf(stderr, "skyshell-render: --server '%s': port '%s' is not in 1..65535\n", shown(o.server).c_str(),
                   shown(portText).c_str());
      return 2;
    }
  }

  // Checked before the GPU starts: a typo should not cost a device start-up.
  std::optional<sky::app::CigiHost> cigiHost;
  if (!o.cigiHost.empty()) {
    auto parsed = sky::app::parseCigiHost(o.cigiHost);
    if (!parsed) {
      std::fprintf(stderr, "skyshell-render: %s\n", parsed.error().detail.c_str());
      return 2;
    }
    cigiHost = *parsed;
  }
  if (!o.maxSpeed.empty()) {
    const auto v = sky::flight::parseSpeed_mps(o.maxSpeed);
    if (!v) {
      std::fprintf(stderr, "skyshell-render: --max-speed '%s' is not a speed (e.g. 350, 350m/s, 680kt)\n",
                   shown(o.maxSpeed).c_str());
      return 2;
    }
    o.cleanOptions.maxGroundSpeed_mps = *v;
  }
  const auto cameraSettings = exposureSettings(o);
  if (!cameraSettings) {
    std::fprintf(stderr, "skyshell-render: --ev100 '%s' is neither auto nor an EV100 in [-10, 30]\n",
                 shown(o.ev100).c_str());
    return 2;
  }
  std::optional<sky::app::TruthSettings> truth;
  if (!o.truth.empty()) {
    if (const std::string conflict = truthConflict(o, app); !conflict.empty()) {
      std::fprintf(stderr, "skyshell-render: %s\n", shown(conflict).c_str());
      return 2;
    }
    auto parsed = sky::app::parseTruthSettings(
        o.truth, app.count("--spp") > 0 ? std::optional(o.spp) : std::nullopt, o.truthThreads);
    if (!parsed) {
      std::fprintf(stderr, "skyshell-render: %s\n", shown(parsed.error().detail).c_str());
      return 2;
    }
    truth = *parsed;
    o.preset = "reference";
  } else if (app.count("--spp") > 0 || app.count("--truth-threads") > 0) {
    std::fprintf(stderr, "skyshell-render: --spp and --truth-threads go with --truth path\n");
    return 2;
  }
  std::optional<double> startUtc_s;
  if (!o.utc.empty()) {
    startUtc_s = sky::app::parseUtc(o.utc.c_str());
    if (!startUtc_s) {
      std::fprintf(stderr, "skyshell-render: --utc '%s' is not YYYY-MM-DDTHH:MM:SSZ of years 1900-2100\n",
                   shown(o.utc).c_str());
      return 2;
    }
  }

  // Windowed only: the metadata is written, the images are not.
  sky::app::FrameOutputs outputs;
  outputs.png = o.headless;
  outputs.exr = o.headless && !o.noExr;
  outputs.pfm = o.headless && o.writeFloat;
  // The window outlives the renderer, whose surface and swapchain live on it.
  std::unique_ptr<sky::app::GlfwWindow> window;
  if (o.window) {
    auto opened = sky::app::GlfwWindow::open(o.width, o.height, "skyshell-render");
    if (!opened) {
      std::fprintf(stderr, "skyshell-render: --window: %s\n", sky::describe(opened.error()).c_str());
      return 3;
    }
    window = std::move(*opened);
  }
  auto preset = sky::render::findPreset(o.preset);
  if (!preset) {
    std::fprintf(stderr, "skyshell-render: --preset: %s\n", sky::describe(preset.error()).c_str());
    return 2;
  }
  // The sun shadow's method holds for the whole run (the renderer's map
  // is sized for it), at every budget level too.
  auto withSunShadow = [&](sky::render::MarchSettings m) {
    for (std::uint32_t k = 0; k <= std::uint32_t(sky::render::SunShadow::Deep); ++k)
      if (o.sunShadow == sky::render::sunShadowName(sky::render::SunShadow(k)))
        m.sunShadow.method = sky::render::SunShadow(k);
    return m;
  };
  sky::render::RenderSettings settings{o.width, o.height, o.fov_deg, 1, o.noNoiseCache ? std::string() : o.cacheDir,
                                       withSunShadow(preset->march), preset->temporal, preset->resolution};
  if (truth) {
    auto frames = sky::app::TruthFrames::create(settings, *truth);
    if (!frames) {
      std::fprintf(stderr, "skyshell-render: --truth: %s\n", sky::describe(frames.error()).c_str());
      return 2;
    }
    auto exposure = sky::render::AutoExposure::create(*cameraSettings, settings.noiseSeed, settings.noiseCacheDir);
    if (!exposure) {
      std::fprintf(stderr, "skyshell-render: exposure: %s\n", sky::describe(exposure.error()).c_str());
      return 2;
    }
    sky::app::ReplayOptions r = replayOptions(o, outputs, serverHost, serverPort);
    r.cameraExposure = &*exposure;
    std::signal(SIGINT, onReplaySignal);
    std::signal(SIGTERM, onReplaySignal);
    return sky::app::runTruthReplay(r, *frames, &gReplayStop);
  }
  std::optional<sky::render::FrameBudget> budget;
  if (o.frameBudget_ms > 0) {
    auto ladder = sky::render::budgetLadder(*preset);
    if (!ladder) {
      std::fprintf(stderr, "skyshell-render: --frame-budget-ms: %s\n", sky::describe(ladder.error()).c_str());
      return 2;
    }
    for (sky::render::BudgetLevel& level : *ladder) level.march = withSunShadow(level.march);
    budget.emplace(o.frameBudget_ms, std::move(*ladder));
  }
  sky::render::GpuOptions gpu;
  gpu.window = window ? &window->surface() : nullptr;
  gpu.validation = o.validation;
  auto renderer = sky::render::CloudRenderer::create(settings, gpu);
  if (!renderer) {
    std::fprintf(stderr, "skyshell-render: %s\n", sky::describe(renderer.error()).c_str());
    return 3;
  }
  spdlog::info("{}", (*renderer)->noiseReport());
  if (o.validation) spdlog::info("vulkan validation on ({})", "VK_LAYER_KHRONOS_validation");
  std::optional<sky::app::WindowDisplay> display;
  if (window) display.emplace(**renderer, *window);
  auto cameraExposure = sky::render::AutoExposure::create(*cameraSettings, settings.noiseSeed, settings.noiseCacheDir);
  if (!cameraExposure) {
    std::fprintf(stderr, "skyshell-render: exposure: %s\n", sky::describe(cameraExposure.error()).c_str());
    return 2;
  }
  // Said at every exit, so a run under --vulkan-validation can be checked.
  struct ValidationSummary {
    sky::render::CloudRenderer& renderer;
    bool on;
    ~ValidationSummary() {
      if (!on) return;
      sky::app::logValidationMessages(renderer);
      const auto c = renderer.validationCounts();
      std::printf("vulkan validation: %zu errors, %zu warnings\n", c.errors, c.warnings);
      std::fflush(stdout);
    }
  } validationSummary{**renderer, o.validation};
  if (!o.replayFlight.empty()) {
    sky::app::ReplayOptions r = replayOptions(o, outputs, serverHost, serverPort);
    r.cameraExposure = &*cameraExposure;
    r.display = display ? &*display : nullptr;
    r.budget = budget ? &*budget : nullptr;
    std::signal(SIGINT, onReplaySignal);
    std::signal(SIGTERM, onReplaySignal);
    return sky::app::runHeadlessReplay(r, **renderer, &gReplayStop);
  }
  // A live channel builds every variant of the cloud pass now: built at the
  // first frame that needs one (a flow's crossfade, the first flash), each
  // stalled that frame by about half a second on lavapipe. A replay renders
  // offline and builds them as it goes.
  {
    const auto started = Clock::now();
    auto built = (*renderer)->buildAllVariants();
    if (!built) {
      std::fprintf(stderr, "skyshell-render: %s\n", sky::describe(built.error()).c_str());
      return 3;
    }
    spdlog::info("built {} variants of the cloud pass in {:.1f} s", *built,
                 std::chrono::duration<double>(Clock::now() - started).count());
  }
  auto writer = sky::app::FrameWriter::open(o.outDir, outputs, {o.preset, (*renderer)->settings()});
  if (!writer) {
    std::fprintf(stderr, "skyshell-render: %s\n", sky::describe(writer.error()).c_str());
    return 2;
  }

  std::optional<sky::app::WeatherView> fileWeather;
  if (!o.weatherFile.empty()) {
    auto loaded = sky::app::scenarioWeather(o.weatherFile, Clock::now());
    if (!loaded) {
      std::fprintf(stderr, "skyshell-render: --weather-file: %s\n", sky::describe(loaded.error()).c_str());
      return 2;
    }
    fileWeather = std::move(*loaded);
  }
  sky::app::FallbackWeather fallback(std::move(fileWeather), o.weatherFile, o.server, o.weatherTimeout_s, Clock::now());

  sky::app::SharedState state;
  {
    sky::app::ChannelView initial;
    initial.viewId = static_cast<std::uint16_t>(o.viewId);
    initial.frustum = sky::render::symmetricFrustum((*renderer)->settings());
    state.setView(initial);
  }
  asio::io_context io;
  auto guard = asio::make_work_guard(io);
  std::atomic<bool> stopRequested{false};
  asio::signal_set signals(io, SIGINT, SIGTERM);
  signals.async_wait([&](boost::system::error_code ec, int) {
    if (!ec) stopRequested = true;
  });
  std::optional<sky::app::CigiListener> cigi;
  try {
    cigi.emplace(io, state, o.cigiAddress, static_cast<unsigned short>(o.cigiPort), cigiHost);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "skyshell-render: cannot listen for CIGI on %s:%u: %s\n", shown(o.cigiAddress).c_str(),
                 o.cigiPort, e.what());
    return 2;
  }
  if (startUtc_s) cigi->setStartUtc(*startUtc_s);
  cigi->setSynchronous(o.cigiSync && o.fdmPort < 0 && o.foreflightPort < 0);
  cigi->start();
  // With --fdm-port the camera comes from FlightGear only; the CIGI endpoint
  // stays open (and answers Start of Frame) but its pose is not used.
  std::optional<sky::app::FdmListener> fdm;
  std::optional<sky::app::ForeFlightListener> foreflight;
  if (o.fdmPort >= 0 && o.foreflightPort >= 0) {
    std::fprintf(stderr, "skyshell-render: choose one of --fdm-port and --foreflight-port\n");
    return 2;
  }
  if (o.foreflightPort >= 0) {
    try {
      foreflight.emplace(io, o.foreflightAddress, static_cast<unsigned short>(o.foreflightPort), startUtc_s);
    } catch (const std::exception& e) {
      std::fprintf(stderr, "skyshell-render: cannot listen for ForeFlight on %s:%d: %s\n",
                   shown(o.foreflightAddress).c_str(), o.foreflightPort, e.what());
      return 2;
    }
    foreflight->start();
  }
  if (o.fdmPort >= 0) {
    try {
      fdm.emplace(io, o.fdmAddress, static_cast<unsigned short>(o.fdmPort));
    } catch (const std::exception& e) {
      std::fprintf(stderr, "skyshell-render: cannot listen for FlightGear FDM on %s:%d: %s\n",
                   shown(o.fdmAddress).c_str(), o.fdmPort, e.what());
      return 2;
    }
    fdm->start();
  }
  sky::app::WeatherClient weather(io, state, serverHost, static_cast<unsigned short>(serverPort), o.channel);
  weather.start();
  std::thread ioThread([&] { io.run(); });
  auto shutdown = [&] {
    weather.stop();
    asio::post(io, [&] {
      cigi->stop();
      if (fdm) fdm->stop();
      if (foreflight) foreflight->stop();
      signals.cancel();
    });
    guard.reset();
    ioThread.join();
  };

  if (!o.portFile.empty() && !writePortFile(o.portFile, cigi->port())) {
    std::fprintf(stderr, "skyshell-render: cannot write --port-file %s\n", o.portFile.c_str());
    shutdown();
    return 2;
  }
  if (fdm && !o.fdmPortFile.empty() && !writePortFile(o.fdmPortFile, fdm->port())) {
    std::fprintf(stderr, "skyshell-render: cannot write --fdm-port-file %s\n", o.fdmPortFile.c_str());
    shutdown();
    return 2;
  }
  if (foreflight && !o.foreflightPortFile.empty() && !writePortFile(o.foreflightPortFile, foreflight->port())) {
    std::fprintf(stderr, "skyshell-render: cannot write --foreflight-port-file %s\n", o.foreflightPortFile.c_str());
    shutdown();
    return 2;
  }
  std::printf("skyshell-render: device '%s', CIGI on %s:%u, weather from %s, frames to %s\n",
              (*renderer)->deviceName().c_str(), o.cigiAddress.c_str(), cigi->port(), o.server.c_str(),
              o.outDir.c_str());
  if (fdm)
    std::printf("skyshell-render: camera from FlightGear native FDM on %s:%u\n", o.fdmAddress.c_str(),
                fdm->port());
  if (foreflight)
    std::printf("skyshell-render: camera from ForeFlight XGPS/XATT on %s:%u\n", o.foreflightAddress.c_str(),
                foreflight->port());
  std::fflush(stdout);

  // The one pose source this channel draws from.
  std::unique_ptr<sky::app::PoseSource> source;
  if (fdm)
    source = std::make_unique<sky::app::FdmPoseSource>(*fdm);
  else if (foreflight)
    source = std::make_unique<sky::app::ForeFlightPoseSource>(*foreflight, state);
  else
    source = std::make_unique<sky::app::CigiPoseSource>(state, *cigi, o.cigiSync);
  sky::app::ChannelFrames channelFrames(**renderer, *writer, display ? &*display : nullptr);
  channelFrames.setBudget(budget ? &*budget : nullptr);
  channelFrames.setExposure(o.exposure_ms / 1000.0);
  channelFrames.setCameraExposure(&*cameraExposure);
  // A host's "auto" (CIGI camera exposure component) is the meter: the
  // channel's own when it meters, else one built now, so that a channel
  // started with a fixed --ev100 meters at once when its host asks.
  std::optional<sky::render::AutoExposure> hostMeter;
  if (!cameraExposure->settings().automatic) {
    sky::render::ExposureSettings metered = cameraExposure->settings();
    metered.automatic = true;
    auto built = sky::render::AutoExposure::create(metered, settings.noiseSeed, settings.noiseCacheDir);
    if (!built) {
      std::fprintf(stderr, "skyshell-render: exposure: %s\n", sky::describe(built.error()).c_str());
      shutdown();
      return 2;
    }
    hostMeter = std::move(*built);
  }
  channelFrames.setHostMeter(hostMeter ? &*hostMeter : &*cameraExposure);

  std::uint64_t frames = 0, lastSequence = 0, resetsSeen = 0;
  sky::app::LatencyHistogram transportDelay, presentDelay;
  sky::app::AreaTracker areas;
  const auto start = Clock::now();
  auto lastReport = start;
  Clock::time_point lastPoseAt{};
  // Smoothed sources are sampled at this period; CIGI frames come with the
  // host's datagrams.
  const bool smoothed = source->smoothed();
  const auto framePeriod = std::chrono::duration_cast<Clock::duration>(
      std::chrono::duration<double>(1.0 / o.fdmFrameRate_hz));
  Clock::time_point nextFrameAt{};
  sky::app::HostLockedClock hostClock;
  int exitCode = 0;
  while (!stopRequested) {
    if (smoothed && Clock::now() < nextFrameAt) std::this_thread::sleep_until(nextFrameAt);
    const auto now = Clock::now();
    const auto pose = source->poseAt(now);
    if (pose)
      for (const auto& area : areas.update(pose->pose)) weather.subscribe(area);
    if (pose) lastPoseAt = pose->receivedAt;
    // Idle only once the newest pose has been rendered: a slow frame must not
    // skip the host's last pose (seen in CI under load: the final fix of the
    // replay arrived while a frame took longer than --idle-exit). (Smoothed
    // sources are rendered continuously: always current.)
    if (o.idleExit_s > 0 && pose && (smoothed || pose->sequence == lastSequence) &&
        std::chrono::duration<double>(now - lastPoseAt).count() > o.idleExit_s) {
      spdlog::info("no {} for {:.1f} s: stopping", source->name(), o.idleExit_s);
      break;
    }
    const auto streamed = state.weather();
    const auto weatherSource = fallback.choose(streamed, now);
    if (display) {
      display->poll();
      if (display->closed()) {
        spdlog::info("the window was closed: stopping");
        break;
      }
    }
    if (!pose || pose->sequence == lastSequence || weatherSource == sky::app::WeatherSource::None) {
      std::this_thread::sleep_for(std::chrono::milliseconds(5));
      continue;
    }
    lastSequence = pose->sequence;
    nextFrameAt = now + framePeriod;
    if (const auto resets = state.resets(); resets != resetsSeen) {
      resetsSeen = resets;
      (*renderer)->resetHistory("IG reset by the host");
    }

    const sky::app::WeatherView& view = fallback.view(weatherSource, streamed);
    const sky::app::ChannelView channelView = state.view();
    sky::app::FrameRequest request;
    request.host = *pose;
    request.source = source->source();
    request.camera = sky::app::viewCamera(pose->pose, channelView);
    request.view = sky::app::FrameRecord::View{channelView, request.camera};
    request.frustum = channelView.frustum;
    request.mirror = channelView.mirror;
    request.weather = &view;
    request.weatherSource = toString(weatherSource);
    request.weatherConnected = streamed.connected;
    // CIGI frames: the clock and the interleave pattern follow the host
    // frame, so every channel draws a host frame alike (host_locked_clock.hpp).
    if (smoothed) {
      request.weatherClock_s = view.clockNow(now);
    } else {
      const auto locked = hostClock.at(pose->hostTimeValid ? std::optional(pose->hostTime_s) : std::nullopt,
                                       pose->host, view.clock, pose->receivedAt, state.hostClock());
      if (locked.proposal) weather.proposeHostClock(*locked.proposal);
      request.weatherClock_s = locked.weatherClock_s;
      request.weatherClockLock = locked.source;
      request.patternIndex = pose->hostFrame;
      request.serverClockAtArrival_s = view.clock.at(pose->receivedAt);
    }
    request.sunAzimuth_deg = o.sunAzimuth_deg;
    request.sunElevation_deg = o.sunElevation_deg;
    request.utc_s = pose->utc_s;
    request.utcSource = pose->timeSource;
    request.atmosphere = source->atmosphere();
    request.hostExposure = state.hostExposure();
    request.frameIndex = frames;
    // The host's own time where it sends one (the same on every channel);
    // else this channel's time since start.
    request.hostTime_s = !smoothed && pose->hostTimeValid
                             ? pose->hostTime_s
                             : std::chrono::duration<double>((smoothed ? now : pose->receivedAt) - start).count();
    request.live = true;
    auto drawn = channelFrames.draw(request);
    if (!drawn) {
      std::fprintf(stderr, "skyshell-render: %s\n", drawn.error().message.c_str());
      exitCode = drawn.error().exitCode;
      break;
    }
    const sky::app::FrameRecord& record = drawn->record;
    if (record.transportDelay_ms) transportDelay.add(*record.transportDelay_ms);
    if (record.presentDelay_ms) presentDelay.add(*record.presentDelay_ms);
    weather.reportCamera(request.camera, frames, view.version, request.weatherClock_s);
    // Synchronous CIGI: the host hears of this host frame only now.
    source->frameDrawn(pose->hostFrame);
    ++frames;
    const auto after = Clock::now();
    if (after - lastReport > std::chrono::seconds(1)) {
      lastReport = after;
      const double elapsed = std::chrono::duration<double>(after - start).count();
      std::printf("render: %llu frames, %.1f frames/s, last %.0f ms, host frame %u, CIGI dropped %llu, "
                  "ignored packets %llu%s\n",
                  static_cast<unsigned long long>(frames), frames / elapsed, record.render_ms, pose->hostFrame,
                  static_cast<unsigned long long>(cigi->datagramsDropped()),
                  static_cast<unsigned long long>(cigi->ignored().total()), source->progress().c_str());
      std::fflush(stdout);
    }
    if (o.maxFrames > 0 && frames >= o.maxFrames) break;
  }
  const double elapsed = std::chrono::duration<double>(Clock::now() - start).count();
  std::printf("render: wrote %llu frames to %s in %.1f s; CIGI datagrams accepted %llu, dropped %llu (%s), "
              "ignored packets by id: %s; weather frames dropped %llu\n",
              static_cast<unsigned long long>(frames), o.outDir.c_str(), elapsed,
              static_cast<unsigned long long>(cigi->datagramsAccepted()),
              static_cast<unsigned long long>(cigi->datagramsDropped()), cigi->drops().summary().c_str(),
              cigi->ignoredSummary().c_str(), static_cast<unsigned long long>(weather.malformedFrames()));
  // Host datagram to finished frame (and to the window): p50, p99, max.
  std::printf("render: transport delay over %llu frames: p50 %.1f ms, p99 %.1f ms, max %.1f ms\n",
              static_cast<unsigned long long>(transportDelay.count()), transportDelay.percentile_ms(50),
              transportDelay.percentile_ms(99), transportDelay.max_ms());
  if (presentDelay.count() > 0)
    std::printf("render: to presentation: p50 %.1f ms, p99 %.1f ms, max %.1f ms\n", presentDelay.percentile_ms(50),
                presentDelay.percentile_ms(99), presentDelay.max_ms());
  std::printf("render: view %u: %llu View Definition and %llu View Control applied, %llu packets for other views "
              "ignored, %llu unsupported parts\n",
              o.viewId, static_cast<unsigned long long>(state.view().definitions),
              static_cast<unsigned long long>(state.view().controls),
              static_cast<unsigned long long>(cigi->otherViewPackets()),
              static_cast<unsigned long long>(cigi->unsupportedViewParts()));
  std::printf("render: camera exposure: %llu host settings applied, %llu for other views ignored\n",
              static_cast<unsigned long long>(cigi->hostExposures()),
              static_cast<unsigned long long>(cigi->otherViewExposures()));
  if (const auto line = source->summary(); !line.empty()) std::printf("%s\n", line.c_str());
  std::fflush(stdout);
  shutdown();
  return exitCode;
}
