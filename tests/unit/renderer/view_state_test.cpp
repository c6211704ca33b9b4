// A channel's view from CIGI View Definition and View Control
// (renderer/app view_state.hpp) and the weather clock locked to the host's
// time (host_locked_clock.hpp): enable bits, other views, views that would not
// draw, mirroring, and channels that receive a host frame at different times.
#include <chrono>
#include <cmath>

#include <gtest/gtest.h>

#include "sky/app/host_locked_clock.hpp"
#include "sky/app/view_state.hpp"
#include "sky/weather/host_clock_lock.hpp"

namespace sky::app {
namespace {

ChannelView channel(std::uint16_t id) {
  ChannelView v;
  v.viewId = id;
  v.frustum = {-40, 40, 25, -25};  // the command line's
  return v;
}

TEST(ViewState, DefinitionAppliesOnlyTheEnabledHalfAngles) {
  ChannelView v = channel(1);
  cigi::ViewDefinition d;
  d.viewId = 1;
  d.leftEnable = d.rightEnable = true;
  d.left_deg = -10;
  d.right_deg = 50;
  d.top_deg = 5;  // not enabled: kept
  d.farEnable = true;
  d.far_m = 20000;
  EXPECT_EQ(applyViewPacket(v, d).outcome, ViewPacketOutcome::Applied);
  EXPECT_EQ(v.frustum, (render::ViewFrustum{-10, 50, 25, -25}));
  EXPECT_TRUE(v.frustumFromHost);
  EXPECT_EQ(v.far_m, 20000.0);
  EXPECT_FALSE(v.near_m);
  EXPECT_EQ(v.definitions, 1u);
}

TEST(ViewState, OtherViewsAreIgnored) {
  ChannelView v = channel(0);
  cigi::ViewDefinition d;
  d.viewId = 2;
  d.leftEnable = true;
  d.left_deg = -5;
  cigi::ViewControl c;
  c.viewId = 2;
  c.yawEnable = true;
  c.yaw_deg = 60;
  EXPECT_EQ(applyViewPacket(v, d).outcome, ViewPacketOutcome::OtherView);
  EXPECT_EQ(applyViewPacket(v, c).outcome, ViewPacketOutcome::OtherView);
  EXPECT_EQ(v.frustum, channel(0).frustum);
  EXPECT_EQ(v.eyepoint.yaw_deg, 0);
}

// A frustum the renderer would refuse (left right of right, or a half-angle
// the decoder lets through at 89.5 deg) is rejected whole: nothing changes.
TEST(ViewState, UndrawableFrustaAreRejected) {
  ChannelView v = channel(0);
  cigi::ViewDefinition d;
  d.leftEnable = true;
  d.left_deg = 45;  // right is still 40
  EXPECT_EQ(applyViewPacket(v, d).outcome, ViewPacketOutcome::Rejected);
  d.left_deg = -89.5f;
  EXPECT_EQ(applyViewPacket(v, d).outcome, ViewPacketOutcome::Rejected);
  EXPECT_EQ(v.frustum, channel(0).frustum);
  EXPECT_EQ(v.definitions, 0u);
  d.left_deg = -30;
  d.orthographic = true;
  const ViewUpdate u = applyViewPacket(v, d);
  EXPECT_EQ(u.outcome, ViewPacketOutcome::Applied);
  EXPECT_EQ(u.unsupported.size(), 1u);
}

TEST(ViewState, ControlAppliesTheEnabledOffsetsOnTheOwnship) {
  ChannelView v = channel(0);
  cigi::ViewControl c;
  c.xEnable = c.yawEnable = true;
  c.x_m = 10;
  c.yaw_deg = 60;
  c.pitch_deg = 30;  // not enabled
  EXPECT_EQ(applyViewPacket(v, c).outcome, ViewPacketOutcome::Applied);
  EXPECT_EQ(v.eyepoint.x_m, 10);
  EXPECT_EQ(v.eyepoint.yaw_deg, 60);
  EXPECT_EQ(v.eyepoint.pitch_deg, 0);
  const geo::GeodeticPose eye = viewCamera({{47, 8, 1000}, 10, 0, 0}, v);
  EXPECT_NEAR(eye.yaw_deg, 70, 1e-4);  // 10 m on: the meridians converge by 2e-5 deg
  c.entityId = 3;
  EXPECT_EQ(applyViewPacket(v, c).outcome, ViewPacketOutcome::Rejected);
}

TEST(ViewState, MirrorFlipsColourAndDepth) {
  render::Image im;
  im.width = 3;
  im.height = 2;
  for (int i = 0; i < 6; ++i) {
    for (int c = 0; c < 4; ++c) im.rgba.push_back(float(i));
    im.cloudDepth_m.push_back(float(i));
  }
  render::Image h = im;
  mirrorImage(h, MirrorMode::Horizontal);
  EXPECT_EQ(h.cloudDepth_m, (std::vector<float>{2, 1, 0, 5, 4, 3}));
  EXPECT_EQ(h.rgba[0], 2.0f);
  render::Image both = im;
  mirrorImage(both, MirrorMode::Both);
  EXPECT_EQ(both.cloudDepth_m, (std::vector<float>{5, 4, 3, 2, 1, 0}));
}

// Three channels receive the same host frames a few ms apart, and re-anchor
// the server's clock at slightly different instants: without the server's
// offset, each snaps its own estimate; here none lies near a grid line, so
// their weather clocks for each host frame are equal bit for bit, and within
// the grid of the server's.
TEST(HostClock, ChannelsAgreeOnEachHostFrame) {
  using namespace std::chrono;
  const auto t0 = steady_clock::now();
  const weather::WeatherClock server(5000.25, 1.0, t0);
  HostLockedClock channels[3];
  for (int frame = 0; frame < 120; ++frame) {
    const double host_s = 17.0 + frame / 60.0;
    const auto sent = t0 + duration_cast<steady_clock::duration>(duration<double>(frame / 60.0 + 0.3));
    double first = NAN;
    for (int c = 0; c < 3; ++c) {
      const auto arrived = sent + microseconds(700 * c + 37 * (frame % 5));
      const weather::WeatherClock anchored(5000.25 + 0.0002 * c, 1.0, t0 + microseconds(200 * c));
      const HostClockReading r = channels[c].at(host_s, "10.0.0.1", anchored, arrived, std::nullopt);
      EXPECT_EQ(r.source, HostClockSource::Local);
      if (c == 0) first = r.weatherClock_s;
      EXPECT_EQ(r.weatherClock_s, first) << "frame " << frame << " channel " << c;
      EXPECT_NEAR(r.weatherClock_s, server.at(sent), 0.5 * weather::kHostClockGrid_s + 0.01);
    }
  }
  // The server's clock set 60 s on: every channel follows at once.
  const weather::WeatherClock moved(5060.25, 1.0, t0);
  const auto later = t0 + seconds(3);
  const double a = channels[0].at(20.0, "10.0.0.1", moved, later, std::nullopt).weatherClock_s;
  const double b = channels[2].at(20.0, "10.0.0.1", moved, later + milliseconds(2), std::nullopt).weatherClock_s;
  EXPECT_EQ(a, b);
  EXPECT_NEAR(a, moved.at(later), 0.5 * weather::kHostClockGrid_s + 0.01);
  // No host time: the server's clock as it stands.
  const HostClockReading none = channels[1].at(std::nullopt, "10.0.0.1", moved, later, std::nullopt);
  EXPECT_EQ(none.weatherClock_s, moved.at(later));
  EXPECT_EQ(none.source, HostClockSource::None);
  EXPECT_FALSE(none.proposal);
}

// What failed in CI: two channels whose estimates lie either side of a grid
// line (the server's clock 5000.4998 and 5000.5003 at their arrivals of host
// time 0) snap 1 s apart on their own and would draw the whole run 1 s
// apart. Each proposes its own; the server keeps the first (channel 0's) and
// sends it to both, and both then draw with it.
TEST(HostClock, StraddlingEstimatesAgreeThroughTheServersOffset) {
  using namespace std::chrono;
  const auto t0 = steady_clock::now();
  const weather::WeatherClock clocks[2] = {weather::WeatherClock(5000.4998, 1.0, t0),
                                           weather::WeatherClock(5000.5003, 1.0, t0)};
  HostLockedClock channels[2];
  HostClockReading own[2];
  for (int c = 0; c < 2; ++c) own[c] = channels[c].at(0.0, "10.0.0.1", clocks[c], t0, std::nullopt);
  EXPECT_EQ(own[1].weatherClock_s - own[0].weatherClock_s, 1.0);  // the failure, without the server
  for (const auto& r : own) {
    EXPECT_EQ(r.source, HostClockSource::Local);
    ASSERT_TRUE(r.proposal);
    EXPECT_EQ(r.proposal->host, "10.0.0.1");
    EXPECT_EQ(r.proposal->rate, 1.0);
    EXPECT_EQ(r.proposal->offset_s, r.weatherClock_s);  // host time 0
  }
  const std::optional<stream::HostClock> held = own[0].proposal;  // what the server sends both
  for (int frame = 1; frame < 60; ++frame) {
    const double host_s = frame / 30.0;
    const auto arrived = t0 + duration_cast<steady_clock::duration>(duration<double>(host_s));
    const HostClockReading a = channels[0].at(host_s, "10.0.0.1", clocks[0], arrived, held);
    const HostClockReading b = channels[1].at(host_s, "10.0.0.1", clocks[1], arrived, held);
    EXPECT_EQ(a.source, HostClockSource::Server);
    EXPECT_EQ(b.source, HostClockSource::Server);
    EXPECT_EQ(a.weatherClock_s, b.weatherClock_s) << "frame " << frame;
    EXPECT_EQ(a.weatherClock_s, held->offset_s + host_s);
    EXPECT_FALSE(a.proposal);
    EXPECT_FALSE(b.proposal);
  }
}

// The server's offset is used only where it stands: for this host, at this
// rate, within the relatch bound (plus half a step) of the channel's
// estimate. Otherwise the channel draws with its own and proposes it again,
// at most every kProposalInterval while unchanged.
TEST(HostClock, AnOffsetThatNoLongerStandsIsNotUsed) {
  using namespace std::chrono;
  const auto t0 = steady_clock::now();
  const weather::WeatherClock server(1000.0, 1.0, t0);
  HostLockedClock channel;
  // The host's time jumped back 100 s (a replay looped): the held offset is
  // 100 s off this estimate.
  const stream::HostClock stale{"10.0.0.1", 800.0, 1.0};
  HostClockReading r = channel.at(100.0, "10.0.0.1", server, t0, stale);
  EXPECT_EQ(r.source, HostClockSource::Local);
  EXPECT_EQ(r.weatherClock_s, 1000.0);
  ASSERT_TRUE(r.proposal);
  EXPECT_EQ(r.proposal->offset_s, 900.0);  // the server's clock 1000 s at host time 100 s
  // Another host's offset, or one taken at another rate, is not this one's.
  const stream::HostClock other{"10.0.0.2", 900.0, 1.0}, otherRate{"10.0.0.1", 900.0, 2.0};
  EXPECT_EQ(channel.at(100.1, "10.0.0.1", server, t0 + milliseconds(100), other).source, HostClockSource::Local);
  EXPECT_EQ(channel.at(100.2, "10.0.0.1", server, t0 + milliseconds(200), otherRate).source, HostClockSource::Local);
  // The proposal is not repeated within kProposalInterval of the last one...
  EXPECT_FALSE(channel.at(100.3, "10.0.0.1", server, t0 + milliseconds(300), std::nullopt).proposal);
  // ...and is after it.
  EXPECT_TRUE(channel.at(100.5, "10.0.0.1", server, t0 + HostLockedClock::kProposalInterval, std::nullopt).proposal);
  // Within 2.5 steps of the estimate, the server's is used (it kept an
  // offset a proposal up to half a step from the estimate stood against).
  const stream::HostClock near{"10.0.0.1", 900.0 + 2.4, 1.0};
  r = channel.at(101.0, "10.0.0.1", server, t0 + seconds(1), near);
  EXPECT_EQ(r.source, HostClockSource::Server);
  EXPECT_EQ(r.weatherClock_s, 902.4 + 101.0);
  const stream::HostClock far{"10.0.0.1", 900.0 + 2.6, 1.0};
  EXPECT_EQ(channel.at(101.0, "10.0.0.1", server, t0 + seconds(1), far).source, HostClockSource::Local);
}

}  // namespace
}  // namespace sky::app
