// The renderer's ForeFlight input: the attitude derived from XGPS alone
// (heading from the track, pitch from the climb, bank of a coordinated turn),
// XATT taking over while it is fresh; FlightGear's real XGPS capture replayed
// at its capture times through the listener and smoother (what the camera
// shows against the fixes the sender wrote); the antimeridian written as
// 180.000 and -180.000; a long stall held; garbage dropped and counted.
// Times are injected; no socket traffic.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "east_track.hpp"
#include "pcap.hpp"
#include "sky/app/foreflight_listener.hpp"

namespace sky::app {
namespace {

using test::at;

std::span<const std::uint8_t> bytesOf(const std::string& s) {
  return {reinterpret_cast<const std::uint8_t*>(s.data()), s.size()};
}

foreflight::Position fix(double lat, double lon, double alt, double track, double gs) {
  return {"test", lon, lat, alt, track, gs};
}

TEST(ForeFlightTrack, DerivesHeadingPitchAndBankFromTheTrack) {
  ForeFlightTrack track;
  // Level, due east at 60 m/s: heading 90, pitch 0, bank 0.
  auto s = track.take(fix(20, -158, 1000, 90, 60), at(0));
  ASSERT_TRUE(s);
  EXPECT_NEAR(s->pose.yaw_deg, 90, 1e-9);
  EXPECT_NEAR(s->pose.pitch_deg, 0, 1e-9);
  EXPECT_NEAR(s->pose.roll_deg, 0, 1e-9);
  ASSERT_TRUE(s->velocityNed_mps);
  EXPECT_NEAR(s->velocityNed_mps->x, 0, 1e-9);
  EXPECT_NEAR(s->velocityNed_mps->y, 60, 1e-9);
  // Climbing 6 m/s while turning right 3 deg/s: pitch atan(6/60) = 5.71 deg,
  // bank atan(60 * 3 deg/s / g) = 17.77 deg.
  s = track.take(fix(20, -157.999, 1006, 93, 60), at(1));
  ASSERT_TRUE(s);
  EXPECT_NEAR(s->pose.yaw_deg, 93, 1e-9);
  EXPECT_NEAR(s->pose.pitch_deg, std::atan(0.1) * 180 / M_PI, 1e-9);
  EXPECT_NEAR(s->pose.roll_deg, std::atan(60 * 3 * M_PI / 180 / 9.80665) * 180 / M_PI, 1e-9);
  EXPECT_NEAR(s->velocityNed_mps->z, -6, 1e-9);
  // Across north: a left turn from 2 to 358 deg is -4 deg, not +356.
  track.take(fix(20, -157.998, 1006, 2, 60), at(2));
  s = track.take(fix(20.001, -157.998, 1006, 358, 60), at(3));
  EXPECT_LT(s->pose.roll_deg, 0);
  EXPECT_GT(s->pose.roll_deg, -30);
  // Stopped: the track of 0.000 a parked aircraft sends is noise, the heading is held.
  s = track.take(fix(20.001, -157.998, 1006, 0, 0), at(4));
  EXPECT_NEAR(s->pose.yaw_deg, -2, 1e-9);  // 358, as the smoother's (-180, 180]
  EXPECT_EQ(s->pose.roll_deg, 0);
}

TEST(ForeFlightTrack, AFreshAttitudeLineWinsAndAStaleOneDoesNot) {
  ForeFlightTrack track;
  EXPECT_FALSE(track.take(foreflight::Attitude{"X-Plane", 100, 4, -20}, at(0)));
  auto s = track.take(fix(20, -158, 1000, 90, 60), at(0.5));
  EXPECT_NEAR(s->pose.yaw_deg, 100, 1e-9);
  EXPECT_NEAR(s->pose.pitch_deg, 4, 1e-9);
  EXPECT_NEAR(s->pose.roll_deg, -20, 1e-9);
  // 2 s without XATT: derived again.
  s = track.take(fix(20, -157.999, 1000, 90, 60), at(2.5));
  EXPECT_NEAR(s->pose.yaw_deg, 90, 1e-9);
  EXPECT_NEAR(s->pose.roll_deg, 0, 1e-9);
  EXPECT_FALSE(track.take(foreflight::Other{"XTRAFFIC"}, at(3)));
}

struct ListenerFixture : ::testing::Test {
  boost::asio::io_context io;
  ForeFlightListener listener{io, "127.0.0.1", 0};
};

// FlightGear's XGPS output (224 lines over 316 s, 0.3-30 s apart, positions
// to 0.001 deg) replayed at its capture times. Just before each fix arrives
// the camera is where the smoother put it from the earlier ones; the
// distance to the fix is what the pilot sees of the feed's sparseness.
// Most of it is the fixes' own rounding (0.001 deg: up to 55 m north-south
// and 52 m east-west here, so up to 76 m between a fix and the truth);
// the rest is turns and stalls flown on along the last track. Measured:
// median 51 m, p95 110 m, max 173 m. Bounds: median 80 m, max 300 m.
// And the camera never jumps: at 30 frames/s no step exceeds what the
// aircraft flies in a frame (2.2 m at 65 m/s) plus the fading correction
// (a 173 m correction over a 0.5 s time constant: 173 * (1 - e^(-1/15)) =
// 11 m). Measured max step 10.3 m; bound 20 m.
TEST_F(ListenerFixture, FlightGearsCaptureGivesASteadyCameraNearTheFixes) {
  const auto packets = sky::test::readPcap(SKY_TEST_DATA_DIR "/flightgear/fgfs-c172p-foreflight-xgps-hawaii.pcap");
  ASSERT_EQ(packets.size(), 224u);
  std::vector<double> errors;
  std::optional<geo::Geodetic> lastFrame;
  double maxStep = 0;
  double frameTime = 0;
  for (const auto& p : packets) {
    // Frames at 30 Hz up to this packet's arrival.
    for (; frameTime < p.t_s; frameTime += 1.0 / 30.0) {
      const auto pose = listener.poseAt(at(frameTime));
      if (!pose) continue;
      if (lastFrame) maxStep = std::max(maxStep, test::distance_m(*lastFrame, pose->pose.position));
      lastFrame = pose->pose.position;
    }
    const auto m = foreflight::parseDatagram(p.payload);
    ASSERT_TRUE(m);
    const auto& f = std::get<foreflight::Position>(m->front());
    const auto before = listener.poseAt(at(p.t_s));
    if (before && f.groundSpeed_mps > 2)
      errors.push_back(test::distance_m(before->pose.position, {f.lat_deg, f.lon_deg, f.alt_m}));
    listener.handleDatagram(p.payload, at(p.t_s));
  }
  EXPECT_EQ(listener.positionsAccepted(), 224u);
  EXPECT_EQ(listener.datagramsDropped(), 0u);
  ASSERT_GT(errors.size(), 150u);
  std::sort(errors.begin(), errors.end());
  const double median = errors[errors.size() / 2], p95 = errors[errors.size() * 95 / 100], worst = errors.back();
  std::printf("ForeFlight capture: camera to next fix median %.0f m, p95 %.0f m, max %.0f m; max step per frame %.1f m\n",
              median, p95, worst, maxStep);
  EXPECT_LT(median, 80.0);
  EXPECT_LT(worst, 300.0);
  EXPECT_LT(maxStep, 20.0);
}

// Eastbound at 250 m/s across the antimeridian, one fix a second, the
// crossing written as "180.000" and the next fix already west of it: the
// camera moves on smoothly (no step beyond a frame's flight plus slack).
TEST_F(ListenerFixture, TheAntimeridianIsCrossedWithoutAJump) {
  const double lat = -17.5, speed = 250;
  const double degPerSecond = speed / (111320.0 * std::cos(lat * M_PI / 180));
  std::optional<geo::Geodetic> last;
  double maxStep = 0;
  for (int i = 0; i <= 12; ++i) {
    // Fix 6 is on the antimeridian, written as 180.000; the ones after it
    // from -180.
    double lon = 180.0 + (i - 6) * degPerSecond;
    if (lon > 180) lon -= 360;
    char line[128];
    std::snprintf(line, sizeof line, "XGPSsim,%.6f,%.4f,3000.0,90.0,%.1f\n", lon, lat, speed);
    listener.handleDatagram(bytesOf(line), at(i));
    for (int k = 0; k < 30; ++k) {
      const auto pose = listener.poseAt(at(i + k / 30.0));
      ASSERT_TRUE(pose || i == 0);
      if (!pose) continue;
      if (last) maxStep = std::max(maxStep, test::distance_m(*last, pose->pose.position));
      last = pose->pose.position;
    }
  }
  EXPECT_EQ(listener.datagramsDropped(), 0u);
  EXPECT_EQ(listener.outliersDropped(), 0u);
  EXPECT_LT(last->lon_deg, -179.9);
  // 250 m/s at 30 frames/s is 8.3 m a frame; the fixes' rounding (1e-6 deg)
  // adds nothing visible. Bound 12 m.
  EXPECT_LT(maxStep, 12.0) << "a jump at the antimeridian";
}

// A sender that stops (the simulator paused, the network gone): the camera
// flies on along the last velocity for 3 s, then holds; the next fix after
// the stall is blended in.
TEST_F(ListenerFixture, ALongStallIsHeldNotFlownOff) {
  for (int i = 0; i < 3; ++i) {
    char line[128];
    std::snprintf(line, sizeof line, "XGPSsim,-158.%06d,20.6,900,90,50\n", 300000 - i * 480);
    listener.handleDatagram(bytesOf(line), at(i));
  }
  const auto justAfter = listener.poseAt(at(2.0));
  const auto held1 = listener.poseAt(at(5.5));
  const auto held2 = listener.poseAt(at(30.0));
  ASSERT_TRUE(justAfter && held1 && held2);
  EXPECT_NEAR(test::distance_m(justAfter->pose.position, held1->pose.position), 150, 5);  // 3 s at 50 m/s
  EXPECT_LT(test::distance_m(held1->pose.position, held2->pose.position), 1e-6);
}

TEST_F(ListenerFixture, GarbageIsDroppedAndCountedAndThePoseKept) {
  listener.handleDatagram(bytesOf("XGPSsim,-158.3,20.6,900,90,50\n"), at(0));
  listener.handleDatagram(bytesOf("XGPSsim,-158.3,20.6,900,90,50\n"), at(0.5));
  const auto before = listener.poseAt(at(0.5));
  ASSERT_TRUE(before);
  const std::vector<std::string> garbage = {
      "", "XGPSsim,nan,20.6,900,90,50", "XGPSsim,-158.3,95,900,90,50", "XATTsim,10,200,0", "\xff\xfe\xfd",
      "XGPSsim,-158.3,20.6", std::string(5000, 'X'), "XGPSsim,-158.3,20.6,900,90,50\nbroken"};
  for (const auto& g : garbage) listener.handleDatagram(bytesOf(g), at(0.6));
  EXPECT_EQ(listener.datagramsDropped(), garbage.size());
  EXPECT_EQ(listener.positionsAccepted(), 2u);
  const auto after = listener.poseAt(at(0.6));
  ASSERT_TRUE(after);
  EXPECT_LT(test::distance_m(before->pose.position, after->pose.position), 10.0);
  // Traffic lines are counted, not dropped.
  listener.handleDatagram(bytesOf("XTRAFFICX-Plane,1,33.8,-118.3,3200,0,1,68,126,N1"), at(0.7));
  EXPECT_EQ(listener.otherLines(), 1u);
  EXPECT_EQ(listener.datagramsDropped(), garbage.size());
}

}  // namespace
}  // namespace sky::app
