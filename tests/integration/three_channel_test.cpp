// Three renderer channels of one display from one host, through real
// processes on loopback: skyshell-weatherd streams the cumulus scenario,
// three skyshell-render channels (view ids 0, 1, 2: left, centre, right)
// subscribe, and one skyshell-replay sends every host datagram to all three
// with each channel's View Definition (60 deg wide) and View Control (yaw
// -60, 0, +60). Checks the seams from the frames' own metadata (the rays of
// the pixels either side of a seam) and pixels (their colours), and that
// the three frames of a host frame share the weather clock and version and
// the camera's exposure (metered on the host's boresight, not each view).
// Writes a contact sheet of the three channels side by side, at noon and at
// dawn (the sun set with --sun-azimuth/--sun-elevation).
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <memory>
#include <thread>
#include <sstream>
#include <vector>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>
// This file is its own test program (it runs alone: tests/integration/CMakeLists.txt).
#define STB_IMAGE_IMPLEMENTATION
#include <stb_image.h>
#define STB_IMAGE_WRITE_IMPLEMENTATION
#include <stb_image_write.h>

#include "child_process.hpp"
#include "frame_files.hpp"
#include "weatherd_process.hpp"
#include "sky/geo/geodetic.hpp"

namespace fs = std::filesystem;
using namespace std::chrono_literals;

