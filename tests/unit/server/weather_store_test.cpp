// The live weather in a real SQLite file: a restart restores the same state
// (hash), ramps mid-way, the event log and the sequence; the clock goes on by
// the downtime at its rate; a refused change leaves the file as it was; a
// file that is not a database is an error naming it.
#include <filesystem>
#include <fstream>

#include <gtest/gtest.h>

#include "sky/server/live_weather.hpp"
#include "sky/server/weather_store.hpp"
#include "store_files.hpp"

namespace fs = std::filesystem;
using namespace std::chrono_literals;

namespace sky::server {
namespace {

const WallClock::time_point kT0 = test::kStoreT0;

Scenario scenario() { return test::oneLayerScenario(); }

fs::path freshFile(const char* name) { return test::freshDatabase("skyshell-store-test", name); }

TEST(WeatherStore, RestartRestoresTheSameStateAndGoesOn) {
  const fs::path file = freshFile("restore.db");
  WallClock::time_point wall = kT0;
  std::int64_t unixMs = 1'700'000'000'000;
  std::uint64_t hash = 0;
  {
    auto store = WeatherStore::open(file);
    ASSERT_TRUE(store) << store.error().detail;
    auto saved = store->load();
    ASSERT_TRUE(saved);
    EXPECT_FALSE(*saved);  // a new file
    LiveWeather w(scenario(), kT0, [&] { return wall; }, [&] { return unixMs; });
    ASSERT_TRUE(store->save(w.toJson(), nullptr));
    w.attachStore(&*store);
    auto target = scenario().layers[0];
    target.coverage = 0.9;
    ASSERT_TRUE(w.submit({{SetLayer{target, Timing{std::nullopt, 600}}}, "alice", "api"}));
    // A refused change: nothing written.
    target.coverage = 2;
    ASSERT_FALSE(w.submit({{SetLayer{target, Timing{}}}, "bob", "api"}));
    wall += 100s;
    unixMs += 100'000;
    hash = w.stateHash();
    EXPECT_NEAR(w.layersAt(w.clockNow())[0].coverage, 0.4, 1e-12);  // 100 s into 0.3 -> 0.9 over 600 s
    // One commit: the refused change never reached the store.
    EXPECT_EQ(w.commitStats().count, 1u);
    EXPECT_GT(w.commitStats().max_s, 0.0);
    EXPECT_LE(w.commitStats().max_s, w.commitStats().total_s);
  }
  // Down for 50 s, then a new process restores.
  unixMs += 50'000;
  const WallClock::time_point wall2 = kT0 + 5000s;  // its own steady clock
  auto store = WeatherStore::open(file);
  ASSERT_TRUE(store) << store.error().detail;
  auto saved = store->load();
  ASSERT_TRUE(saved && *saved);
  LiveWeather w(scenario(), wall2, [&] { return wall2; }, [&] { return unixMs; });
  ASSERT_TRUE(w.restore((*saved)->state, (*saved)->events));
  EXPECT_EQ(w.stateHash(), hash);
  EXPECT_EQ(w.view().lastSequence, 1u);
  ASSERT_EQ(w.events(10).size(), 1u);
  EXPECT_EQ(w.events(10)[0].author, "alice");
  // The saved clock was 1100 at the last commit? No: it is saved at commit
  // time (clock 1000) and goes on by the 150 s since at rate 1.
  EXPECT_NEAR(w.clockNow(), 1150.0, 1e-6);
  EXPECT_NEAR(w.layersAt(w.clockNow())[0].coverage, 0.45, 1e-12);  // the ramp goes on
  // Sequence numbers continue.
  w.attachStore(&*store);
  auto next = scenario().layers[0];
  next.coverage = 0.5;
  auto applied = w.submit({{SetLayer{next, Timing{}}}, "carol", "api"});
  ASSERT_TRUE(applied);
  EXPECT_EQ(applied->sequence, 2u);
}

TEST(WeatherStore, NotADatabaseIsAnErrorNamingTheFile) {
  const fs::path file = freshFile("junk.db");
  std::ofstream(file) << "this is not an SQLite file, just text that is long enough to have a header page";
  auto store = WeatherStore::open(file);
  ASSERT_FALSE(store);
  EXPECT_NE(store.error().detail.find(file.string()), std::string::npos) << store.error().detail;
}

// One store per file: SQLite locks the file only while it commits, so a
// second server on the same file would open it and both would write it.
// The second open fails naming the file and the lock, and succeeds once the
// first store is gone (the kernel's flock goes with the descriptor, as it
// does when a server dies).
TEST(WeatherStore, ASecondStoreOnTheSameFileIsRefusedUntilTheFirstCloses) {
  const fs::path file = freshFile("owned.db");
  {
    auto first = WeatherStore::open(file);
    ASSERT_TRUE(first) << describe(first.error());
    auto second = WeatherStore::open(file, std::chrono::milliseconds{0});
    ASSERT_FALSE(second);
    EXPECT_EQ(second.error().code, ErrorCode::Io);
    EXPECT_NE(second.error().detail.find(file.string()), std::string::npos) << second.error().detail;
    EXPECT_NE(second.error().detail.find("second server"), std::string::npos) << second.error().detail;
    // Another file beside it is another weather.
    auto other = WeatherStore::open(freshFile("other.db"));
    EXPECT_TRUE(other) << describe(other.error());
  }
  auto again = WeatherStore::open(file);
  EXPECT_TRUE(again) << describe(again.error());
}

}  // namespace
}  // namespace sky::server
