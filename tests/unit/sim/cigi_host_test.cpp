// The replay's CIGI host frames: what a simulator host sends, decoded by our
// own (tshark-checked) CIGI reader.
#include <cmath>

#include <gtest/gtest.h>

#include "sky/sim/cigi_host.hpp"

namespace sky::sim {
namespace {

TEST(CigiHost, FirstFrameCarriesViewDefinitionAndCelestial) {
  CigiHost host({cigi::ByteOrder::Little, 60, 2.0, 1795299684});
  geo::GeodeticPose pose{{46.2, 12.8, 900}, 370, 5, -190};  // yaw and roll outside CIGI's ranges
  auto first = cigi::decodeDatagram(host.nextFrame(pose, 0.0));
  ASSERT_TRUE(first) << first.error().detail;
  EXPECT_EQ(first->order, cigi::ByteOrder::Little);
  ASSERT_EQ(first->packets.size(), 4u);
  const auto& ig = std::get<cigi::IgControl>(first->packets[0]);
  EXPECT_EQ(ig.hostFrame, 0u);
  const auto& own = std::get<cigi::EntityControl>(first->packets[1]);
  EXPECT_FLOAT_EQ(own.yaw_deg, 10.0f);    // wrapped into [0, 360)
  EXPECT_FLOAT_EQ(own.roll_deg, 170.0f);  // wrapped into (-180, 180]
  const auto& vd = std::get<cigi::ViewDefinition>(first->packets[2]);
  EXPECT_FLOAT_EQ(vd.top_deg, 30.0f);
  // tan(h) = tan(30 deg) * 2
  EXPECT_NEAR(vd.right_deg, 49.1066, 1e-3);
  const auto& cel = std::get<cigi::CelestialSphereControl>(first->packets[3]);
  EXPECT_EQ(cel.dateMmddyyyy, 11212026u);

  // Within the same UTC minute: ownship only. A minute later: Celestial again.
  auto second = cigi::decodeDatagram(host.nextFrame(pose, 1.0));
  ASSERT_TRUE(second);
  EXPECT_EQ(second->packets.size(), 2u);
  EXPECT_EQ(std::get<cigi::IgControl>(second->packets[0]).hostFrame, 1u);
  auto later = cigi::decodeDatagram(host.nextFrame(pose, 60.0));
  ASSERT_TRUE(later);
  ASSERT_EQ(later->packets.size(), 3u);
  EXPECT_EQ(std::get<cigi::CelestialSphereControl>(later->packets[2]).minute, 22);
}

// Three channels 60 deg wide: every frame carries, per view id, a View
// Definition of +-30 deg horizontally and atan(tan 30 / aspect) vertically,
// and a View Control turning the view -60, 0, +60 deg.
TEST(CigiHost, ChannelsCarryTheirViewsEveryFrame) {
  HostOptions o;
  o.aspect = 120.0 / 68.0;
  o.channels = 3;
  o.channelWidth_deg = 60;
  CigiHost host(o);
  const geo::GeodeticPose pose{{46.2, 12.8, 900}, 90, 0, 0};
  for (double t : {0.0, 0.5}) {
    auto d = cigi::decodeDatagram(host.nextFrame(pose, t));
    ASSERT_TRUE(d) << d.error().detail;
    ASSERT_EQ(d->packets.size(), 2u + 2 * 3);
    for (std::uint16_t i = 0; i < 3; ++i) {
      const auto& vd = std::get<cigi::ViewDefinition>(d->packets[2 + 2 * i]);
      const auto& vc = std::get<cigi::ViewControl>(d->packets[3 + 2 * i]);
      EXPECT_EQ(vd.viewId, i);
      EXPECT_EQ(vc.viewId, i);
      EXPECT_FLOAT_EQ(vd.left_deg, -30.0f);
      EXPECT_FLOAT_EQ(vd.right_deg, 30.0f);
      EXPECT_NEAR(vd.top_deg, std::atan(std::tan(M_PI / 6) * 68.0 / 120.0) * 180 / M_PI, 1e-5);
      EXPECT_FLOAT_EQ(vd.bottom_deg, -vd.top_deg);
      EXPECT_TRUE(vd.leftEnable && vd.rightEnable && vd.topEnable && vd.bottomEnable);
      EXPECT_FLOAT_EQ(vc.yaw_deg, -60.0f + 60.0f * i);
      EXPECT_TRUE(vc.yawEnable && vc.xEnable);
      EXPECT_EQ(vc.entityId, 0);
    }
  }
}

TEST(CigiHost, TracksStartOfFrameAndCountsJunk) {
  CigiHost host;
  geo::GeodeticPose pose{{0, 0, 100}, 0, 0, 0};
  for (int i = 0; i < 5; ++i) host.nextFrame(pose, i / 60.0);
  EXPECT_EQ(host.igLagFrames(), 5u);
  cigi::StartOfFrame sof;
  sof.igFrame = 9;
  sof.lastHostFrame = 3;
  cigi::DatagramWriter w;
  w.add(sof);
  EXPECT_TRUE(host.onIgDatagram(w.bytes()));
  EXPECT_EQ(host.lastIgFrame(), std::optional<std::uint32_t>(9));
  EXPECT_EQ(host.igLagFrames(), 1u);  // frame 4 not yet seen
  const std::vector<std::uint8_t> junk = {1, 2, 3};
  EXPECT_FALSE(host.onIgDatagram(junk));
  EXPECT_EQ(host.malformedReceived(), 1u);
}

}  // namespace
}  // namespace sky::sim
