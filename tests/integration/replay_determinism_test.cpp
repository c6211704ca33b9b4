// skyshell-render --replay from a weather file is byte-identical run to run
// without --weather-clock: the first frame's weather clock is the file's own
// (its [clock] start_s), not the file's clock advanced by however long the
// renderer took between reading the file and drawing the first frame (which
// made 2 of 31 frames differ between two runs of the same command at
// --preset medium). Tiny frames, two runs, every PNG compared byte for byte.
// Also the replay's cleaning flags and skyshell-replay --info, on a track
// with a spoofed fix, and the recorded-flight readers (issue 25: readsb
// traces, X-Plane FDR) end to end, with what report.json says of the file.
#include <filesystem>
#include <fstream>
#include <sstream>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "child_process.hpp"

namespace fs = std::filesystem;
using namespace std::chrono_literals;

namespace sky::test {
namespace {

std::string readAll(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

fs::path outputDir() {
  const fs::path dir = fs::path(SKY_TEST_OUTPUT_DIR) /
                       ("determinism-" + std::string(::testing::UnitTest::GetInstance()->current_test_info()->name()));
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir;
}

int run(std::vector<std::string> argv, const fs::path& log, std::string* text = nullptr) {
  // Leak checking off for the renderer (lavapipe's JIT), as in the other replay tests.
  ChildProcess child(std::move(argv), log.string(), {"ASAN_OPTIONS=detect_leaks=0:abort_on_error=1"});
  const auto code = child.wait(300s);
  if (text) *text = child.log();
  return code.value_or(-1);
}

// The 6 s test flight at 0.2 s a frame: 31 frames, as in the report of the
// bug, at 64x36 so that the two runs take seconds.
std::vector<std::string> replayArgs(const fs::path& out) {
  return {SKY_RENDER, "--headless", "--replay", SKY_TEST_FLIGHT, "--weather-file", SKY_SCENARIO_CLOUDY,
          "--preset", "medium", "--step", "0.2", "--width", "64", "--height", "36", "--no-video",
          "--out", out.string()};
}

TEST(ReplayDeterminism, TwoRunsFromAWeatherFileGiveTheSameBytes) {
  const fs::path dir = outputDir();
  std::string logA, logB;
  ASSERT_EQ(run(replayArgs(dir / "a"), dir / "a.log", &logA), 0) << logA;
  ASSERT_EQ(run(replayArgs(dir / "b"), dir / "b.log", &logB), 0) << logB;
  std::size_t compared = 0, differing = 0;
  for (const auto& entry : fs::directory_iterator(dir / "a" / "frames")) {
    if (entry.path().extension() != ".png") continue;
    ++compared;
    if (readAll(entry.path()) != readAll(dir / "b" / "frames" / entry.path().filename())) {
      ++differing;
      ADD_FAILURE() << entry.path().filename() << " differs between the two runs";
    }
  }
  EXPECT_EQ(compared, 31u);
  EXPECT_EQ(differing, 0u);
  const auto report = nlohmann::json::parse(readAll(dir / "a" / "report.json"));
  // skeleton-cumulus.toml: [clock] start_s = 0.0, rate 1; frames 0.2 s apart.
  // This is what catches the bug every time: with the old clock the first
  // frame was at 0.00036 s and the bytes differed in 2 of 31 frames in one
  // pair of runs, in none in another.
  EXPECT_EQ(report["weather_clock_s"][0], 0.0);
  EXPECT_NEAR(report["weather_clock_s"][1].get<double>(), 6.0, 1e-9);
  EXPECT_EQ(report["weather_clock_from"], "the weather file's clock");
  EXPECT_FALSE(report.contains("weather_clock_pin"));
  EXPECT_EQ(report["cleaning"]["enabled"], true);
  EXPECT_EQ(report["cleaning"]["fixes_in"], 7);
  EXPECT_EQ(report["cleaning"]["fixes_kept"], 7);
}

// The test flight with its fix at t = 3 s (line 8) moved 3 degrees of
// latitude (333 km) north: a spoofed fix.
fs::path spoofedFlight(const fs::path& dir) {
  std::istringstream in(readAll(SKY_TEST_FLIGHT));
  std::ostringstream out;
  std::string line;
  for (std::size_t n = 1; std::getline(in, line); ++n) {
    if (line.rfind("3,46.2000,", 0) == 0) {
      EXPECT_EQ(n, 8u);
      line.replace(2, 7, "49.2000");
    }
    out << line << '\n';
  }
  const fs::path path = dir / "spoofed.csv";
  std::ofstream(path) << out.str();
  return path;
}

// The metadata of a replay's second frame (t = 3 s at --step 3).
nlohmann::json secondFrame(const fs::path& out) {
  std::ifstream jsonl(out / "frames" / "frames.jsonl");
  std::string line;
  std::getline(jsonl, line);
  std::getline(jsonl, line);
  return nlohmann::json::parse(line, nullptr, false);
}

TEST(ReplayDeterminism, TheCleaningDropsASpoofedFixAndSaysSo) {
  const fs::path dir = outputDir();
  const fs::path flight = spoofedFlight(dir);
  std::vector<std::string> args = {SKY_RENDER, "--headless", "--replay", flight.string(), "--weather-file",
                                   SKY_SCENARIO_CLOUDY, "--step", "3", "--width", "64", "--height", "36",
                                   "--no-video", "--out", (dir / "clean").string()};
  std::string log;
  ASSERT_EQ(run(args, dir / "clean.log", &log), 0) << log;
  EXPECT_NE(log.find("cleaning: 1 fix at line 8 (t 3.0 s) dropped"), std::string::npos) << log;
  const auto report = nlohmann::json::parse(readAll(dir / "clean" / "report.json"));
  ASSERT_EQ(report["cleaning"]["dropped"].size(), 1u) << report["cleaning"].dump();
  EXPECT_EQ(report["cleaning"]["dropped"][0]["reason"], "speed");
  EXPECT_EQ(report["cleaning"]["dropped"][0]["lines"][0], 8);
  EXPECT_EQ(report["cleaning"]["fixes_kept"], 6);
  // Interpolated past it, along the chord between t = 2 and 4 s re-projected: 0.2 mm off the parallel.
  EXPECT_NEAR(secondFrame(dir / "clean")["lat_deg"].get<double>(), 46.2, 1e-6);
  // --no-clean flies to the spoofed fix: the frame at t = 3 s is 3 deg north.
  args[args.size() - 1] = (dir / "raw").string();
  args.push_back("--no-clean");
  ASSERT_EQ(run(args, dir / "raw.log", &log), 0) << log;
  EXPECT_EQ(nlohmann::json::parse(readAll(dir / "raw" / "report.json"))["cleaning"]["enabled"], false);
  EXPECT_NEAR(secondFrame(dir / "raw")["lat_deg"].get<double>(), 49.2, 1e-9);
}

TEST(ReplayInfo, SaysWhatTheFileHoldsWithoutReplaying) {
  const fs::path dir = outputDir();
  const fs::path flight = spoofedFlight(dir);
  std::string out;
  ASSERT_EQ(run({SKY_REPLAY, "--info", flight.string()}, dir / "info.log", &out), 0) << out;
  EXPECT_NE(out.find("format: Skyshell CSV"), std::string::npos) << out;
  EXPECT_NE(out.find("time: 0.0 s to 6.0 s of the record (0h00m06s)"), std::string::npos) << out;
  EXPECT_NE(out.find("fixes: 6"), std::string::npos) << out;
  EXPECT_NE(out.find("cleaning: kept 6 of 7 fixes; 1 dropped (speed)"), std::string::npos) << out;
  EXPECT_NE(out.find("1 fix at line 8"), std::string::npos) << out;
  // The box of the kept fixes: 46.2 N, 12.8000 to 12.8042 E (0.0007 deg/s for 6 s).
  EXPECT_NE(out.find("bounding box: lat 46.20000 to 46.20000 deg, lon 12.80000 to 12.80420 deg"), std::string::npos)
      << out;
  ASSERT_EQ(run({SKY_REPLAY, "--info", "--no-clean", flight.string()}, dir / "raw.log", &out), 0) << out;
  EXPECT_NE(out.find("fixes: 7"), std::string::npos) << out;
  EXPECT_NE(out.find("lat 46.20000 to 49.20000 deg"), std::string::npos) << out;
}

// A KML with two tracks: --track picks the one --info describes; without it
// the error names both.
TEST(ReplayInfo, ATrackOfAKmlIsChosenByName) {
  const fs::path dir = outputDir();
  const fs::path kml = dir / "two.kml";
  auto track = [](const char* name, double lat) {
    std::string t = std::string("<Placemark><name>") + name + "</name><gx:Track>";
    for (int i = 0; i < 3; ++i) t += "<when>2024-03-10T14:00:0" + std::to_string(2 * i) + "Z</when>";
    for (int i = 0; i < 3; ++i) t += "<gx:coord>12.8 " + std::to_string(lat + 0.001 * i) + " 900</gx:coord>";
    return t + "</gx:Track></Placemark>";
  };
  std::ofstream(kml) << "<kml xmlns=\"http://www.opengis.net/kml/2.2\" xmlns:gx=\"http://www.google.com/kml/ext/2.2\">"
                        "<Document><altitudeMode>absolute</altitudeMode>"
                     << track("ONE", 46.0) << track("TWO", 47.0) << "</Document></kml>\n";
  std::string out;
  EXPECT_NE(run({SKY_REPLAY, "--info", kml.string()}, dir / "both.log", &out), 0) << out;
  EXPECT_NE(out.find("ONE"), std::string::npos) << out;
  EXPECT_NE(out.find("TWO"), std::string::npos) << out;
  ASSERT_EQ(run({SKY_REPLAY, "--info", "--track", "TWO", kml.string()}, dir / "two.log", &out), 0) << out;
  EXPECT_NE(out.find("lat 47.00000 to 47.00200 deg"), std::string::npos) << out;
}

// The recorded-flight formats end to end (issue 25): a file replayed
// headless at 64x36 from the bundled scenario file, a few frames, and what
// report.json says of it (format, where the altitude came from, the
// cleaning) and of its frames. The samples are the readers' unit-test files,
// hand-made in the formats' published layouts (tests/data/readsb/README.md,
// tests/data/fdr/README.md), not recordings.
struct Recorded {
  const char* file;      // under tests/data
  const char* step_s;    // --step
  const char* format;    // report.json's flight_format
  const char* altitude;  // its altitude_source
  int fixes;             // the fixes the reader keeps, all kept by the cleaning
  int frames;
  double lat_deg, lon_deg, alt_m;  // the first kept fix: the first frame's camera
};

// Replays `r` headless and checks report.json and the first frame; returns
// the frames' metadata (frames.jsonl), empty when the replay failed.
std::vector<nlohmann::json> expectReplayedAndReported(const Recorded& r, const fs::path& out) {
  const std::vector<std::string> args = {SKY_RENDER, "--headless", "--replay", std::string(SKY_TEST_DATA_DIR "/") + r.file,
                                         "--weather-file", SKY_SCENARIO_CLOUDY, "--step", r.step_s, "--width", "64",
                                         "--height", "36", "--no-video", "--out", out.string()};
  std::string log;
  const int code = run(args, out.string() + ".log", &log);
  EXPECT_EQ(code, 0) << log;
  if (code != 0) return {};
  const auto report = nlohmann::json::parse(readAll(out / "report.json"));
  EXPECT_EQ(report["flight_format"], r.format);
  EXPECT_EQ(report["altitude_source"], r.altitude);
  EXPECT_EQ(report["frames"], r.frames);
  EXPECT_EQ(report["complete"], true);
  EXPECT_EQ(report["non_finite_pixels"], 0);
  const auto& cleaning = report["cleaning"];
  EXPECT_EQ(cleaning["enabled"], true) << cleaning.dump();
  EXPECT_EQ(cleaning["fixes_in"], r.fixes) << cleaning.dump();
  EXPECT_EQ(cleaning["fixes_kept"], r.fixes) << cleaning.dump();
  EXPECT_TRUE(cleaning["summary"].is_array() && !cleaning["summary"].empty() &&
              cleaning["summary"][0].get<std::string>().rfind("kept " + std::to_string(r.fixes) + " of ", 0) == 0)
      << cleaning.dump();
  std::vector<nlohmann::json> frames;
  std::ifstream jsonl(out / "frames" / "frames.jsonl");
  for (std::string line; std::getline(jsonl, line);)
    if (!line.empty()) frames.push_back(nlohmann::json::parse(line));
  EXPECT_EQ(frames.size(), std::size_t(r.frames));
  if (frames.empty()) return frames;
  EXPECT_NEAR(frames[0]["lat_deg"].get<double>(), r.lat_deg, 1e-9);
  EXPECT_NEAR(frames[0]["lon_deg"].get<double>(), r.lon_deg, 1e-9);
  EXPECT_NEAR(frames[0]["alt_m"].get<double>(), r.alt_m, 1e-6);
  return frames;
}

constexpr double kFt_m = 0.3048;

// trace_full_3c6444.json: the reader keeps 4 of its 9 rows, 0.5 to 40.5 s
// after the trace's whole second (readsb_test.cpp works them out), three
// with alt_geom and one barometric; at --step 10, frames at 0, 10, ..., 40
// s. The first kept, row 1: 50.001 N 8.49 E, alt_geom 1100 ft.
TEST(ReplayRecorded, AReadsbTraceReplaysHeadlessAndIsReported) {
  expectReplayedAndReported({"readsb/trace_full_3c6444.json", "10", "readsb trace JSON",
                             "geometric ('alt_geom', ft) for 3 fixes; barometric ('alt_baro', ft) to geometric by the "
                             "ICAO standard atmosphere for 1 fix",
                             4, 5, 50.001, 8.49, 1100 * kFt_m},
                            outputDir() / "readsb");
}

// xplane-v4.fdr: four rows kept (the repeated time skipped by the reader),
// 0.5 to 3.5 s after 23:59:58 UTC, altitude ft MSL, pitch and roll from the
// file; at --step 1, frames at 0, 1, 2, 3 s. The first row: 37.5 N 122 W,
// 1000 ft, pitch 2.0 and roll -1.5, which the frame takes as the file gives
// them.
TEST(ReplayRecorded, AnXPlaneFdrFileReplaysHeadlessAndIsReported) {
  const auto frames = expectReplayedAndReported(
      {"fdr/xplane-v4.fdr", "1", "X-Plane FDR",
       "MSL (the FDR altitude column, ft) for 4 fixes; pitch and roll from the file, heading from the track", 4, 4,
       37.5, -122.0, 1000 * kFt_m},
      outputDir() / "fdr");
  ASSERT_FALSE(frames.empty());
  EXPECT_NEAR(frames[0]["pitch_deg"].get<double>(), 2.0, 1e-9);
  EXPECT_NEAR(frames[0]["roll_deg"].get<double>(), -1.5, 1e-9);
}

}  // namespace
}  // namespace sky::test
