// A channel's view from CIGI View Definition and View Control
// (renderer/app view_state.hpp) and the weather clock locked to the host's
// time (host_locked_clock.hpp): enable bits, other views, views that would not
// draw, mirroring, and channels that receive a host frame at different times.
#include <chrono>
#include <cmath>

#include <gtest/gtest.h>

#include "sky/app/host_locked_clock.hpp"
#include "sky/app/view_state.hpp"

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
// the server's clock at slightly different instants: their weather clocks
// for each host frame are equal bit for bit, and within the grid of the
// server's.
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
      const double w = channels[c].at(host_s, anchored, arrived);
      if (c == 0) first = w;
      EXPECT_EQ(w, first) << "frame " << frame << " channel " << c;
      EXPECT_NEAR(w, server.at(sent), 0.5 * kHostClockGrid_s + 0.01);
    }
  }
  // The server's clock set 60 s on: every channel follows at once.
  const weather::WeatherClock moved(5060.25, 1.0, t0);
  const auto later = t0 + seconds(3);
  const double a = channels[0].at(20.0, moved, later), b = channels[2].at(20.0, moved, later + milliseconds(2));
  EXPECT_EQ(a, b);
  EXPECT_NEAR(a, moved.at(later), 0.5 * kHostClockGrid_s + 0.01);
  // No host time: the server's clock as it stands.
  EXPECT_EQ(channels[1].at(std::nullopt, moved, later), moved.at(later));
}

}  // namespace
}  // namespace sky::app
