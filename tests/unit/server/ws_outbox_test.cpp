// A console client's bounded outbox: hello first, events in order and
// bounded, state/renderers/health coalesced to the newest.
#include <gtest/gtest.h>

#include "sky/server/ws_outbox.hpp"

namespace sky::server {
namespace {

WsText text(const char* s) { return std::make_shared<const std::string>(s); }

std::string take(WsOutbox& box) {
  auto t = box.takeNext();
  return t ? **t : std::string("(nothing)");
}

TEST(WsOutbox, HelloThenEventsInOrderThenTheNewestOfEachSlot) {
  WsOutbox box(8);
  EXPECT_TRUE(box.empty());
  box.setHealth(text("health 1"));
  box.setState(text("state 1"));
  box.setRenderers(text("renderers 1"));
  ASSERT_TRUE(box.pushEvent(text("event 1")));
  box.pushFirst(text("hello"));
  box.setState(text("state 2"));  // replaces state 1, unsent
  ASSERT_TRUE(box.pushEvent(text("event 2")));
  box.setHealth(text("health 2"));
  EXPECT_EQ(take(box), "hello");
  EXPECT_EQ(take(box), "event 1");
  EXPECT_EQ(take(box), "event 2");
  EXPECT_EQ(take(box), "state 2");
  EXPECT_EQ(take(box), "renderers 1");
  EXPECT_EQ(take(box), "health 2");
  EXPECT_TRUE(box.empty());
  EXPECT_EQ(take(box), "(nothing)");
}

// An event queued after the state was taken comes before the next state:
// a client never sees a state older than an event it has seen.
TEST(WsOutbox, AStateAfterAnEventIsSentAfterIt) {
  WsOutbox box(8);
  box.setState(text("state 1"));
  EXPECT_EQ(take(box), "state 1");
  ASSERT_TRUE(box.pushEvent(text("event 2")));
  box.setState(text("state 2"));
  EXPECT_EQ(take(box), "event 2");
  EXPECT_EQ(take(box), "state 2");
}

TEST(WsOutbox, EventsAreBounded) {
  WsOutbox box(3);
  for (int i = 0; i < 3; ++i) EXPECT_TRUE(box.pushEvent(text("e")));
  EXPECT_FALSE(box.pushEvent(text("one too many")));
  EXPECT_EQ(box.queuedEvents(), 3u);
  // Coalesced slots never grow whatever arrives.
  for (int i = 0; i < 1000; ++i) box.setState(text("s"));
  int n = 0;
  while (box.takeNext()) ++n;
  EXPECT_EQ(n, 4);
}

}  // namespace
}  // namespace sky::server
