// The server's host clock offsets (host_clocks.hpp): the first proposal for
// a host holds for every later one that stands against it; one that does not
// (a jump, another rate) replaces it; hosts are bounded. And on a real
// socket: two channels whose own estimates snap 1 s apart both get the
// first one's offset, and a replaced offset reaches every channel of that
// host and no other.
#include <chrono>
#include <memory>
#include <string>
#include <thread>

#include <gtest/gtest.h>

#include "sky/server/host_clocks.hpp"
#include "sky/server/scenario.hpp"
#include "sky/server/server.hpp"
#include "stream_test_client.hpp"

namespace sky::server {
namespace {

TEST(HostClocks, TheFirstProposalHoldsUntilOneNoLongerStands) {
  HostClocks clocks;
  const HostClockAnswer first = clocks.propose({"10.0.0.1", 5000.0, 1.0});
  EXPECT_TRUE(first.changed);
  EXPECT_EQ(first.held.offset_s, 5000.0);
  // A channel whose estimate snapped to the next grid point: the first's.
  HostClockAnswer a = clocks.propose({"10.0.0.1", 5001.0, 1.0});
  EXPECT_FALSE(a.changed);
  EXPECT_EQ(a.held.offset_s, 5000.0);
  a = clocks.propose({"10.0.0.1", 5002.0, 1.0});  // the relatch bound itself still stands
  EXPECT_FALSE(a.changed);
  EXPECT_EQ(a.held.offset_s, 5000.0);
  // The host's time jumped back 60 s: the new line replaces the old.
  a = clocks.propose({"10.0.0.1", 5060.0, 1.0});
  EXPECT_TRUE(a.changed);
  EXPECT_EQ(a.held.offset_s, 5060.0);
  // The server's clock runs at another rate: offsets at the old one are void.
  a = clocks.propose({"10.0.0.1", 5060.0, 2.0});
  EXPECT_TRUE(a.changed);
  EXPECT_EQ(a.held.rate, 2.0);
  // Another host is another clock.
  a = clocks.propose({"10.0.0.2", 100.0, 2.0});
  EXPECT_TRUE(a.changed);
  EXPECT_EQ(a.held.offset_s, 100.0);
  EXPECT_EQ(clocks.size(), 2u);
}

TEST(HostClocks, HostsAreBoundedForgettingTheLeastRecentlyProposedFor) {
  HostClocks clocks;
  clocks.propose({"keep", 1.0, 1.0});
  for (std::size_t i = 0; i < 3 * HostClocks::kMaxHosts; ++i) {
    clocks.propose({"host " + std::to_string(i), double(i), 1.0});
    clocks.propose({"keep", 1.0, 1.0});  // proposed for all along: never the one forgotten
    ASSERT_LE(clocks.size(), HostClocks::kMaxHosts);
  }
  EXPECT_EQ(clocks.size(), HostClocks::kMaxHosts);
  EXPECT_FALSE(clocks.propose({"keep", 1.5, 1.0}).changed);
  EXPECT_TRUE(clocks.propose({"host 0", 0.0, 1.0}).changed) << "forgotten long ago: set anew";
}

TEST(HostClockSocket, ChannelsOfOneHostGetOneOffsetAndHearItsReplacement) {
  auto scenario = loadScenario(SKY_SOURCE_DIR "/deploy/scenarios/skeleton-cumulus.toml");
  ASSERT_TRUE(scenario) << scenario.error().detail;
  ServerOptions options;
  options.port = 0;
  options.heartbeatInterval = 50ms;
  options.handleSignals = false;
  auto created = Server::create(options, WeatherState(*scenario, WallClock::now()));
  ASSERT_TRUE(created) << created.error().detail;
  std::unique_ptr<Server> server = std::move(*created);
  std::thread thread([&] { server->run(); });

  TestClient left(server->port()), right(server->port()), other(server->port());
  for (TestClient* c : {&left, &right, &other}) {
    auto hello = c->readNext<stream::Hello>();
    ASSERT_TRUE(hello) << hello.error().detail;
    EXPECT_NE(hello->features & stream::kFeatureHostClock, 0u);
  }
  // Estimates either side of a grid line snapped 1 s apart.
  left.send(stream::HostClock{"10.0.0.1", 4000.0, 1.0});
  auto got = left.readNext<stream::HostClock>();
  ASSERT_TRUE(got) << got.error().detail;
  EXPECT_EQ(got->offset_s, 4000.0);
  right.send(stream::HostClock{"10.0.0.1", 4001.0, 1.0});
  got = right.readNext<stream::HostClock>();
  ASSERT_TRUE(got) << got.error().detail;
  EXPECT_EQ(got->offset_s, 4000.0) << "the first channel's offset, bit for bit";
  other.send(stream::HostClock{"10.0.0.9", 7.0, 1.0});
  got = other.readNext<stream::HostClock>();
  ASSERT_TRUE(got) << got.error().detail;
  EXPECT_EQ(got->offset_s, 7.0);
  // The host's replay looped: the right channel sees it first; the left
  // channel hears the new offset without asking, the other host's does not.
  right.send(stream::HostClock{"10.0.0.1", 4100.0, 1.0});
  for (TestClient* c : {&right, &left}) {
    got = c->readNext<stream::HostClock>();
    ASSERT_TRUE(got) << got.error().detail;
    EXPECT_EQ(got->host, "10.0.0.1");
    EXPECT_EQ(got->offset_s, 4100.0);
  }
  const auto until = std::chrono::steady_clock::now() + 300ms;
  while (std::chrono::steady_clock::now() < until) {
    auto m = other.read(200ms);
    ASSERT_TRUE(m) << m.error().detail;
    EXPECT_FALSE(std::holds_alternative<stream::HostClock>(*m)) << "another host's offset";
  }
  EXPECT_EQ(server->streamCounters().hostClockProposals.load(), 4u);
  EXPECT_EQ(server->streamCounters().hostClockChanges.load(), 3u);
  server->stop();
  thread.join();
}

}  // namespace
}  // namespace sky::server
