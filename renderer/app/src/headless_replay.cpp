// Headless replay of a recorded flight (see headless_replay.hpp).
#include "sky/app/headless_replay.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <limits>
#include <map>
#include <optional>
#include <set>
#include <sstream>
#include <thread>

#include <boost/asio.hpp>
#include <nlohmann/json.hpp>

#include "sky/app/area_of_interest.hpp"
#include "sky/app/channel_frame.hpp"
#include "sky/app/fallback_weather.hpp"
#include "sky/app/frame_writer.hpp"
#include "sky/app/pose_source.hpp"
#include "sky/app/radar_image.hpp"
#include "sky/app/replay_outputs.hpp"
#include "sky/app/shared_state.hpp"
#include "sky/app/truth_frames.hpp"
#include "sky/app/weather_client.hpp"
#include "sky/flight/clean.hpp"
#include "sky/flight/file_limits.hpp"
#include "sky/flight/flight.hpp"
#include "sky/flight/info.hpp"
#include "sky/core/assert.hpp"
#include "sky/flight/utf8_text.hpp"
#include "sky/weather/lightning.hpp"
#include "sky/weather/scenario.hpp"

namespace sky::app {

namespace {

namespace asio = boost::asio;
using Clock = std::chrono::steady_clock;

constexpr std::size_t kSheetColumns = 4, kSheetRows = 3;
constexpr std::uint32_t kSheetCellWidth = 240;
// Video frame rate: one video second per flight second (1 / step), kept to
// what players handle.
constexpr double kMinVideoFps = 1, kMaxVideoFps = 60;
// Poll period while waiting for weather.
constexpr auto kWeatherPoll = std::chrono::milliseconds(5);
// How often a window's events are handled while the replay waits for a frame's time.
constexpr auto kWindowPoll = std::chrono::milliseconds(20);
// Least time between a path-traced frame's progress lines: a line every few
// seconds shows it is alive without flooding a log over a frame of minutes.
constexpr auto kTruthProgressPeriod = std::chrono::seconds(5);

std::string duration(double s) {
  char buf[32];
  const long t = std::lround(std::max(0.0, s));
  if (t >= 3600)
    std::snprintf(buf, sizeof buf, "%ldh%02ldm%02lds", t / 3600, t / 60 % 60, t % 60);
  else
    std::snprintf(buf, sizeof buf, "%ldm%02lds", t / 60, t % 60);
  return buf;
}

// Polls until `ready` holds; false on a stop request or after timeout_s.
template <class Ready>
bool waitUntil(Ready ready, double timeout_s, const std::atomic<bool>* stop) {
  const auto until = Clock::now() + std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(timeout_s));
  while (!ready()) {
    if ((stop && *stop) || Clock::now() > until) return false;
    std::this_thread::sleep_for(kWeatherPoll);
  }
  return true;
}

// Waits until the weather version exceeds `after` (a snapshot or delta arrived).
bool waitForWeather(const SharedState& state, std::uint64_t after, double timeout_s, const std::atomic<bool>* stop) {
  return waitUntil([&] { return state.weatherVersion() > after; }, timeout_s, stop);
}

// Waits for the coarse area's first snapshot.
bool waitForCoarse(const SharedState& state, double timeout_s, const std::atomic<bool>* stop) {
  return waitUntil([&] { return state.coarseVersion() > 0; }, timeout_s, stop);
}

// The cleaning's report for report.json.
nlohmann::json cleaningJson(const flight::CleanReport* r, const flight::CleanOptions& options) {
  if (!r) return {{"enabled", false}};
  nlohmann::json dropped = nlohmann::json::array(), gaps = nlohmann::json::array();
  for (const auto& d : r->dropped) {
    nlohmann::json j = {{"reason", flight::toString(d.reason)}, {"count", d.count}, {"time_s", {d.first_s, d.last_s}}};
    if (d.firstLine) j["lines"] = {d.firstLine, d.lastLine};
    if (d.reason == flight::DropReason::Speed || d.reason == flight::DropReason::Jump) j["off_track_m"] = d.offTrack_m;
    if (d.reason == flight::DropReason::Speed) j["implied_speed_mps"] = d.impliedSpeed_mps;
    dropped.push_back(std::move(j));
  }
  for (const auto& g : r->gaps) {
    const char* action = g.action == flight::GapNote::Action::Held    ? "held"
                         : g.action == flight::GapNote::Action::Ended ? "ended"
                                                                       : "interpolated";
    nlohmann::json j = {{"time_s", {g.from_s, g.to_s}}, {"distance_m", g.distance_m}, {"action", action}};
    if (g.fromLine) j["lines"] = {g.fromLine, g.toLine};
    gaps.push_back(std::move(j));
  }
  return {{"enabled", true},
          {"max_ground_speed_mps", options.maxGroundSpeed_mps},
          {"max_gap_s", options.maxGap_s},
          {"long_gap", options.longGap == flight::LongGap::End ? "end" : "hold"},
          {"fixes_in", r->input},
          {"fixes_kept", r->kept},
          {"reordered", r->reordered},
          {"dropped", dropped},
          {"gaps", gaps},
          {"attitude_rederived", r->attitudeRederived},
          {"summary", r->lines(options)}};
}

// What draws a replay's frames: the GPU renderer or the path-traced truth
// (exactly one), and what the report says of it.
struct ReplayDrawer {
  render::CloudRenderer* gpu = nullptr;
  TruthFrames* truth = nullptr;
  const render::RenderSettings& settings;
  std::string device;
};

int runReplay(const ReplayOptions& o, const ReplayDrawer& drawer, const std::atomic<bool>* stop);

}  // namespace

