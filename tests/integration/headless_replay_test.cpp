// skyshell-render --replay against a running skyshell-weatherd: every step of
// the flight becomes a frame whose camera is the flight's pose at that time,
// two runs with the same inputs give byte-identical PNGs, and the run leaves
// a video, a contact sheet and a report that say what happened. A bad flight
// file is refused with its line and field.
#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "child_process.hpp"
#include "sky/flight/flight.hpp"

namespace fs = std::filesystem;
using namespace std::chrono_literals;

namespace sky::test {
namespace {

// The 6 s test flight at one frame per 1.5 s: frames at 0, 1.5, 3, 4.5, 6 s.
constexpr double kStep_s = 1.5;
constexpr std::size_t kFrames = 5;
// Pinned so the two runs see the same weather clock.
constexpr const char* kWeatherClock = "5000";
// The metadata carries the pose in decimal JSON (shortest round-trip form):
// compare with what the flight says to well below a millimetre.
constexpr double kPoseTolerance_deg = 1e-9;
constexpr double kAltTolerance_m = 1e-6;

std::string readAll(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

struct ReplayRun {
  int exitCode = -1;
  std::string log;
};

ReplayRun replay(unsigned weatherPort, const std::string& flight, const fs::path& out,
                 std::vector<std::string> extra = {}) {
  std::vector<std::string> argv = {SKY_RENDER, "--headless", "--server", "127.0.0.1:" + std::to_string(weatherPort),
                                   "--replay", flight, "--step", std::to_string(kStep_s), "--weather-clock",
                                   kWeatherClock, "--out", out.string(), "--width", "160", "--height", "90"};
  argv.insert(argv.end(), extra.begin(), extra.end());
  // Leak checking off for the renderer only (as in skeleton_test.cpp): lavapipe's JIT.
  ChildProcess render(argv, out.string() + ".log", {"ASAN_OPTIONS=detect_leaks=0:abort_on_error=1"});
  const auto code = render.wait(300s);
  return {code.value_or(-1), render.log()};
}

class HeadlessReplay : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::path(SKY_TEST_OUTPUT_DIR) / ("replay-" + std::string(::testing::UnitTest::GetInstance()->current_test_info()->name()));
    fs::remove_all(dir_);
    fs::create_directories(dir_);
    // The server's weather is an input of the render: its snapshots carry
    // the weather clock they were made at, and the renderer advects their
    // coverage from then on. A frozen clock makes that input the same in
    // every run; the cumulus layer (10 m/s westerly) of the bundled scenario.
    std::ifstream cloudy(SKY_SCENARIO_CLOUDY);
    std::ostringstream text;
    text << cloudy.rdbuf();
    std::string scenario = text.str();
    const auto rate = scenario.find("rate = 1.0");
    ASSERT_NE(rate, std::string::npos);
    scenario.replace(rate, 10, "rate = 0.0");
    std::ofstream(dir_ / "frozen.toml") << scenario;
    weatherd_.emplace(std::vector<std::string>{SKY_WEATHERD, "--scenario", (dir_ / "frozen.toml").string(), "--port",
                                               "0", "--port-file", (dir_ / "weatherd.port").string()},
                      (dir_ / "weatherd.log").string());
    port_ = waitForPortFile((dir_ / "weatherd.port").string(), 20s);
    ASSERT_GT(port_, 0u) << weatherd_->log();
  }
  void TearDown() override {
    if (weatherd_) {
      EXPECT_EQ(weatherd_->stop(), 0) << weatherd_->log();
    }
  }
  fs::path dir_;
  std::optional<ChildProcess> weatherd_;
  unsigned port_ = 0;
};

TEST_F(HeadlessReplay, FramesFollowTheFlightAreDeterministicAndReported) {
  const ReplayRun a = replay(port_, SKY_TEST_FLIGHT, dir_ / "a");
  ASSERT_EQ(a.exitCode, 0) << a.log;
  const ReplayRun b = replay(port_, SKY_TEST_FLIGHT, dir_ / "b", {"--no-video"});
  ASSERT_EQ(b.exitCode, 0) << b.log;
  EXPECT_NE(a.log.find("replay: frame 5/5 (100%)"), std::string::npos) << "no progress line in\n" << a.log;

  // The flight as the protocol reader sees it: the oracle for the camera.
  auto flight = flight::parseCsv(readAll(SKY_TEST_FLIGHT), SKY_TEST_FLIGHT);
  ASSERT_TRUE(flight);

  std::vector<nlohmann::json> frames;
  std::ifstream jsonl(dir_ / "a" / "frames" / "frames.jsonl");
  for (std::string line; std::getline(jsonl, line);)
    if (!line.empty()) frames.push_back(nlohmann::json::parse(line));
  ASSERT_EQ(frames.size(), kFrames);
  for (std::size_t i = 0; i < kFrames; ++i) {
    const auto& f = frames[i];
    const double t = double(i) * kStep_s;
    EXPECT_EQ(f["source"], "replay");
    EXPECT_NEAR(f["host_time_s"].get<double>(), t, 1e-9);
    EXPECT_NEAR(f["weather_clock_s"].get<double>(), 5000.0, 1e-9) << "pinned, and the server's clock is frozen";
    const geo::GeodeticPose want = flight::sample(*flight, t);
    EXPECT_NEAR(f["lat_deg"].get<double>(), want.position.lat_deg, kPoseTolerance_deg) << "frame " << i;
    EXPECT_NEAR(f["lon_deg"].get<double>(), want.position.lon_deg, kPoseTolerance_deg) << "frame " << i;
    EXPECT_NEAR(f["alt_m"].get<double>(), want.position.alt_m, kAltTolerance_m) << "frame " << i;
    EXPECT_NEAR(f["yaw_deg"].get<double>(), want.yaw_deg, 1e-9);
    EXPECT_NEAR(f["pitch_deg"].get<double>(), want.pitch_deg, 1e-9);
    EXPECT_EQ(f["non_finite"], 0);
    EXPECT_EQ(f["layers"], 1);
    // Byte-identical re-render.
    const std::string file = f["file"];
    const std::string pngA = readAll(dir_ / "a" / "frames" / file), pngB = readAll(dir_ / "b" / "frames" / file);
    ASSERT_GT(pngA.size(), 100u);
    EXPECT_TRUE(pngA == pngB) << file << " differs between two runs with the same inputs";
  }
  // The camera moved east along the flight (55 m/s for 6 s), so the frames differ.
  EXPECT_NE(readAll(dir_ / "a" / "frames" / "frame_000000.png"), readAll(dir_ / "a" / "frames" / "frame_000004.png"));

  const auto report = nlohmann::json::parse(readAll(dir_ / "a" / "report.json"));
  EXPECT_EQ(report["frames"], kFrames);
  EXPECT_EQ(report["complete"], true);
  EXPECT_EQ(report["resolution"], nlohmann::json::array({160, 90}));
  EXPECT_EQ(report["non_finite_pixels"], 0);
  EXPECT_EQ(report["metadata_index"], "frames/frames.jsonl");
  EXPECT_FALSE(report["weather_versions_seen"].empty());
  EXPECT_GT(report["render_ms"]["p50"].get<double>(), 0.0);
  EXPECT_LE(report["render_ms"]["p50"].get<double>(), report["render_ms"]["p90"].get<double>());
  EXPECT_EQ(report["weather_clock_s"], nlohmann::json::array({5000.0, 5000.0}));
  EXPECT_EQ(report["weather_clock_rate"], 0.0);

  // The contact sheet is a PNG; the video an MP4 (ISO base media: 'ftyp' box first).
  const std::string sheet = readAll(dir_ / "a" / "contact-sheet.png");
  ASSERT_GT(sheet.size(), 8u);
  EXPECT_EQ(sheet.substr(1, 3), "PNG");
  EXPECT_EQ(report["video"], "replay.mp4");
  const std::string mp4 = readAll(dir_ / "a" / "replay.mp4");
  ASSERT_GT(mp4.size(), 1000u) << a.log;
  EXPECT_EQ(mp4.substr(4, 4), "ftyp");
  EXPECT_FALSE(fs::exists(dir_ / "b" / "replay.mp4")) << "--no-video must not write one";
}

// With the server's clock running at x1, frame i's weather clock is the
// pinned start plus the flight time it shows.
TEST_F(HeadlessReplay, WeatherClockFollowsFlightTimeAtTheServersRate) {
  ChildProcess live({SKY_WEATHERD, "--scenario", SKY_SCENARIO_CLOUDY, "--port", "0", "--port-file",
                     (dir_ / "live.port").string()},
                    (dir_ / "live.log").string());
  const unsigned port = waitForPortFile((dir_ / "live.port").string(), 20s);
  ASSERT_GT(port, 0u) << live.log();
  const ReplayRun run = replay(port, SKY_TEST_FLIGHT, dir_ / "live", {"--no-video"});
  ASSERT_EQ(run.exitCode, 0) << run.log;
  std::ifstream jsonl(dir_ / "live" / "frames" / "frames.jsonl");
  std::size_t n = 0;
  for (std::string line; std::getline(jsonl, line); ++n) {
    const auto f = nlohmann::json::parse(line);
    EXPECT_NEAR(f["weather_clock_s"].get<double>(), 5000.0 + double(n) * kStep_s, 1e-9);
  }
  EXPECT_EQ(n, kFrames);
  EXPECT_EQ(live.stop(), 0) << live.log();
}

// Lightning at the frames' own clock: the server's process draws flashes as
// its clock runs (near 0 s here), far from the replay's (5000 s on); the
// replay asks the server for the flashes of each frame's clock, so its
// frames show the storm's flashes, the same in every run.
TEST_F(HeadlessReplay, FramesShowTheStormsLightningAtTheirOwnClock) {
  std::ifstream cloudy(SKY_SCENARIO_CLOUDY);
  std::ostringstream text;
  text << cloudy.rdbuf();
  std::string scenario = text.str();
  const auto type = scenario.find("type = \"cumulus\"");
  ASSERT_NE(type, std::string::npos);
  scenario.replace(type, 16, "type = \"cumulonimbus\"");
  std::ofstream(dir_ / "storm.toml") << scenario;
  ChildProcess storm({SKY_WEATHERD, "--scenario", (dir_ / "storm.toml").string(), "--port", "0", "--port-file",
                      (dir_ / "storm.port").string(), "--lightning-rate", "2", "--lightning-seed", "7"},
                     (dir_ / "storm.log").string());
  const unsigned port = waitForPortFile((dir_ / "storm.port").string(), 20s);
  ASSERT_GT(port, 0u) << storm.log();
  const ReplayRun a = replay(port, SKY_TEST_FLIGHT, dir_ / "sa", {"--no-video"});
  ASSERT_EQ(a.exitCode, 0) << a.log;
  const ReplayRun b = replay(port, SKY_TEST_FLIGHT, dir_ / "sb", {"--no-video"});
  ASSERT_EQ(b.exitCode, 0) << b.log;
  EXPECT_EQ(storm.stop(), 0) << storm.log();
  const auto lit = [&](const char* run) {
    std::vector<nlohmann::json> out;
    std::ifstream jsonl(dir_ / run / "frames" / "frames.jsonl");
    for (std::string line; std::getline(jsonl, line);) {
      const auto f = nlohmann::json::parse(line);
      out.push_back(f.value("lightning", nlohmann::json::array()));
      const double clock = f["weather_clock_s"].get<double>();
      for (const auto& flash : out.back()) {
        EXPECT_LE(flash["time_s"].get<double>(), clock) << run;
        EXPECT_GT(flash["time_s"].get<double>(), clock - 2.0) << run << ": a flash lights its sky for under 2 s";
      }
    }
    return out;
  };
  const auto litA = lit("sa"), litB = lit("sb");
  ASSERT_EQ(litA.size(), kFrames);
  std::size_t flashes = 0;
  for (const auto& l : litA) flashes += l.size();
  // The storm covers every area the replay watches at 2 flashes a minute per
  // 100 km^2: tens of flashes a second over the area, a few in each frame.
  EXPECT_GT(flashes, kFrames) << a.log;
  EXPECT_EQ(litA, litB) << "the same flashes at the same clocks in both runs";
}

// An ADS-B track with two aircraft: refused with both listed, until
// --icao24 picks one, whose fixes the frames then follow.
TEST_F(HeadlessReplay, AnAdsbFileWithTwoAircraftNeedsOneChosen) {
  const std::string two = SKY_TEST_DATA_DIR "/adsb/opensky-two-aircraft.csv";
  const std::vector<std::string> file = {"--weather-file", SKY_SCENARIO_CLOUDY, "--no-video", "--replay-end", "3"};
  const ReplayRun refused = replay(port_, two, dir_ / "two", file);
  EXPECT_EQ(refused.exitCode, 2) << refused.log;
  EXPECT_NE(refused.log.find("3c6444"), std::string::npos) << refused.log;
  EXPECT_NE(refused.log.find("4b1815"), std::string::npos) << refused.log;
  std::vector<std::string> chosen = file;
  chosen.insert(chosen.end(), {"--icao24", "4B1815", "--exposure-ms", "4"});
  const ReplayRun one = replay(port_, two, dir_ / "one", chosen);
  ASSERT_EQ(one.exitCode, 0) << one.log;
  EXPECT_NE(one.log.find("altitude:"), std::string::npos) << "the altitude's source is said\n" << one.log;
  const auto report = nlohmann::json::parse(readAll(dir_ / "one" / "report.json"));
  ASSERT_TRUE(report["altitude_source"].is_string()) << report.dump(2);
  EXPECT_NE(report["altitude_source"].get<std::string>().find("geometric"), std::string::npos) << report.dump(2);
  std::ifstream jsonl(dir_ / "one" / "frames" / "frames.jsonl");
  std::string line;
  ASSERT_TRUE(std::getline(jsonl, line));
  const auto f = nlohmann::json::parse(line);
  EXPECT_NEAR(f["lat_deg"].get<double>(), 47.45, 1e-9) << "4b1815's first fix";
  EXPECT_NEAR(f["alt_m"].get<double>(), 3050.0, 1e-6) << "its geometric altitude";
  EXPECT_NEAR(f["exposure_s"].get<double>(), 0.004, 1e-12) << "--exposure-ms reaches the frame";
}

// A KML with two aircraft's tracks: refused with both named, until --track
// picks one, whose fixes the frames then follow.
TEST_F(HeadlessReplay, AKmlWithTwoTracksNeedsOneChosen) {
  const fs::path two = dir_ / "two-tracks.kml";
  auto track = [](const char* name, double lat) {
    std::string t = std::string("<Placemark><name>") + name + "</name><gx:Track><altitudeMode>absolute</altitudeMode>";
    for (int i = 0; i < 5; ++i) t += "<when>2024-03-10T14:00:" + std::to_string(10 + 2 * i) + "Z</when>";
    for (int i = 0; i < 5; ++i) t += "<gx:coord>" + std::to_string(12.80 + 0.002 * i) + " " + std::to_string(lat) + " 1200</gx:coord>";
    return t + "</gx:Track></Placemark>\n";
  };
  std::ofstream(two) << "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n"
                        "<kml xmlns=\"http://www.opengis.net/kml/2.2\" xmlns:gx=\"http://www.google.com/kml/ext/2.2\">"
                        "<Document>\n"
                     << track("DLH400", 46.20) << track("AUA123", 46.30) << "</Document></kml>\n";
  const std::vector<std::string> file = {"--weather-file", SKY_SCENARIO_CLOUDY, "--no-video", "--replay-end", "4"};
  const ReplayRun refused = replay(port_, two.string(), dir_ / "k2", file);
  EXPECT_EQ(refused.exitCode, 2) << refused.log;
  EXPECT_NE(refused.log.find("DLH400"), std::string::npos) << refused.log;
  EXPECT_NE(refused.log.find("AUA123"), std::string::npos) << refused.log;
  std::vector<std::string> chosen = file;
  chosen.insert(chosen.end(), {"--track", "AUA123"});
  const ReplayRun one = replay(port_, two.string(), dir_ / "k1", chosen);
  ASSERT_EQ(one.exitCode, 0) << one.log;
  std::ifstream jsonl(dir_ / "k1" / "frames" / "frames.jsonl");
  std::string line;
  ASSERT_TRUE(std::getline(jsonl, line));
  const auto f = nlohmann::json::parse(line);
  EXPECT_NEAR(f["lat_deg"].get<double>(), 46.30, 1e-9) << "AUA123's first fix";
  EXPECT_NEAR(f["lon_deg"].get<double>(), 12.80, 1e-9);
  EXPECT_NEAR(f["alt_m"].get<double>(), 1200.0, 1e-6);
}

// Without a server: the weather of a scenario file, the same in every run.
TEST_F(HeadlessReplay, WeatherFileWithoutAServer) {
  // The fixture's server is stopped first: nothing answers on its port.
  ASSERT_EQ(weatherd_->stop(), 0) << weatherd_->log();
  weatherd_.reset();
  const std::vector<std::string> noServer = {"--weather-file", SKY_SCENARIO_CLOUDY, "--no-video", "--replay-end", "3"};
  const ReplayRun a = replay(port_, SKY_TEST_FLIGHT, dir_ / "fa", noServer);
  ASSERT_EQ(a.exitCode, 0) << a.log;
  // The second run stops early (--max-frames) and draws the same frames.
  std::vector<std::string> twoFrames = noServer;
  twoFrames.insert(twoFrames.end(), {"--max-frames", "2"});
  const ReplayRun b = replay(port_, SKY_TEST_FLIGHT, dir_ / "fb", twoFrames);
  ASSERT_EQ(b.exitCode, 0) << b.log;
  const auto report = nlohmann::json::parse(readAll(dir_ / "fa" / "report.json"));
  EXPECT_EQ(report["weather_source"], SKY_SCENARIO_CLOUDY);
  EXPECT_EQ(report["frames"], 3);  // 0, 1.5, 3 s
  const auto reportB = nlohmann::json::parse(readAll(dir_ / "fb" / "report.json"));
  EXPECT_EQ(reportB["frames"], 2);
  EXPECT_EQ(reportB["complete"], true);
  EXPECT_FALSE(fs::exists(dir_ / "fb" / "frames" / "frame_000002.png"));
  for (const char* f : {"frame_000000.png", "frame_000001.png"})
    EXPECT_TRUE(readAll(dir_ / "fa" / "frames" / f) == readAll(dir_ / "fb" / "frames" / f)) << f;
  std::ifstream jsonl(dir_ / "fa" / "frames" / "frames.jsonl");
  std::string line;
  ASSERT_TRUE(std::getline(jsonl, line));
  EXPECT_EQ(nlohmann::json::parse(line)["layers"], 1);
}

TEST_F(HeadlessReplay, BadFlightFileIsRefusedWithLineAndField) {
  const fs::path bad = dir_ / "bad.csv";
  std::ofstream(bad) << "time_s,lat_deg,lon_deg,alt_m,yaw_deg,pitch_deg,roll_deg\n"
                        "0,46.2,12.8,900,90,0,0\n"
                        "1,146.2,12.8,900,90,0,0\n";
  const ReplayRun r = replay(port_, bad.string(), dir_ / "out");
  EXPECT_EQ(r.exitCode, 2) << r.log;
  EXPECT_NE(r.log.find("bad.csv:3"), std::string::npos) << r.log;
  EXPECT_NE(r.log.find("lat_deg"), std::string::npos) << r.log;
  EXPECT_FALSE(fs::exists(dir_ / "out" / "frames" / "frame_000000.png"));

  const ReplayRun missing = replay(port_, (dir_ / "nope.igc").string(), dir_ / "out2");
  EXPECT_EQ(missing.exitCode, 2) << missing.log;
  EXPECT_NE(missing.log.find("nope.igc: cannot open"), std::string::npos) << missing.log;
}

}  // namespace
}  // namespace sky::test

