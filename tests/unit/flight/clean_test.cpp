// Cleaning of dirty tracks (clean.hpp): a GPS-spoofed fix and a spoofed
// stretch, a smaller jump the speed bound lets pass, repeated and backwards
// timestamps, long gaps held, ended or interpolated. Tracks are straight
// lines in a local tangent plane, so what must be kept and dropped, and the
// distances the report gives, follow from the construction.
#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "sky/flight/clean.hpp"
#include "sky/flight/flight.hpp"

namespace sky::flight {
namespace {

const geo::Geodetic kOrigin{46.0, 12.0, 10000.0};

// A fix at east/north metres from kOrigin in its tangent plane, at kOrigin's altitude.
Fix fixAt(double t_s, double east_m, double north_m) {
  const geo::EnuFrame enu = geo::enuFrameAt(kOrigin);
  geo::Geodetic g = geo::fromEcef(enu.originEcef_m + enu.east * east_m + enu.north * north_m);
  g.alt_m = kOrigin.alt_m;
  return Fix{t_s, {g, 0, 0, 0}};
}

// Flying east at speed, one fix per step from t = 0 to last_s, fix i read
// from line 100 + i.
ParsedFlight eastbound(double speed_mps, double step_s, double last_s) {
  ParsedFlight f;
  for (double t = 0; t <= last_s + 1e-9; t += step_s) {
    f.fixes.push_back(fixAt(t, speed_mps * t, 0));
    f.fixLines.push_back(100 + f.fixLines.size());
  }
  return f;
}

double distanceBetween_m(const geo::Geodetic& a, const geo::Geodetic& b) {
  return geo::length(geo::toEcef(a) - geo::toEcef(b));
}

TEST(Clean, ASpoofedFixIsDroppedWithItsLine) {
  ParsedFlight f = eastbound(100, 1, 20);
  f.fixes[10] = fixAt(10, 1000, 300'000);  // 300 km north of the track, as a spoofer puts it
  const auto r = clean(f, {}, "spoof.csv");
  ASSERT_TRUE(r) << r.error().detail;
  EXPECT_EQ(r->input, 21u);
  EXPECT_EQ(r->kept, 20u);
  ASSERT_EQ(r->dropped.size(), 1u);
  const DroppedStretch& d = r->dropped[0];
  EXPECT_EQ(d.reason, DropReason::Speed);
  EXPECT_EQ(d.count, 1u);
  EXPECT_EQ(d.firstLine, 110u);
  EXPECT_EQ(d.first_s, 10);
  // 300 km in the tangent plane is 299.8 km on the sphere (atan(300/6371) x
  // 6371 km at 10 km up); 1 s from each kept neighbour: ~300 000 m/s.
  EXPECT_NEAR(d.offTrack_m, 300'000, 1000);
  EXPECT_NEAR(d.impliedSpeed_mps, 300'000, 1000);
  ASSERT_EQ(f.fixes.size(), 20u);
  ASSERT_EQ(f.fixLines.size(), 20u);
  EXPECT_EQ(f.fixes[10].time_s, 11);
  EXPECT_EQ(f.fixLines[10], 111u);
  const auto text = r->lines({});
  ASSERT_GE(text.size(), 2u);
  EXPECT_NE(text[0].find("kept 20 of 21"), std::string::npos) << text[0];
  EXPECT_NE(text[1].find("1 fix at line 110"), std::string::npos) << text[1];
}

TEST(Clean, ASpoofedStretchIsDroppedAndTheTrackEitherSideKept) {
  // 60 fixes at 200 m/s; for t = 20..29 a spoofer reports a slow drift 400 km
  // away: ten fixes consistent with each other, not with the track.
  ParsedFlight f = eastbound(200, 1, 59);
  for (int t = 20; t <= 29; ++t) f.fixes[static_cast<std::size_t>(t)] = fixAt(t, 5.0 * t, 400'000);
  const auto r = clean(f, {}, "spoof.csv");
  ASSERT_TRUE(r) << r.error().detail;
  EXPECT_EQ(r->kept, 50u);
  ASSERT_EQ(r->dropped.size(), 1u);
  EXPECT_EQ(r->dropped[0].reason, DropReason::Speed);
  EXPECT_EQ(r->dropped[0].count, 10u);
  EXPECT_EQ(r->dropped[0].firstLine, 120u);
  EXPECT_EQ(r->dropped[0].lastLine, 129u);
  EXPECT_EQ(r->dropped[0].first_s, 20);
  EXPECT_EQ(r->dropped[0].last_s, 29);
  EXPECT_EQ(f.fixes[19].time_s, 19);
  EXPECT_EQ(f.fixes[20].time_s, 30);
  // The kept fix at t = 30 is where the straight track puts it.
  EXPECT_NEAR(distanceBetween_m(f.fixes[20].pose.position, fixAt(30, 6000, 0).pose.position), 0, 1e-6);
}

TEST(Clean, AStretchSpoofedFromTheFirstFixIsDroppedToo) {
  ParsedFlight f = eastbound(200, 1, 30);
  for (int t = 0; t <= 4; ++t) f.fixes[static_cast<std::size_t>(t)] = fixAt(t, 0, -250'000);
  const auto r = clean(f, {}, "spoof.csv");
  ASSERT_TRUE(r);
  EXPECT_EQ(r->kept, 26u);
  EXPECT_EQ(r->droppedFor(DropReason::Speed), 5u);
  EXPECT_EQ(f.fixes.front().time_s, 5);
}

TEST(Clean, AJumpTheSpeedBoundLetsPassIsDroppedAgainstBothNeighbours) {
  // Fixes 10 s apart at 100 m/s; one is 3 km north: 3.16 km from each
  // neighbour (296 m/s after the 200 m slack, under 350), but 3 km off their
  // line where the bound is 1 km + 20 m/s^2 x 10 s x 10 s / 2 = 2 km.
  ParsedFlight f = eastbound(100, 10, 200);
  f.fixes[5] = fixAt(50, 5000, 3000);
  const auto r = clean(f, {}, "jump.csv");
  ASSERT_TRUE(r);
  ASSERT_EQ(r->dropped.size(), 1u);
  EXPECT_EQ(r->dropped[0].reason, DropReason::Jump);
  EXPECT_EQ(r->dropped[0].firstLine, 105u);
  EXPECT_NEAR(r->dropped[0].offTrack_m, 3000, 5);
  // 1.9 km off (under the 2 km bound) is a sharp turn, and kept.
  ParsedFlight g = eastbound(100, 10, 200);
  g.fixes[5] = fixAt(50, 5000, 1900);
  ASSERT_TRUE(clean(g, {}, "turn.csv"));
  EXPECT_EQ(g.fixes.size(), 21u);
}

TEST(Clean, RepeatedAndBackwardTimestampsAreSortedAndDropped) {
  ParsedFlight f;
  // Lines 1-9: t = 0 1 2 2(repeat) 4 3(backwards) 5 5(another position) 6.
  const double times[] = {0, 1, 2, 2, 4, 3, 5, 5, 6};
  const double east[] = {0, 100, 200, 200, 400, 300, 500, 550, 600};
  for (std::size_t i = 0; i < 9; ++i) {
    f.fixes.push_back(fixAt(times[i], east[i], 0));
    f.fixLines.push_back(i + 1);
  }
  const auto r = clean(f, {}, "order.csv");
  ASSERT_TRUE(r);
  EXPECT_EQ(r->reordered, 1u);  // the 3 after the 4
  EXPECT_EQ(r->droppedFor(DropReason::Repeat), 1u);
  EXPECT_EQ(r->droppedFor(DropReason::SameTime), 1u);
  ASSERT_EQ(r->dropped.size(), 2u);
  EXPECT_EQ(r->dropped[0].firstLine, 4u);
  EXPECT_EQ(r->dropped[1].firstLine, 8u);
  ASSERT_EQ(f.fixes.size(), 7u);
  for (std::size_t i = 0; i < 7; ++i) {
    EXPECT_EQ(f.fixes[i].time_s, static_cast<double>(i));
    EXPECT_NEAR(distanceBetween_m(f.fixes[i].pose.position, fixAt(i, 100.0 * i, 0).pose.position), 0, 1e-6);
  }
  EXPECT_EQ(f.fixLines[3], 6u);  // t = 3 came from line 6
}

// 100 m/s east, t = 0..10, a gap, then t = gapEnd..gapEnd+10 on the same line.
ParsedFlight withGap(double gapEnd_s) {
  ParsedFlight f;
  for (int t = 0; t <= 10; ++t) f.fixes.push_back(fixAt(t, 100.0 * t, 0));
  for (int t = 0; t <= 10; ++t) f.fixes.push_back(fixAt(gapEnd_s + t, 100.0 * (gapEnd_s + t), 0));
  return f;
}

TEST(Clean, ALongGapIsHeldAtItsStart) {
  ParsedFlight f = withGap(400);
  const auto r = clean(f, {}, "gap.csv");
  ASSERT_TRUE(r);
  EXPECT_EQ(r->kept, 22u);
  ASSERT_EQ(r->gaps.size(), 1u);
  EXPECT_EQ(r->gaps[0].action, GapNote::Action::Held);
  EXPECT_EQ(r->gaps[0].from_s, 10);
  EXPECT_EQ(r->gaps[0].to_s, 400);
  EXPECT_NEAR(r->gaps[0].distance_m, 39'000, 1);  // 390 s at 100 m/s, a chord of 39 km
  ASSERT_EQ(f.fixes.size(), 23u);  // one hold fix
  EXPECT_NEAR(f.fixes[11].time_s, 400 - kHoldJump_s, 1e-9);
  const geo::Geodetic lastBefore = fixAt(10, 1000, 0).pose.position;
  EXPECT_NEAR(distanceBetween_m(sample(f, 200).position, lastBefore), 0, 1e-3);
  EXPECT_NEAR(distanceBetween_m(sample(f, 399.9).position, lastBefore), 0, 1e-3);
  EXPECT_NEAR(distanceBetween_m(sample(f, 400).position, fixAt(400, 40'000, 0).pose.position), 0, 1e-3);
}

TEST(Clean, ALongGapCanEndTheTrack) {
  ParsedFlight f = withGap(400);
  const auto r = clean(f, {350, 120, LongGap::End}, "gap.csv");
  ASSERT_TRUE(r);
  EXPECT_EQ(r->kept, 11u);
  EXPECT_EQ(r->droppedFor(DropReason::AfterGap), 11u);
  ASSERT_EQ(r->gaps.size(), 1u);
  EXPECT_EQ(r->gaps[0].action, GapNote::Action::Ended);
  ASSERT_EQ(f.fixes.size(), 11u);
  EXPECT_EQ(f.fixes.back().time_s, 10);
}

TEST(Clean, AShorterGapIsInterpolatedAndNoted) {
  ParsedFlight f = withGap(100);  // a 90 s gap: over kGapWarning_s, under the default 120 s
  const auto r = clean(f, {}, "gap.csv");
  ASSERT_TRUE(r);
  ASSERT_EQ(r->gaps.size(), 1u);
  EXPECT_EQ(r->gaps[0].action, GapNote::Action::Interpolated);
  EXPECT_EQ(f.fixes.size(), 22u);
  EXPECT_NEAR(distanceBetween_m(sample(f, 55).position, fixAt(55, 5500, 0).pose.position), 0, 2);
  // With --max-gap 60 the same gap is held.
  ParsedFlight g = withGap(100);
  ASSERT_TRUE(clean(g, {350, 60, LongGap::Hold}, "gap.csv"));
  EXPECT_EQ(g.fixes.size(), 23u);
}

TEST(Clean, TooFewFixesLeftIsAnError) {
  ParsedFlight f;
  f.fixes = {fixAt(0, 0, 0), fixAt(1, 1'000'000, 0)};
  const auto r = clean(f, {}, "two.csv");
  ASSERT_FALSE(r);
  EXPECT_NE(r.error().detail.find("--no-clean"), std::string::npos) << r.error().detail;
}

TEST(Clean, AttitudeIsDerivedAgainWithoutTheSpoofedFix) {
  ParsedFlight f = eastbound(100, 1, 40);
  f.fixes[20] = fixAt(20, 2000, 300'000);
  deriveAttitude(f);
  f.attitudeFromTrack = true;
  EXPECT_GT(std::abs(f.fixes[19].pose.roll_deg), 10);  // the jump banks the neighbours
  const auto r = clean(f, {}, "spoof.csv");
  ASSERT_TRUE(r);
  EXPECT_TRUE(r->attitudeRederived);
  for (const Fix& x : f.fixes) {
    EXPECT_NEAR(x.pose.roll_deg, 0, 0.01) << "t=" << x.time_s;
    // Due east along a great circle: its azimuth drifts 0.04 deg in 4 km at 46 N.
    EXPECT_NEAR(x.pose.yaw_deg, 90, 0.1) << "t=" << x.time_s;
  }
}

TEST(Clean, ACleanTrackIsLeftAsItIs) {
  ParsedFlight f = eastbound(250, 1, 100);
  const ParsedFlight before = f;
  const auto r = clean(f, {}, "clean.csv");
  ASSERT_TRUE(r);
  EXPECT_EQ(r->kept, 101u);
  EXPECT_TRUE(r->dropped.empty());
  EXPECT_TRUE(r->gaps.empty());
  ASSERT_EQ(f.fixes.size(), before.fixes.size());
  for (std::size_t i = 0; i < f.fixes.size(); ++i) EXPECT_EQ(f.fixes[i].time_s, before.fixes[i].time_s);
}

}  // namespace
}  // namespace sky::flight