int runHeadlessReplay(const ReplayOptions& o, render::CloudRenderer& renderer, const std::atomic<bool>* stop) {
  return runReplay(o, ReplayDrawer{&renderer, nullptr, renderer.settings(), renderer.deviceName()}, stop);
}

int runTruthReplay(const ReplayOptions& o, TruthFrames& truth, const std::atomic<bool>* stop) {
  SKY_ASSERT(o.display == nullptr && o.budget == nullptr);
  return runReplay(o, ReplayDrawer{nullptr, &truth, truth.settings(), truth.deviceName()}, stop);
}

namespace {

int runReplay(const ReplayOptions& o, const ReplayDrawer& drawer, const std::atomic<bool>* stop) {
  // Flight files are read here and parsed by protocol/ (the renderer does
  // not link sim_clients/).
  auto text = readFile(o.flightPath, flight::kMaxFlightFileBytes);
  auto flight = text ? flight::parseFlight(*text, o.flightPath, o.read)
                     : Result<flight::ParsedFlight>(tl::unexpected(text.error()));
  if (!flight) {
    std::fprintf(stderr, "skyshell-render: %s\n", describe(flight.error()).c_str());
    return 2;
  }
  for (const auto& w : flight->warnings) std::fprintf(stderr, "skyshell-render: warning: %s\n", w.c_str());
  if (!flight->altitudeSource.empty()) std::fprintf(stderr, "skyshell-render: altitude: %s\n", flight->altitudeSource.c_str());
  std::optional<flight::CleanReport> cleaning;
  if (o.clean) {
    auto cleaned = flight::clean(*flight, o.cleanOptions, o.flightPath);
    if (!cleaned) {
      std::fprintf(stderr, "skyshell-render: %s\n", describe(cleaned.error()).c_str());
      return 2;
    }
    cleaning = std::move(*cleaned);
    for (const auto& line : cleaning->lines(o.cleanOptions))
      std::fprintf(stderr, "skyshell-render: cleaning: %s\n", line.c_str());
  } else {
    std::fprintf(stderr, "skyshell-render: cleaning off (--no-clean): the track as read\n");
  }
  const double first_s = flight->fixes.front().time_s;
  const double t0 = first_s + o.start_s;
  const double t1 = o.end_s ? std::min(first_s + *o.end_s, flight->fixes.back().time_s) : flight->fixes.back().time_s;
  if (!(o.step_s > 0) || !(t1 >= t0)) {
    std::fprintf(stderr, "skyshell-render: --replay %s: nothing to render between %.3f s and %.3f s of the flight\n",
                 o.flightPath.c_str(), t0 - first_s, t1 - first_s);
    return 2;
  }
  // A tiny tolerance so that a step dividing the span exactly includes the end.
  const auto frameCount = std::min(static_cast<std::size_t>(std::floor((t1 - t0) / o.step_s + 1e-9)) + 1,
                                   o.maxFrames > 0 ? o.maxFrames : std::numeric_limits<std::size_t>::max());

  auto writer = FrameWriter::open(o.outDir + "/frames", o.outputs, RunSettings{o.preset, drawer.settings});
  if (!writer) {
    std::fprintf(stderr, "skyshell-render: %s\n", describe(writer.error()).c_str());
    return 2;
  }

  SharedState state;
  asio::io_context io;
  auto guard = asio::make_work_guard(io);
  // The weather: streamed by a server, or read once from a scenario file.
  std::optional<WeatherClient> weather;
  std::string weatherSource;
  if (!o.weatherFile.empty()) {
    const auto now = Clock::now();
    auto view = scenarioWeather(o.weatherFile, now);
    if (!view) {
      std::fprintf(stderr, "skyshell-render: --weather-file: %s\n", describe(view.error()).c_str());
      return 2;
    }
    state.setSnapshot(std::move(view->snapshot), now);
    state.setClock(view->clock.at(now), view->clock.rate(), now);
    weatherSource = o.weatherFile;
  } else {
    weather.emplace(io, state, o.serverHost, o.serverPort);
    // Its frames ask for their flashes (below): the ones the server sends
    // at its own clock are not theirs.
    weather->takeOnlyAskedFlashes();
    weather->start();
    weatherSource = o.serverHost + ":" + std::to_string(o.serverPort);
  }
  std::thread ioThread([&] { io.run(); });
  struct Stopper {
    std::optional<WeatherClient>& weather;
    decltype(guard)& g;
    std::thread& t;
    ~Stopper() {
      if (weather) weather->stop();
      g.reset();
      t.join();
    }
  } stopper{weather, guard, ioThread};

  const auto& s = drawer.settings;
  std::printf("skyshell-render: replaying %s %s: %zu frames of %.3f s (flight %.1f-%.1f s) at %ux%u, "
              "weather from %s, output to %s\n",
              o.flightPath.c_str(), o.display ? "in a window" : "headless", frameCount, o.step_s, t0 - first_s, t1 - first_s, s.width, s.height,
              weatherSource.c_str(), o.outDir.c_str());
  if (drawer.truth)
    std::printf("skyshell-render: path-traced truth: %u samples per pixel on %u threads (slow: the first frame's "
                "rows say how slow)\n",
                drawer.truth->truth().samplesPerPixel, drawer.truth->threads());
  std::fflush(stdout);

  // The camera and the time of day come from the flight, as a live
  // channel's come from its host.
  FlightPoseSource poses(*flight, t0 - first_s, Clock::now(), o.pace > 0 ? o.pace : 1.0, o.fixedSun);
  const HostPose firstHost = poses.poseAtFlightTime(t0 - first_s, 0);
  geo::GeodeticPose pose = firstHost.pose;
  AreaTracker areas;
  if (weather)
    for (const auto& area : areas.update(pose)) weather->subscribe(area);
  if (!waitForWeather(state, 0, o.weatherTimeout_s, stop)) {
    std::fprintf(stderr, "skyshell-render: no weather from %s within %.0f s\n", weatherSource.c_str(),
                 o.weatherTimeout_s);
    return 4;
  }
  // The coarse ring's weather too, when the server sends it, so that the
  // first frames already see the far weather (the detailed area comes first).
  if (weather && weather->serverTakesAreas() && !waitForCoarse(state, o.weatherTimeout_s, stop))
    std::fprintf(stderr, "skyshell-render: warning: no coarse-area weather within %.0f s; the coarse ring "
                         "holds the detailed area's\n", o.weatherTimeout_s);
  const WeatherView firstView = state.weather();
  // The first frame's weather clock. From a file: the file's own clock (its
  // start), never the wall clock's offset from when it was read, so that two
  // runs draw the same frames byte for byte. From a server: its clock now,
  // which differs between runs; --weather-clock pins it.
  const double clockBase_s = o.weatherClock_s       ? *o.weatherClock_s
                             : !o.weatherFile.empty() ? firstView.snapshot.weatherClock_s
                                                      : firstView.clockNow(Clock::now());
  const std::string clockFrom = o.weatherClock_s       ? "--weather-clock"
                                : !o.weatherFile.empty() ? "the weather file's clock"
                                                         : "the server's clock at the first frame";
  const double clockRate = firstView.clock.rate();

  // The real sun when the record says when it was flown.
  const bool sunFromDate = firstHost.timeSource == TimeSource::FlightFile;
  const auto picks = ContactSheet::pick(frameCount, kSheetColumns * kSheetRows);
  ContactSheet sheet(kSheetColumns, kSheetRows, kSheetCellWidth, s.width, s.height);
  std::size_t nextPick = 0;
  std::vector<double> renderMs;
  std::map<std::string, std::vector<double>> gpuMs;  // per pass, over the frames it ran in
  std::set<std::uint64_t> versionsSeen;
  std::size_t nonFinite = 0;
  const auto start = Clock::now();
  auto lastReport = start;
  int exitCode = 0;
  std::size_t done = 0;
  ChannelFrames frames = drawer.truth ? ChannelFrames(*drawer.truth, *writer) : ChannelFrames(*drawer.gpu, *writer, o.display);
  frames.setBudget(o.budget);
  frames.setExposure(o.exposure_s);
  frames.setCameraExposure(o.cameraExposure);
  std::map<std::string, std::size_t> framesPerLevel;
  std::size_t drawing = 0;  // the frame being drawn
  std::uint64_t violations = 0;
  auto lastRows = start;
  if (drawer.truth) {
    // A path-traced frame takes seconds to minutes: its rows say how far it
    // is, and the time left counts the rows of the frames still to draw.
    drawer.truth->setProgress([&](std::uint32_t rows, std::uint32_t all) {
      const auto now = Clock::now();
      // The first row of all says at once how slow the frames will be.
      if (now - lastRows < kTruthProgressPeriod && !(drawing == 0 && rows == 1)) return;
      lastRows = now;
      const double elapsed = std::chrono::duration<double>(now - start).count();
      const double rowsDone = double(drawing) * all + rows, rowsAll = double(frameCount) * all;
      const double rate = elapsed > 0 ? rowsDone / elapsed : 0;
      std::printf("truth: frame %zu/%zu, rows %u/%u, %.2f rows/s, %s elapsed, %s left\n", drawing + 1, frameCount,
                  rows, all, rate, duration(elapsed).c_str(),
                  duration(rate > 0 ? (rowsAll - rowsDone) / rate : 0).c_str());
      std::fflush(stdout);
    });
  }
  // A paced replay keeps its pace as a live channel does: it waits for the
  // server's answers (a new area's weather, the lightning at a frame's clock)
  // until the next frame is due at most, then draws the weather it holds. A
  // server that falls silent (a relay cut off, its socket still open) would
  // otherwise hold every frame for the whole --weather-timeout. Unpaced, a
  // replay waits the full timeout: its frames are what it is run for.
  const double answerWait_s = o.pace > 0 ? std::min(o.weatherTimeout_s, o.step_s / o.pace) : o.weatherTimeout_s;
  for (std::size_t i = 0; i < frameCount; ++i) {
    drawing = i;
    if (stop && *stop) {
      exitCode = 1;
      break;
    }
    const double t = t0 + double(i) * o.step_s;
    if (o.pace > 0) {
      const auto due = start + std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>((t - t0) / o.pace));
      // A window keeps handling its events while the replay waits.
      while (o.display && Clock::now() + kWindowPoll < due && !o.display->closed()) {
        o.display->poll();
        std::this_thread::sleep_for(kWindowPoll);
      }
      std::this_thread::sleep_until(due);
    }
    if (o.display && o.display->closed()) {
      std::printf("replay: the window was closed after %zu frames\n", done);
      break;
    }
    const HostPose host = poses.poseAtFlightTime(t - first_s, static_cast<std::uint32_t>(i));
    pose = host.pose;
    if (const auto asked = weather ? areas.update(pose) : std::vector<stream::Subscribe>{}; !asked.empty()) {
      const std::uint64_t before = state.weatherVersion();
      for (const auto& area : asked) weather->subscribe(area);
      if (!waitForWeather(state, before, answerWait_s, stop))
        std::fprintf(stderr, "skyshell-render: warning: frame %zu: no weather for the new area within %.3g s; "
                             "drawing the old area's\n", i, answerWait_s);
    }
    const double frameClock_s = clockBase_s + (t - t0) * clockRate;
    // The lightning at this frame's clock: the server's stream sends flashes
    // as its own clock runs, which a replay's frames run ahead of or behind,
    // so the replay asks for the flashes still giving light at its frame.
    // A server that goes away (its connection lost) ends the wait at once:
    // the frame draws the flashes it holds, as it draws the weather it holds.
    if (weather && weather->serverTakesLightningRequests()) {
      weather->requestLightning(frameClock_s - weather::kFlashLifetime_s - o.exposure_s, frameClock_s);
      const auto answered = [&] {
        const auto to = state.lightningAnsweredTo();
        return (to && *to >= frameClock_s) || !weather->serverTakesLightningRequests();
      };
      if (!waitUntil(answered, answerWait_s, stop))
        std::fprintf(stderr, "skyshell-render: warning: frame %zu: no lightning answer from the server within %.3g s\n",
                     i, answerWait_s);
    }
    const WeatherView view = state.weather();
    FrameRequest request;
    request.host = host;
    request.source = poses.source();
    request.camera = pose;
    request.weather = &view;
    request.weatherSource = o.weatherFile.empty() ? "server" : "file";
    request.weatherConnected = view.connected;
    request.weatherClock_s = frameClock_s;
    request.sunAzimuth_deg = o.sunAzimuth_deg;
    request.sunElevation_deg = o.sunElevation_deg;
    request.utc_s = host.utc_s;
    request.utcSource = host.timeSource;
    request.frameIndex = i;
    request.hostTime_s = t;
    auto drawn = frames.draw(request);
    if (!drawn) {
      std::fprintf(stderr, "skyshell-render: %s\n", drawn.error().message.c_str());
      exitCode = drawn.error().exitCode;
      break;
    }
    if (weather) weather->reportCamera(pose, i, view.version, request.weatherClock_s);
    if (o.radarRange_m) {
      char name[48];
      std::snprintf(name, sizeof name, "/frames/radar_%06zu.png", i);
      if (auto ok = writeRadarPicture(view.snapshot, request.weatherClock_s, pose.position, *o.radarRange_m, o.outDir + name);
          !ok) {
        std::fprintf(stderr, "skyshell-render: %s\n", describe(ok.error()).c_str());
        exitCode = 2;
        break;
      }
    }
    const FrameRecord& record = drawn->record;
    renderMs.push_back(record.render_ms);
    if (record.budget) ++framesPerLevel[record.budget->name];
    for (const auto& pass : record.gpu) gpuMs[pass.pass].push_back(pass.gpu_ms);
    versionsSeen.insert(view.version);
    nonFinite += record.stats.nonFinite;
    if (record.truth) violations += record.truth->majorantViolations;
    if (nextPick < picks.size() && picks[nextPick] == i) {
      sheet.add(drawn->image, record.cameraExposure.exposure);
      ++nextPick;
    }
    done = i + 1;
    const auto now = Clock::now();
    if (now - lastReport > std::chrono::seconds(1) || done == frameCount) {
      lastReport = now;
      const double elapsed = std::chrono::duration<double>(now - start).count();
      const double rate = elapsed > 0 ? double(done) / elapsed : 0;
      std::printf("replay: frame %zu/%zu (%.0f%%), %.2f frames/s, %s elapsed, %s left\n", done, frameCount,
                  100.0 * double(done) / double(frameCount), rate, duration(elapsed).c_str(),
                  duration(rate > 0 ? double(frameCount - done) / rate : 0).c_str());
      std::fflush(stdout);
    }
  }
  const double wall_s = std::chrono::duration<double>(Clock::now() - start).count();
  // The progress reads this loop's locals: it ends with them.
  if (drawer.truth) drawer.truth->setProgress({});

