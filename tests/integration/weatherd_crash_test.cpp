// Crash safety of the weather server's SQLite state: several clients post a
// storm of two-change batches (each batch sets two layers to the same marker,
// so half a batch is visible) while the server is killed with SIGKILL at
// random moments, many times, and restarted on the same file. After every
// restart: every change that was acknowledged (HTTP 200 with its sequence)
// is there, in the event log and in the state; no batch is half applied; the
// sequence never goes back; a change that got no answer is either wholly
// there or wholly absent.
#include <filesystem>
#include <fstream>
#include <map>
#include <mutex>
#include <random>
#include <thread>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "child_process.hpp"
#include "change_storm.hpp"
#include "sky/sim/http_client.hpp"

namespace fs = std::filesystem;
using namespace std::chrono_literals;

namespace sky::test {
namespace {

constexpr const char* kToken = "crash-test-token";
constexpr int kClients = 3;
constexpr int kCycles = 20;
// Events GET /api/events returns at most (server/src/live_weather.cpp's kMaxEvents).
constexpr std::size_t kEventWindow = 10000;

TEST(WeatherdCrash, AcknowledgedChangesSurviveKillNineAndNoBatchIsHalfApplied) {
  const fs::path dir = fs::path(SKY_TEST_OUTPUT_DIR) / "weatherd-crash";
  fs::remove_all(dir);
  fs::create_directories(dir);
  std::ofstream(dir / "token") << kToken << "\n";
  const unsigned seed = std::random_device{}();
  std::mt19937 rng(seed);
  SCOPED_TRACE("seed " + std::to_string(seed));

  StormRecord record;
  const std::vector<Acked>& acked = record.acked;
  std::uint64_t lastSequence = 0;
  for (int cycle = 0; cycle < kCycles; ++cycle) {
    const fs::path portFile = dir / ("http." + std::to_string(cycle) + ".port");
    ChildProcess server({SKY_WEATHERD, "--scenario", SKY_SCENARIO_CLOUDY, "--port", "0", "--http-port", "0",
                         "--http-port-file", portFile.string(), "--token-file", (dir / "token").string(), "--db",
                         (dir / "weather.db").string()},
                        (dir / ("weatherd." + std::to_string(cycle) + ".log")).string());
    const unsigned port = waitForPortFile(portFile.string(), 20s);
    ASSERT_GT(port, 0u) << server.log();

    // What survived the last crash.
    auto survivors = readSurvivors(port, kToken, kEventWindow);
    ASSERT_TRUE(survivors) << describe(survivors.error()) << server.log();
    const std::uint64_t sequence = survivors->sequence;
    EXPECT_GE(sequence, lastSequence) << "cycle " << cycle << ": the sequence went back";
    std::map<int, double>& base = survivors->base;
    for (int c = 0; c < kClients; ++c) {
      EXPECT_EQ(base.count(10 + c), base.count(20 + c)) << "cycle " << cycle << " client " << c << ": half a batch";
      if (base.count(10 + c)) {
        EXPECT_EQ(base[10 + c], base[20 + c]) << "cycle " << cycle << " client " << c << ": half a batch";
        EXPECT_LE(base[10 + c], 1000 + record.lastAttempt[c]) << "a marker never sent";
      }
    }
    for (const Acked& a : acked) {
      // Each client's markers only grow: its layers hold at least its last acknowledged one.
      EXPECT_GE(base[10 + a.client], 1000 + a.marker)
          << "cycle " << cycle << ": client " << a.client << " marker " << a.marker << " (sequence " << a.sequence
          << ") was acknowledged and is lost";
    }
    const std::map<std::uint64_t, std::string>& events = survivors->authors;
    // The server and its database keep the newest kEventWindow events
    // (kMaxStoredEvents): an acknowledged change older than the
    // window is checked through the state above, and then the window must
    // be full and reach up to the current sequence.
    const std::uint64_t oldest = events.empty() ? 0 : events.begin()->first;
    if (!events.empty()) {
      EXPECT_EQ(events.rbegin()->first, sequence) << "cycle " << cycle << ": the newest event";
    }
    for (const Acked& a : acked) {
      if (a.sequence < oldest) {
        EXPECT_EQ(events.size(), kEventWindow) << "cycle " << cycle << ": sequence " << a.sequence
                                               << " left a window that is not full";
        continue;
      }
      const auto it = events.find(a.sequence);
      ASSERT_NE(it, events.end()) << "cycle " << cycle << ": acknowledged sequence " << a.sequence << " missing (the log holds "
                                 << events.size() << " events from " << oldest << ")";
      EXPECT_EQ(it->second, "client" + std::to_string(a.client)) << "sequence " << a.sequence;
    }
    lastSequence = sequence;
    if (cycle == kCycles - 1) {
      EXPECT_EQ(server.stop(), 0) << server.log();
      break;
    }

    // The storm, and a SIGKILL at a random moment in it.
    ChangeStorm storm(port, kToken, kClients, 2, record);
    std::this_thread::sleep_for(std::chrono::milliseconds(std::uniform_int_distribution<int>(100, 600)(rng)));
    server.killNow();
    storm.stop();
  }
  std::printf("crash test: %d kills, %zu acknowledged batches checked after each, %zu unanswered, "
              "last sequence %llu, seed %u\n",
              kCycles - 1, acked.size(), record.unanswered, static_cast<unsigned long long>(lastSequence), seed);
  EXPECT_GT(acked.size(), 50u) << "the storm hardly ran";
}

}  // namespace
}  // namespace sky::test
