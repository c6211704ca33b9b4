// A recorded flight as a pose source (renderer/app/pose_source.hpp), on a
// real IGC log: the pose at a flight time is the flight's own sample there,
// numbered as the caller's host frame; the time of day is the log's date
// plus the flight time (source flight-file) unless the sun is fixed; a CSV
// without dates has none; poseAt maps a steady clock onto flight time at the
// pace from the start and holds the last fix past the end.
#include <chrono>
#include <fstream>
#include <sstream>

#include <gtest/gtest.h>

#include "sky/app/pose_source.hpp"
#include "sky/flight/flight.hpp"

namespace sky::app {
namespace {

flight::ParsedFlight load(const std::string& name) {
  std::ifstream in(std::string(SKY_TEST_DATA_DIR) + "/" + name, std::ios::binary);
  std::stringstream text;
  text << in.rdbuf();
  auto f = flight::parseFlight(text.str(), name);
  EXPECT_TRUE(f) << describe(f.error());
  return f ? *f : flight::ParsedFlight{};
}

void expectSamePose(const geo::GeodeticPose& a, const geo::GeodeticPose& b) {
  EXPECT_EQ(a.position.lat_deg, b.position.lat_deg);
  EXPECT_EQ(a.position.lon_deg, b.position.lon_deg);
  EXPECT_EQ(a.position.alt_m, b.position.alt_m);
  EXPECT_EQ(a.yaw_deg, b.yaw_deg);
  EXPECT_EQ(a.pitch_deg, b.pitch_deg);
  EXPECT_EQ(a.roll_deg, b.roll_deg);
}

TEST(FlightPoseSource, TheFlightsPoseAndTimeOfDay) {
  const flight::ParsedFlight igc = load("flights/glider-thermalling-ne-italy.igc");
  ASSERT_FALSE(igc.fixes.empty());
  ASSERT_TRUE(igc.startUtc_s);
  const SteadyTime start = std::chrono::steady_clock::now();
  const FlightPoseSource dated(igc, 0.0, start, 2.0, false);
  const double first_s = igc.fixes.front().time_s;
  for (const double t : {0.0, 61.5, igc.duration_s() / 2}) {
    const HostPose p = dated.poseAtFlightTime(t, 7);
    expectSamePose(p.pose, flight::sample(igc, first_s + t));
    EXPECT_EQ(p.hostFrame, 7u);
    EXPECT_EQ(p.hostTime_s, t);
    ASSERT_TRUE(p.utc_s);
    EXPECT_EQ(*p.utc_s, double(*igc.startUtc_s) + t);
    EXPECT_EQ(p.timeSource, TimeSource::FlightFile);
  }
  const FlightPoseSource fixed(igc, 0.0, start, 1.0, true);
  EXPECT_FALSE(fixed.poseAtFlightTime(10, 0).utc_s);
  EXPECT_EQ(fixed.poseAtFlightTime(10, 0).timeSource, TimeSource::Fixed);

  // The steady clock at pace 2 from 30 s into the flight: 10 s later is 50 s in.
  FlightPoseSource paced(igc, 30.0, start, 2.0, false);
  const auto at10 = paced.poseAt(start + std::chrono::seconds(10));
  ASSERT_TRUE(at10);
  expectSamePose(at10->pose, flight::sample(igc, first_s + 50.0));
  EXPECT_EQ(at10->utc_s, double(*igc.startUtc_s) + 50.0);
  const auto late = paced.poseAt(start + std::chrono::hours(100));
  ASSERT_TRUE(late);
  EXPECT_EQ(late->hostTime_s, igc.duration_s()) << "holds the last fix";
  EXPECT_EQ(late->hostFrame, 1u) << "poseAt numbers its frames";
  EXPECT_STREQ(paced.source(), "replay");
}

TEST(FlightPoseSource, ACsvWithoutDatesHasNoTimeOfDay) {
  const flight::ParsedFlight csv = load("short-flight.csv");
  ASSERT_FALSE(csv.fixes.empty());
  const FlightPoseSource source(csv, 0.0, std::chrono::steady_clock::now(), 1.0, false);
  const HostPose p = source.poseAtFlightTime(1.0, 0);
  EXPECT_FALSE(p.utc_s);
  EXPECT_EQ(p.timeSource, TimeSource::Fixed);
  expectSamePose(p.pose, flight::sample(csv, csv.fixes.front().time_s + 1.0));
}

}  // namespace
}  // namespace sky::app
