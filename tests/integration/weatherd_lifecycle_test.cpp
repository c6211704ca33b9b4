// Issue 18: skyshell-weatherd's start-up and shutdown as a process. A weather
// database of garbage bytes, and one held under an exclusive lock by another
// connection, each end the start with exit code 3 (which the systemd unit
// does not restart on) and a message naming the file. SIGTERM in the middle
// of a storm of changes exits 0 within a second or two and loses no
// acknowledged change: after a restart on the same file, every acknowledged
// sequence is in the event log and every client's last acknowledged marker
// is in the state; the CIGI changes a client saw before SIGTERM are there too.
#include <sqlite3.h>

#include <atomic>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <mutex>
#include <thread>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <boost/asio/ip/udp.hpp>

#include "child_process.hpp"
#include "sky/cigi/codec.hpp"
#include "change_storm.hpp"
#include "sky/sim/http_client.hpp"

namespace fs = std::filesystem;
using namespace std::chrono_literals;

namespace sky::test {
namespace {

constexpr const char* kToken = "lifecycle-test-token";
// server/main.cpp's exit code for a database that cannot be used.
constexpr int kExitStorage = 3;

fs::path freshDir(const char* name) {
  const fs::path dir = fs::path(SKY_TEST_OUTPUT_DIR) / name;
  fs::remove_all(dir);
  fs::create_directories(dir);
  std::ofstream(dir / "token") << kToken << "\n";
  return dir;
}

std::vector<std::string> weatherdArgs(const fs::path& dir, const std::string& tag) {
  return {SKY_WEATHERD,  "--scenario", SKY_SCENARIO_CLOUDY, "--port", "0", "--http-port", "0", "--http-port-file",
          (dir / ("http." + tag + ".port")).string(), "--token-file", (dir / "token").string(), "--db",
          (dir / "weather.db").string()};
}

Result<sim::HttpResponse> call(unsigned port, const std::string& method, const std::string& target) {
  return callWeatherd(port, kToken, method, target);
}

TEST(WeatherdLifecycle, ADatabaseOfGarbageExitsWithThreeNamingTheFile) {
  const fs::path dir = freshDir("weatherd-garbage-db");
  {
    std::ofstream out(dir / "weather.db", std::ios::binary);
    for (int i = 0; i < 8192; ++i) out.put(static_cast<char>((i * 131 + 7) & 0xff));
  }
  ChildProcess server(weatherdArgs(dir, "0"), (dir / "weatherd.log").string());
  const auto code = server.wait(10s);
  ASSERT_TRUE(code) << "still running:\n" << server.log();
  EXPECT_EQ(*code, kExitStorage) << server.log();
  EXPECT_NE(server.log().find((dir / "weather.db").string()), std::string::npos) << server.log();
  EXPECT_NE(server.log().find("corrupt"), std::string::npos) << server.log();
}

TEST(WeatherdLifecycle, ALockedDatabaseExitsWithThreeNamingTheFile) {
  const fs::path dir = freshDir("weatherd-locked-db");
  {  // A real database first, made by the server itself.
    ChildProcess first(weatherdArgs(dir, "0"), (dir / "weatherd.0.log").string());
    ASSERT_GT(waitForPortFile((dir / "http.0.port").string(), 20s), 0u) << first.log();
    // A second server on the same file while the first runs: SQLite would
    // let both write it (it locks only during a commit); the store's owner
    // lock refuses the second, which exits 3 saying so.
    ChildProcess twin(weatherdArgs(dir, "twin"), (dir / "weatherd.twin.log").string());
    const auto twinCode = twin.wait(15s);
    ASSERT_TRUE(twinCode) << "a second server on the same database still running:\n" << twin.log();
    EXPECT_EQ(*twinCode, kExitStorage) << twin.log();
    EXPECT_NE(twin.log().find((dir / "weather.db").string()), std::string::npos) << twin.log();
    EXPECT_NE(twin.log().find("second server"), std::string::npos) << twin.log();
    ASSERT_EQ(first.stop(), 0) << first.log();
  }
  sqlite3* other = nullptr;
  ASSERT_EQ(sqlite3_open((dir / "weather.db").c_str(), &other), SQLITE_OK);
  ASSERT_EQ(sqlite3_exec(other, "BEGIN EXCLUSIVE;", nullptr, nullptr, nullptr), SQLITE_OK);
  ChildProcess second(weatherdArgs(dir, "1"), (dir / "weatherd.1.log").string());
  const auto code = second.wait(15s);
  sqlite3_exec(other, "ROLLBACK;", nullptr, nullptr, nullptr);
  sqlite3_close(other);
  ASSERT_TRUE(code) << "still running while another connection holds the lock:\n" << second.log();
  EXPECT_EQ(*code, kExitStorage) << second.log();
  EXPECT_NE(second.log().find((dir / "weather.db").string()), std::string::npos) << second.log();
  EXPECT_NE(second.log().find("lock"), std::string::npos) << second.log();
}

TEST(WeatherdLifecycle, SigtermInAStormExitsZeroPromptlyAndLosesNoAcknowledgedChange) {
  const fs::path dir = freshDir("weatherd-sigterm");
  constexpr int kClients = 3, kCycles = 3;
  StormRecord record;
  for (int cycle = 0; cycle <= kCycles; ++cycle) {
    const std::string tag = std::to_string(cycle);
    ChildProcess server(weatherdArgs(dir, tag), (dir / ("weatherd." + tag + ".log")).string());
    const unsigned port = waitForPortFile((dir / ("http." + tag + ".port")).string(), 20s);
    ASSERT_GT(port, 0u) << server.log();

    // Everything acknowledged before the last SIGTERM is here.
    auto survivors = readSurvivors(port, kToken);
    ASSERT_TRUE(survivors) << describe(survivors.error()) << server.log();
    // A change may be committed and its answer lost in the shutdown: a
    // client's layer holds its last acknowledged marker or a later one.
    for (const auto& [client, m] : record.lastAcked)
      EXPECT_GE(survivors->base[10 + client], 1000 + m)
          << "cycle " << cycle << ": client " << client << "'s last acknowledged change";
    for (const Acked& a : record.acked)
      EXPECT_EQ(survivors->authors[a.sequence], "client" + std::to_string(a.client))
          << "cycle " << cycle << ": acknowledged sequence " << a.sequence << " is not in the event log";
    if (cycle == kCycles) break;

    ChangeStorm storm(port, kToken, kClients, 1, record);
    std::this_thread::sleep_for(700ms);
    const auto signalled = std::chrono::steady_clock::now();
    const int code = server.stop();  // SIGTERM; SIGKILL (exit 137) only after 5 s
    const auto took = std::chrono::steady_clock::now() - signalled;
    storm.stop();
    EXPECT_EQ(code, 0) << server.log();
    EXPECT_LT(took, 2s) << "SIGTERM to exit: " << std::chrono::duration<double>(took).count() << " s";
    std::printf("cycle %d: SIGTERM to exit %.0f ms, %zu acknowledged so far\n", cycle,
                std::chrono::duration<double, std::milli>(took).count(), record.acked.size());
  }
  EXPECT_GT(record.acked.size(), 30u) << "the storm hardly ran";
}

// CIGI changes have no acknowledgement; what a client can see (the state
// over HTTP) must still survive SIGTERM, which commits the batch waiting.
// Whether the SIGTERM lands inside the 50 ms batch is up to timing here;
// that close() commits a waiting batch is checked deterministically in
// tests/unit/server/input_bounds_test.cpp.
TEST(WeatherdLifecycle, CigiChangesSeenBeforeSigtermSurviveIt) {
  const fs::path dir = freshDir("weatherd-sigterm-cigi");
  auto args = [&](const std::string& tag) {
    auto a = weatherdArgs(dir, tag);
    a.insert(a.end(), {"--cigi-port", "0", "--cigi-port-file", (dir / ("cigi." + tag + ".port")).string()});
    return a;
  };
  double last = 0;
  {
    ChildProcess server(args("0"), (dir / "weatherd.0.log").string());
    const unsigned port = waitForPortFile((dir / "http.0.port").string(), 20s);
    const unsigned cigiPort = waitForPortFile((dir / "cigi.0.port").string(), 20s);
    ASSERT_GT(cigiPort, 0u) << server.log();
    boost::asio::io_context io;
    boost::asio::ip::udp::socket socket(io, boost::asio::ip::udp::endpoint(boost::asio::ip::udp::v4(), 0));
    const boost::asio::ip::udp::endpoint to(boost::asio::ip::make_address("127.0.0.1"),
                                            static_cast<unsigned short>(cigiPort));
    for (int i = 1; i <= 200; ++i) {
      cigi::DatagramWriter w(cigi::ByteOrder::Big);
      w.add(cigi::IgControl{});
      cigi::WeatherControl wc;
      wc.layerId = cigi::LayerId::CloudLayer2;
      wc.cloudType = weather::CloudType::Stratocumulus;
      wc.coverage_pct = static_cast<float>(i % 100);
      wc.baseElevation_m = 3000;
      wc.thickness_m = 500;
      w.add(wc);
      last = (i % 100) / 100.0;
      socket.send_to(boost::asio::buffer(w.bytes()), to);
      if (i % 50 == 0) std::this_thread::sleep_for(5ms);
    }
    // Seen: the last change is in the state a client reads...
    bool seen = false;
    for (int i = 0; i < 200 && !seen; ++i) {
      auto state = call(port, "GET", "/api/state");
      ASSERT_TRUE(state && state->status == 200);
      const auto j = nlohmann::json::parse(state->body);
      for (const auto& l : j["layers"])
        if (l["id"] == 2 && std::abs(l["coverage"].get<double>() - last) < 1e-6) seen = true;
      if (!seen) std::this_thread::sleep_for(5ms);
    }
    ASSERT_TRUE(seen) << call(port, "GET", "/metrics")->body << server.log();
    // ... and SIGTERM at once, most likely inside the 50 ms commit batch.
    EXPECT_EQ(server.stop(), 0) << server.log();
  }
  ChildProcess again(args("1"), (dir / "weatherd.1.log").string());
  const unsigned port = waitForPortFile((dir / "http.1.port").string(), 20s);
  auto state = call(port, "GET", "/api/state");
  ASSERT_TRUE(state && state->status == 200) << again.log();
  const auto j = nlohmann::json::parse(state->body);
  bool found = false;
  for (const auto& l : j["layers"])
    if (l["id"] == 2) {
      found = true;
      EXPECT_NEAR(l["coverage"].get<double>(), last, 1e-6);
    }
  EXPECT_TRUE(found) << "the CIGI layer was lost";
}

}  // namespace
}  // namespace sky::test