namespace sky::test {
namespace {

constexpr int kChannels = 3;
constexpr double kChannelWidth_deg = 60;
constexpr int kWidth = 120, kHeight = 68;
constexpr double kRadToDeg = 180.0 / 3.14159265358979323846;

// The colour check across a seam, row by row: the step across it,
// |displayed left - displayed right| (x / (1 + x) per channel, averaged over
// rgb), against the steps between the neighbouring columns beside it inside
// each image (the left image's last two, the right image's first two: the
// scene's own gradient there). The pixels either side of a seam are one
// pixel apart in angle (checked from the metadata), so a seamless display
// steps across it as it does between neighbours. A row "breaks" where the
// step across is more than 2 x the neighbours' (mean of the two) + 0.002
// (the march's per-pixel noise); the bound is on the fraction of rows that
// break, worst over seams and host frames.
// Why rows and not the mean over them: the clouds drift with the weather
// clock the run starts at, and a cloud edge crossing a seam in a few rows
// raised the mean step across one seam to 1.85-2.06 x its neighbours' in
// correct noon runs (under load, with a later start), while a channel 3
// pixels off stepped 2.0 x in another: the means overlap, the rows do not.
// Measured (lavapipe, 120x68, `high`, ASan; the misplaced channels made
// from the frames of two runs by taking the right image from column k
// instead of 0): correct channels break in 1-16 % of rows (four runs under
// load: noon at most 12 %, dawn 16 %); a right channel 1 pixel off in 10-26 %, 3 pixels off in
// 18-57 % (worst over a run's frames 29 % and more), one drawing the left
// channel's view (View Control ignored) in 68-100 %. Bound: 25 %: it catches
// a channel 3 pixels off and a lost View Control; the ray geometry (from
// the metadata) pins the placement to far under a pixel.
constexpr double kSeamStepFactor = 2.0;
constexpr double kSeamStepSlack = 0.002;
constexpr double kMaxBrokenRows = 0.25;

// The displayed value's step between two pixels, mean over rgb.
double step(const float* a, const float* b) {
  double s = 0;
  for (int c = 0; c < 3; ++c) s += std::abs(a[c] / (1.0 + a[c]) - b[c] / (1.0 + b[c]));
  return s / 3;
}

// The ray (ECEF, unit) through image position (u, v) in pixels (0 at the
// top-left corner) of a frame, from its metadata alone: the camera pose's
// body axes and the half-angles, the image plane at unit distance spanning
// tan(left)..tan(right) and tan(top)..tan(bottom) (CIGI View Definition).
geo::Vec3d rayAt(const nlohmann::json& frame, double u, double v) {
  const auto& c = frame["camera"];
  const geo::GeodeticPose pose{{c["lat_deg"], c["lon_deg"], c["alt_m"]}, c["yaw_deg"], c["pitch_deg"], c["roll_deg"]};
  const geo::BodyAxes axes = geo::bodyAxes(pose);
  const auto& h = frame["view"]["half_angles_deg"];
  auto tanOf = [&](const char* k) { return std::tan(h[k].get<double>() / kRadToDeg); };
  const double sx = tanOf("left") + (tanOf("right") - tanOf("left")) * u / kWidth;
  const double sy = tanOf("top") + (tanOf("bottom") - tanOf("top")) * v / kHeight;
  return geo::normalize(axes.forward + axes.right * sx - axes.down * sy);
}

double angle_deg(const geo::Vec3d& a, const geo::Vec3d& b) {
  return std::acos(std::clamp(geo::dot(a, b), -1.0, 1.0)) * kRadToDeg;
}

struct DisplayRun {
  fs::path dir;
  // Per host frame, the three channels' metadata (only host frames every
  // channel drew).
  std::map<std::uint32_t, std::array<nlohmann::json, kChannels>> frames;
  std::string pfm(int channel, const nlohmann::json& f) const {
    return (dir / ("channel" + std::to_string(channel)) / fs::path(f["file"].get<std::string>()).replace_extension(".pfm"))
        .string();
  }
};

// One weather server, three channels, one host flying an 8 s hover (a still
// scene: nose up 15 deg heading east, 600 m under the cumulus base) at 2
// host frames per second: about the rate an ASan channel draws at with
// another test beside it (400-550 ms a frame), so every channel draws most
// host frames. At 5 Hz each drew every second or third one, and the frames
// all three drew were a matter of their phases (3 of 40 in one run).
// The channels shadow the clouds with the light march, not the presets' sun
// map: the seams are the rays' geometry, the same either way (the channels
// share the camera, so their maps share the anchor), and a map build took
// 150-500 ms a frame under ASan.
DisplayRun runDisplay(const std::string& name, double sunAzimuth_deg, double sunElevation_deg) {
  DisplayRun run;
  Weatherd weatherd(name);  // the cumulus scenario; makes SKY_TEST_OUTPUT_DIR/name afresh
  run.dir = weatherd.dir;
  const std::string d = run.dir.string();
  EXPECT_GT(weatherd.streamPort, 0u) << weatherd.process->log();
  if (weatherd.streamPort == 0) return run;
  const unsigned weatherPort = weatherd.streamPort;
  {
    std::ofstream flight(d + "/hover.csv");
    flight << "time_s,lat_deg,lon_deg,alt_m,yaw_deg,pitch_deg,roll_deg\n"
              "0,46.2,12.8,900,90,15,0\n8,46.2,12.8,900,90,15,0\n";  // 16 host frames at 2 Hz
  }
  // Leak checking off in the renderers only: lavapipe's JIT (skeleton_test.cpp).
  std::vector<std::unique_ptr<ChildProcess>> channels;
  std::vector<std::string> igs;
  for (int i = 0; i < kChannels; ++i) {
    const std::string ch = d + "/channel" + std::to_string(i);
    channels.push_back(std::make_unique<ChildProcess>(
        std::vector<std::string>{SKY_RENDER, "--headless", "--server", "127.0.0.1:" + std::to_string(weatherPort),
                                 "--cigi-port", "0", "--port-file", ch + ".port", "--out", ch, "--view-id",
                                 std::to_string(i), "--width", std::to_string(kWidth), "--height",
                                 std::to_string(kHeight), "--write-float", "--no-exr", "--idle-exit", "3",
                                 "--weather-timeout", "60", "--sun-azimuth", std::to_string(sunAzimuth_deg),
                                 "--sun-elevation", std::to_string(sunElevation_deg), "--sun-shadow", "march",
                                 "--channel",
                                 name + "-" + std::to_string(i)},
        ch + ".log", std::vector<std::string>{"ASAN_OPTIONS=detect_leaks=0:abort_on_error=1"}));
  }
  for (int i = 0; i < kChannels; ++i) {
    // A channel writes its port once its pipelines are built: three ASan
    // renderers building theirs on two busy cores took over a minute.
    const unsigned port = waitForPortFile(d + "/channel" + std::to_string(i) + ".port", 180s);
    EXPECT_GT(port, 0u) << channels[i]->log();
    if (port == 0) return run;
    igs.push_back("127.0.0.1:" + std::to_string(port));
  }
  // Let the channels take their first weather before the host starts, so
  // they all draw from its first frame on.
  std::this_thread::sleep_for(2s);
  std::vector<std::string> replayArgs = {SKY_REPLAY, d + "/hover.csv", "--rate", "2", "--conditions-rate", "0",
                                         "--channels", std::to_string(kChannels), "--channel-width-deg",
                                         std::to_string(kChannelWidth_deg), "--channel-aspect",
                                         std::to_string(double(kWidth) / kHeight)};
  for (const auto& ig : igs) replayArgs.insert(replayArgs.end(), {"--ig", ig});
  ChildProcess replay(replayArgs, d + "/replay.log");
  EXPECT_EQ(replay.wait(60s), std::optional<int>(0)) << replay.log();
  for (auto& c : channels) EXPECT_EQ(c->wait(180s), std::optional<int>(0)) << c->log();
  EXPECT_EQ(weatherd.process->stop(), 0) << weatherd.process->log();

  std::map<std::uint32_t, std::array<nlohmann::json, kChannels>> all;
  std::map<std::uint32_t, int> seen;
  for (int i = 0; i < kChannels; ++i) {
    std::istringstream lines(readText(d + "/channel" + std::to_string(i) + "/frames.jsonl"));
    for (std::string line; std::getline(lines, line);) {
      if (line.empty()) continue;
      auto f = nlohmann::json::parse(line);
      const auto host = f["host_frame"].get<std::uint32_t>();
      all[host][i] = f;
      ++seen[host];
    }
  }
  for (auto& [host, trio] : all)
    if (seen[host] == kChannels) run.frames[host] = trio;
  return run;
}

// Writes the three channels' PNGs of one host frame side by side.
void writeContactSheet(const DisplayRun& run, const std::array<nlohmann::json, kChannels>& trio,
                       const std::string& path) {
  std::vector<unsigned char> sheet(std::size_t(kWidth) * kChannels * kHeight * 3, 0);
  for (int i = 0; i < kChannels; ++i) {
    const std::string png = (run.dir / ("channel" + std::to_string(i)) / trio[i]["file"].get<std::string>()).string();
    int w = 0, h = 0, n = 0;
    unsigned char* pixels = stbi_load(png.c_str(), &w, &h, &n, 3);
    ASSERT_NE(pixels, nullptr) << png;
    ASSERT_EQ(w, kWidth);
    ASSERT_EQ(h, kHeight);
    for (int y = 0; y < h; ++y)
      std::copy_n(pixels + std::size_t(y) * w * 3, std::size_t(w) * 3,
                  sheet.begin() + std::ptrdiff_t((std::size_t(y) * kWidth * kChannels + std::size_t(i) * kWidth) * 3));
    stbi_image_free(pixels);
  }
  ASSERT_NE(stbi_write_png(path.c_str(), kWidth * kChannels, kHeight, 3, sheet.data(), kWidth * kChannels * 3), 0)
      << path;
  std::printf("[ sheet    ] %s\n", path.c_str());
}

void checkDisplay(const std::string& name, double sunAzimuth_deg, double sunElevation_deg) {
  const DisplayRun run = runDisplay(name, sunAzimuth_deg, sunElevation_deg);
  ASSERT_GE(run.frames.size(), 4u) << "too few host frames drawn by all three channels in " << run.dir;

  // The angular width of one pixel at the image centre, where pixels are
  // widest in angle (tangent spacing): the bound for rays "a pixel apart".
  const double pixel_deg = std::atan(2 * std::tan(kChannelWidth_deg / 2 / kRadToDeg) / kWidth) * kRadToDeg;
  double worstEdge_deg = 0, worstCentres_deg = 0, worstRatio = 0, worstBroken = 0;
  std::size_t checked = 0;
  std::size_t startUp = 0;
  double arrivalSpread_s = 0, lockedOff_s = 0;  // the host clock lock's inputs and result
  // The server's clock at arrival minus the host's time, over the frames:
  // how much later than its own time line the host's datagrams arrived (a
  // loaded machine delays the host process), which the lock cannot see.
  double lagMin_s = 1e300, lagMax_s = -1e300;
  double evSpread = 0;  // the largest EV100 difference between the channels of a settled host frame
  double evOwnViews = 0;  // how far apart the channels' own views meter (their frames' mean log luminance)
  for (const auto& [host, trio] : run.frames) {
    SCOPED_TRACE("host frame " + std::to_string(host));
    bool settled = true;
    for (int i = 0; i < kChannels; ++i) {
      EXPECT_EQ(trio[i]["view"]["id"], i);
      EXPECT_TRUE(trio[i]["view"]["frustum_from_host"].get<bool>());
      EXPECT_NEAR(trio[i]["view"]["rotation_deg"]["yaw"].get<double>(), (i - 1) * kChannelWidth_deg, 1e-4);
      EXPECT_NEAR(trio[i]["fov_deg"]["horizontal"].get<double>(), kChannelWidth_deg, 1e-4);
      EXPECT_EQ(trio[i]["noise_seeds"], trio[0]["noise_seeds"]);
      EXPECT_EQ(trio[i]["host_time_s"], trio[0]["host_time_s"]);
      settled = settled && trio[i]["weather_areas"].size() == 2;
      // Until the server's offset for the host has come, a channel draws
      // with its own estimate, which may snap a grid step from the others'.
      settled = settled && trio[i]["weather_clock_lock"] == "server";
      // The server's clock at each channel's arrival of the frame: their
      // spread is what the lock's grid must absorb (host_locked_clock.hpp).
      const double server_s = trio[i]["weather_clock_server_s"].get<double>();
      arrivalSpread_s = std::max(arrivalSpread_s, std::abs(server_s - trio[0]["weather_clock_server_s"].get<double>()));
      lockedOff_s = std::max(lockedOff_s, std::abs(trio[i]["weather_clock_s"].get<double>() - server_s));
      lagMin_s = std::min(lagMin_s, server_s - trio[i]["host_time_s"].get<double>());
      lagMax_s = std::max(lagMax_s, server_s - trio[i]["host_time_s"].get<double>());
    }
    // A channel subscribes at its first pose and draws once the detailed
    // area has come; the coarse area comes a moment later, so a channel may
    // draw its first frame a version behind the others; and it proposes its
    // clock offset at its first host frame and has the server's a round
    // trip later. Frames from when every channel holds both areas and the
    // server's offset on must agree on the version and clock and are the
    // ones compared below.
    if (!settled) {
      ++startUp;
      continue;
    }
    for (int i = 0; i < kChannels; ++i) {
      // One shared picture: the same clock (host_locked_clock.hpp), bit for bit.
      EXPECT_EQ(trio[i]["weather_clock_s"], trio[0]["weather_clock_s"]);
      EXPECT_EQ(trio[i]["weather_version"], trio[0]["weather_version"]);
      EXPECT_EQ(trio[i]["camera_exposure"]["mode"], "auto");
      evSpread = std::max(evSpread, std::abs(trio[i]["camera_exposure"]["ev100"].get<double>() -
                                             trio[0]["camera_exposure"]["ev100"].get<double>()));
      // A channel's own picture as a meter would read it (mean luminance:
      // the log mean is not in the metadata), in EV against the centre's.
      evOwnViews = std::max(evOwnViews, std::abs(std::log2(trio[i]["mean_luminance"].get<double>() /
                                                           trio[1]["mean_luminance"].get<double>())));
    }
    for (int i = 0; i + 1 < kChannels; ++i) {
      const auto &left = trio[i], &right = trio[i + 1];
      // Geometry from the metadata: the left channel's right edge is the
      // right channel's left edge (top, middle, bottom of the seam), and the
      // pixel centres either side are less than a centre pixel apart.
      for (double v : {0.0, kHeight / 2.0, double(kHeight)})
        worstEdge_deg = std::max(worstEdge_deg, angle_deg(rayAt(left, kWidth, v), rayAt(right, 0, v)));
      for (int y = 0; y < kHeight; ++y)
        worstCentres_deg =
            std::max(worstCentres_deg, angle_deg(rayAt(left, kWidth - 0.5, y + 0.5), rayAt(right, 0.5, y + 0.5)));
      // Colours either side of the seam.
      const Pfm a = readPfm(run.pfm(i, left)), b = readPfm(run.pfm(i + 1, right));
      double seam = 0, near = 0;
      int broken = 0;
      for (int y = 0; y < kHeight; ++y) {
        const double across = step(a.at(kWidth - 1, y), b.at(0, y));
        const double beside = 0.5 * (step(a.at(kWidth - 2, y), a.at(kWidth - 1, y)) + step(b.at(0, y), b.at(1, y)));
        if (across > kSeamStepFactor * beside + kSeamStepSlack) ++broken;
        seam += across;
        near += beside;
      }
      seam /= kHeight;
      near /= kHeight;
      worstRatio = std::max(worstRatio, seam / std::max(near, 1e-9));
      worstBroken = std::max(worstBroken, double(broken) / kHeight);
      if (host == run.frames.rbegin()->first)
        std::printf("[ seams    ] %s seam %d|%d: colour step across %.4f, between neighbours beside it %.4f\n",
                    name.c_str(), i, i + 1, seam, near);
    }
    ++checked;
  }
  EXPECT_GE(checked, 3u) << startUp << " host frames of start-up";
  // Channels that drew the same host frames compute the same exposure bit
  // for bit (exposure_test.cpp); a channel that missed a different host frame
  // metered a pose a frame apart, and the start-up's differences decay with
  // the adaptation (tau 0.5 s): 0.05 EV is a twentieth of a stop.
  std::printf("[ exposure ] %s: the channels' EV100 at most %.2e apart; their own views' mean luminances %.2f EV apart\n",
              name.c_str(), evSpread, evOwnViews);
  EXPECT_LE(evSpread, 0.05);
  const double lagSwing_s = lagMax_s - lagMin_s;
  std::printf("[ clock    ] %s: the server's clock at the channels' arrivals of a host frame %.2f ms apart at most; "
              "the host's datagrams late by a varying %.3f s; the locked clock within %.3f s of it\n",
              name.c_str(), 1e3 * arrivalSpread_s, lagSwing_s, lockedOff_s);
  // Half kHostClockGrid_s (1 s), plus the arrival spread, plus how much the
  // host's lateness varied (the lock follows the host's time, the server's
  // clock the wall's).
  EXPECT_LE(lockedOff_s, 0.5 * 1.0 + 0.05 + lagSwing_s);
  std::printf("[ seams    ] %s: %zu host frames (and %zu of start-up); edge rays %.2e deg apart, centre rays at most %.4f deg apart "
              "(a centre pixel: %.4f deg); colour step across a seam at most %.2f x its neighbours' (mean over rows), "
              "rows breaking at a seam at most %.0f %%\n",
              name.c_str(), checked, startUp, worstEdge_deg, worstCentres_deg, pixel_deg, worstRatio, 100 * worstBroken);
  // Half-angles travel as CIGI floats and the pose through double geodesy:
  // the edges agree to float's 1e-7 relative (6e-6 deg); 1e-4 deg is 0.0002 px.
  EXPECT_LT(worstEdge_deg, 1e-4);
  EXPECT_LT(worstCentres_deg, pixel_deg);
  EXPECT_LE(worstBroken, kMaxBrokenRows) << "rows where a seam steps more than " << kSeamStepFactor
                                         << " x its neighbours + " << kSeamStepSlack;
  writeContactSheet(run, run.frames.rbegin()->second, (run.dir / (name + "-contact-sheet.png")).string());
}

TEST(ThreeChannels, NoonSeamsAreSeamless) { checkDisplay("three_channel_noon", 180.0, 60.0); }

// Dawn: the sun low in the east, ahead of the centre channel, so the seams
// cross the bright forward-scattering lobe.
TEST(ThreeChannels, DawnSeamsAreSeamless) { checkDisplay("three_channel_dawn", 80.0, 4.0); }

}  // namespace
}  // namespace sky::test
