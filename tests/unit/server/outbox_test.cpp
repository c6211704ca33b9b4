// The bounded outbox: control frames in order and first; weather coalesced to
// the latest state.
#include <gtest/gtest.h>

#include <variant>

#include "sky/server/outbox.hpp"

namespace sky::server {
namespace {

Frame frame(std::uint8_t tag) { return Frame{tag}; }

stream::Subscribe subscribe(double lat_deg) {
  stream::Subscribe s;
  s.area = {lat_deg, 0, 1000};
  return s;
}

Frame takeFrame(Outbox& box) {
  auto item = box.takeNext();
  EXPECT_TRUE(item.has_value());
  if (!item) return {};
  const Frame* f = std::get_if<Frame>(&*item);
  EXPECT_NE(f, nullptr);
  return f ? *f : Frame{};
}

stream::Subscribe takeSubscribe(Outbox& box) {
  auto item = box.takeNext();
  EXPECT_TRUE(item.has_value());
  if (!item) return {};
  const stream::Subscribe* s = std::get_if<stream::Subscribe>(&*item);
  EXPECT_NE(s, nullptr);
  return s ? *s : stream::Subscribe{};
}

TEST(Outbox, StartsEmpty) {
  Outbox box;
  EXPECT_TRUE(box.empty());
  EXPECT_FALSE(box.takeNext().has_value());
}

TEST(Outbox, ControlGoesFirstInOrder) {
  Outbox box;
  box.setHeartbeat(frame(9));
  box.requestSnapshot(subscribe(10));
  box.pushControl(frame(1));
  box.pushControl(frame(2));
  EXPECT_EQ(takeFrame(box), frame(1));
  EXPECT_EQ(takeFrame(box), frame(2));
  EXPECT_DOUBLE_EQ(takeSubscribe(box).area.centerLat_deg, 10);
  EXPECT_TRUE(box.empty());
}

TEST(Outbox, NewerSubscriptionReplacesOneNotYetSent) {
  Outbox box;
  box.requestSnapshot(subscribe(10));
  box.requestSnapshot(subscribe(20));
  box.requestSnapshot(subscribe(30));
  EXPECT_DOUBLE_EQ(takeSubscribe(box).area.centerLat_deg, 30);
  EXPECT_FALSE(box.takeNext().has_value());
}

TEST(Outbox, NewerHeartbeatReplacesOneNotYetSent) {
  Outbox box;
  for (std::uint8_t i = 0; i < 100; ++i) box.setHeartbeat(frame(i));
  EXPECT_EQ(takeFrame(box), frame(99));
  EXPECT_TRUE(box.empty());
}

TEST(Outbox, SnapshotSupersedesWaitingHeartbeat) {
  // The snapshot is built when sent, with a clock newer than the heartbeat's:
  // sending the heartbeat after it would move the client's clock backwards.
  Outbox box;
  box.setHeartbeat(frame(9));
  box.requestSnapshot(subscribe(10));
  takeSubscribe(box);
  EXPECT_TRUE(box.empty());
}

TEST(Outbox, DropWeatherKeepsControl) {
  Outbox box;
  box.setHeartbeat(frame(9));
  box.requestSnapshot(subscribe(10));
  box.pushControl(frame(1));
  box.dropWeather();
  EXPECT_EQ(takeFrame(box), frame(1));
  EXPECT_TRUE(box.empty());
}

}  // namespace
}  // namespace sky::server