  nlohmann::json report;
  if (done > 0) {
    const std::string sheetPath = o.outDir + "/contact-sheet.png";
    if (auto ok = render::writePng(sheet.image(), sheetPath); ok)
      report["contact_sheet"] = "contact-sheet.png";
    else
      std::fprintf(stderr, "skyshell-render: warning: %s\n", describe(ok.error()).c_str());
    if (o.video && o.outputs.png && exitCode == 0) {
      const double fps = std::clamp(1.0 / o.step_s, kMinVideoFps, kMaxVideoFps);
      if (auto ok = encodeVideo(o.outDir + "/frames", fps, o.outDir + "/replay.mp4"); ok)
        report["video"] = "replay.mp4";
      else
        std::fprintf(stderr, "skyshell-render: warning: no video: %s\n", describe(ok.error()).c_str());
    }
  }
  const Percentiles ms = percentiles(renderMs);
  report["flight"] = o.flightPath;
  // The format the file was read as (as skyshell-replay --info names it).
  report["flight_format"] = flight::formatName(*text, o.flightPath);
  report["flight_window_s"] = {t0 - first_s, t1 - first_s};
  report["step_s"] = o.step_s;
  report["frames"] = done;
  report["frames_planned"] = frameCount;
  report["complete"] = exitCode == 0 && done == frameCount;
  report["resolution"] = {s.width, s.height};
  report["vertical_fov_deg"] = s.verticalFov_deg;
  report["noise_seed"] = s.noiseSeed;
  report["preset"] = o.preset;
  // The camera's exposure of the PNGs and the contact sheet (each frame's in frames.jsonl).
  if (o.cameraExposure) {
    const render::ExposureSettings& e = o.cameraExposure->settings();
    report["camera_exposure"] = {{"mode", e.automatic ? "auto" : "fixed"},
                                 {"ev100", e.automatic ? nlohmann::json() : nlohmann::json(e.fixedEv100)},
                                 {"compensation_ev", e.compensation_ev},
                                 {"adaptation_tau_s", e.adaptationTau_s},
                                 {"meter_period_s", e.meterPeriod_s}};
  }
  if (o.budget) {
    report["budget"] = {{"target_ms", o.budget->target_ms()}, {"frames_per_level", framesPerLevel}};
  }
  if (sunFromDate) {
    report["sun"] = "ephemeris at the recorded date and time";
    report["utc_start_s"] = *firstHost.utc_s;
  } else {
    report["sun"] = {{"azimuth_deg", o.sunAzimuth_deg}, {"elevation_deg", o.sunElevation_deg}};
  }
  report["device"] = drawer.device;
  // What drew the frames: the GPU, or the path tracer (each frame's samples
  // and standard error in frames.jsonl "truth").
  if (drawer.truth)
    report["truth"] = {{"mode", "path"},
                       {"samples_per_pixel", drawer.truth->truth().samplesPerPixel},
                       {"threads", drawer.truth->threads()},
                       {"seed", "frame index + 1"},
                       {"majorant_violations", violations},
                       {"exr_channel", o.outputs.exr ? nlohmann::json(kExrTruthStandardError) : nlohmann::json()}};
  else
    report["truth"] = {{"mode", "none"}};
  report["render_ms"] = {{"p50", ms.p50}, {"p90", ms.p90}, {"p99", ms.p99}, {"mean", ms.mean}, {"max", ms.max}};
  nlohmann::json gpu = nlohmann::json::object();
  for (const auto& [pass, samples] : gpuMs) {
    const Percentiles p = percentiles(samples);
    gpu[pass] = {{"frames", samples.size()}, {"p50", p.p50}, {"p90", p.p90}, {"p99", p.p99}, {"mean", p.mean},
                 {"max", p.max}};
  }
  report["gpu_ms"] = gpu;
  report["wall_s"] = wall_s;
  report["weather_source"] = weatherSource;
  report["weather_clock_s"] = {clockBase_s, clockBase_s + double(frameCount - 1) * o.step_s * clockRate};
  report["weather_clock_rate"] = clockRate;
  report["weather_clock_from"] = clockFrom;
  if (!o.weatherClock_s && o.weatherFile.empty()) {
    char pin[160];
    std::snprintf(pin, sizeof pin, "--weather-clock %.6f draws the same weather again (byte-identical frames)",
                  clockBase_s);
    report["weather_clock_pin"] = pin;
  }
  report["cleaning"] = cleaningJson(cleaning ? &*cleaning : nullptr, o.cleanOptions);
  // Where the altitudes came from, where the format has more than one kind
  // (ADS-B, readsb: geometric or barometric through the standard atmosphere);
  // null where the file has one kind, taken as written.
  report["altitude_source"] = flight->altitudeSource.empty() ? nlohmann::json(nullptr)
                                                              : nlohmann::json(flight->altitudeSource);
  report["weather_versions_seen"] = versionsSeen;
  report["non_finite_pixels"] = nonFinite;
  if (o.display) report["frames_presented"] = o.display->presented();
  report["metadata_index"] = "frames/frames.jsonl";
  std::ofstream(o.outDir + "/report.json", std::ios::trunc) << report.dump(2) << '\n';
  std::printf("replay: wrote %zu frames to %s/frames in %.1f s (render p50 %.0f ms, p90 %.0f ms); "
              "report %s/report.json\n",
              done, o.outDir.c_str(), wall_s, ms.p50, ms.p90, o.outDir.c_str());
  std::fflush(stdout);
  return exitCode;
}

}  // namespace

}  // namespace sky::app