namespace sky::test {
namespace {

// An interleaved preset through the whole program: the first frame is drawn
// whole, the frames after it reuse the history (the camera moves a few metres
// a frame), and the metadata says so per frame, with the reprojection pass
// timed. `realtime` draws the clouds at half the size (80x45 here, the
// pixels the counts are of) and upscales them.
TEST_F(HeadlessReplay, InterleavedPresetReportsItsReprojection) {
  ASSERT_EQ(weatherd_->stop(), 0) << weatherd_->log();
  weatherd_.reset();
  std::vector<std::string> args = {"--weather-file", SKY_SCENARIO_CLOUDY, "--no-video", "--replay-end", "2",
                                   "--preset", "realtime", "--max-frames", "8"};
  // --step is the fixture's 1.5 s; this run wants frames 0.1 s apart.
  std::vector<std::string> argv = {SKY_RENDER, "--headless", "--replay", SKY_TEST_FLIGHT, "--step", "0.1",
                                   "--weather-clock", kWeatherClock, "--out", (dir_ / "rt").string(),
                                   "--width", "160", "--height", "90"};
  argv.insert(argv.end(), args.begin(), args.end());
  ChildProcess render(argv, (dir_ / "rt").string() + ".log", {"ASAN_OPTIONS=detect_leaks=0:abort_on_error=1"});
  ASSERT_EQ(render.wait(300s).value_or(-1), 0) << render.log();
  std::ifstream jsonl(dir_ / "rt" / "frames" / "frames.jsonl");
  std::vector<nlohmann::json> frames;
  for (std::string line; std::getline(jsonl, line);) frames.push_back(nlohmann::json::parse(line));
  ASSERT_EQ(frames.size(), 8u);
  for (std::size_t i = 0; i < frames.size(); ++i) {
    SCOPED_TRACE("frame " + std::to_string(i));
    const auto& f = frames[i];
    EXPECT_EQ(f["preset"], "realtime");
    EXPECT_EQ(f["interleave"], 4);
    EXPECT_EQ(f["resolution_divisor"], 2);
    EXPECT_EQ(f["resolution"], nlohmann::json::array({160, 90}));
    EXPECT_TRUE(f["gpu_ms"].contains("upscale")) << f["gpu_ms"].dump();
    ASSERT_TRUE(f.contains("temporal"));
    const auto& t = f["temporal"];
    EXPECT_EQ(t["drawn_whole"], i == 0) << t.dump();
    if (i == 0) {
      EXPECT_EQ(t["reason"], "first frame");
      EXPECT_EQ(t["drawn"], 80 * 45);
    } else {
      EXPECT_EQ(t["reason"], "");
      // 1 pixel of 16 drawn (20 x 11 or 12 blocks' worth), the rest mostly reused.
      EXPECT_GE(t["drawn"].get<int>(), 20 * 11);
      EXPECT_LE(t["drawn"].get<int>(), 20 * 12);
      EXPECT_GT(t["reused"].get<int>(), 80 * 45 / 2);
      EXPECT_EQ(t["drawn"].get<int>() + t["reused"].get<int>() + t["offscreen"].get<int>() +
                    t["disoccluded"].get<int>(),
                80 * 45);
      EXPECT_TRUE(f["gpu_ms"].contains("reproject")) << f["gpu_ms"].dump();
    }
  }
}

}  // namespace
}  // namespace sky::test
