// Issue 18, storage and CIGI side: the event log's retention bound and a
// restore that loads no more than it; a corrupt or locked database refused at
// open naming the file; schedules bounded in time and count; the CIGI input's
// bounded senders and its batched commits (one transaction per burst, every
// accepted change on disk after the batch interval or close()). Real SQLite
// files, a real UDP-bound input, datagrams from the protocol encoder.
#include <sqlite3.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <string>

#include <gtest/gtest.h>

#include <boost/asio/io_context.hpp>

#include "sky/cigi/codec.hpp"
#include "sky/server/cigi_weather_input.hpp"
#include "sky/server/live_weather.hpp"
#include "sky/server/weather_store.hpp"
#include "store_files.hpp"

namespace fs = std::filesystem;
using namespace std::chrono_literals;

namespace sky::server {
namespace {

const WallClock::time_point kT0 = test::kStoreT0;

Scenario scenario() { return test::oneLayerScenario(); }

fs::path freshFile(const char* name) { return test::freshDatabase("skyshell-bounds-test", name); }

weather::CloudLayer layerWithCoverage(double coverage) {
  weather::CloudLayer l = scenario().layers[0];
  l.coverage = coverage;
  return l;
}

TEST(StoreBounds, TheEventLogKeepsTheNewestAndARestoreLoadsNoMore) {
  const fs::path file = freshFile("retention.db");
  auto store = WeatherStore::open(file);
  ASSERT_TRUE(store) << store.error().detail;
  const std::size_t total = kMaxStoredEvents + 500;
  // In batches, as the CIGI input commits them: the bound holds across both paths.
  std::vector<ChangeEvent> batch;
  for (std::size_t seq = 1; seq <= total; ++seq) {
    batch.push_back({seq, double(seq), 0, "test", "api", "event " + std::to_string(seq)});
    if (batch.size() == 250 || seq == total) {
      ASSERT_TRUE(store->save(nlohmann::json{{"x", seq}}, batch));
      batch.clear();
    }
  }
  EXPECT_EQ(store->storedEvents().value(), kMaxStoredEvents);
  auto saved = store->load();
  ASSERT_TRUE(saved && *saved);
  ASSERT_EQ((*saved)->events.size(), kMaxStoredEvents);
  EXPECT_EQ((*saved)->events.front().sequence, total - kMaxStoredEvents + 1);  // the oldest kept
  EXPECT_EQ((*saved)->events.back().sequence, total);
}

TEST(StoreBounds, GarbageBytesAreRefusedAsCorruptNamingTheFile) {
  const fs::path file = freshFile("garbage.db");
  {
    std::ofstream out(file, std::ios::binary);
    for (int i = 0; i < 4096; ++i) out.put(static_cast<char>((i * 131 + 7) & 0xff));
  }
  auto store = WeatherStore::open(file);
  ASSERT_FALSE(store);
  EXPECT_EQ(store.error().code, ErrorCode::Malformed);
  EXPECT_NE(store.error().detail.find(file.string()), std::string::npos) << store.error().detail;
  EXPECT_NE(store.error().detail.find("corrupt"), std::string::npos) << store.error().detail;
}

TEST(StoreBounds, ADatabaseLockedByAnotherConnectionIsRefusedAfterTheLockWait) {
  const fs::path file = freshFile("locked.db");
  ASSERT_TRUE(WeatherStore::open(file));  // made and closed: a valid database in WAL mode
  sqlite3* other = nullptr;
  ASSERT_EQ(sqlite3_open(file.c_str(), &other), SQLITE_OK);
  ASSERT_EQ(sqlite3_exec(other, "BEGIN EXCLUSIVE;", nullptr, nullptr, nullptr), SQLITE_OK);
  const auto started = std::chrono::steady_clock::now();
  auto store = WeatherStore::open(file, 300ms);
  const auto took = std::chrono::steady_clock::now() - started;
  ASSERT_FALSE(store);
  EXPECT_EQ(store.error().code, ErrorCode::Io);
  EXPECT_NE(store.error().detail.find(file.string()), std::string::npos) << store.error().detail;
  EXPECT_NE(store.error().detail.find("lock"), std::string::npos) << store.error().detail;
  EXPECT_GE(took, 300ms);  // it waited for the lock as long as told, no longer than a few times that
  EXPECT_LT(took, 3s);
  sqlite3_exec(other, "ROLLBACK;", nullptr, nullptr, nullptr);
  sqlite3_close(other);
  EXPECT_TRUE(WeatherStore::open(file, 300ms));  // free again
}

TEST(ScheduleBounds, AStartBeyondTheHorizonIsRefusedNamingTheField) {
  WallClock::time_point wall = kT0;
  LiveWeather w(scenario(), kT0, [&] { return wall; }, [] { return std::int64_t{0}; });
  const double now_s = w.clockNow();
  Timing far;
  far.at_s = now_s + 31 * 86400.0;
  auto r = w.submit({{SetLayer{layerWithCoverage(0.5), far}}, "test", "api"});
  ASSERT_FALSE(r);
  EXPECT_NE(r.error().detail.find("changes[0].at_s"), std::string::npos) << r.error().detail;
  EXPECT_NE(r.error().detail.find("30 days"), std::string::npos) << r.error().detail;
  Timing near;
  near.at_s = now_s + 29 * 86400.0;
  EXPECT_TRUE(w.submit({{SetLayer{layerWithCoverage(0.5), near}}, "test", "api"}));
}

TEST(ScheduleBounds, PendingRampsAreCapped) {
  WallClock::time_point wall = kT0;
  LiveWeather w(scenario(), kT0, [&] { return wall; }, [] { return std::int64_t{0}; });
  const double now_s = w.clockNow();
  // 256 changes a request (the request cap), each a future start: they wait.
  std::size_t accepted = 0;
  Result<AppliedChange> last = AppliedChange{};
  for (int request = 0; request < 8 && last; ++request) {
    ChangeRequest req{{}, "test", "api"};
    for (int i = 0; i < 256; ++i) {
      Timing t;
      t.at_s = now_s + 3600 + request * 256 + i;
      req.changes.push_back(SetLayer{layerWithCoverage(0.5), t});
    }
    last = w.submit(req);
    if (last) accepted += req.changes.size();
  }
  EXPECT_EQ(accepted, kMaxPendingRamps);
  ASSERT_FALSE(last);
  EXPECT_NE(last.error().detail.find("at most 1024"), std::string::npos) << last.error().detail;
}

// A batch of 256 changes names each in its summary (some 25 kB); the event
// keeps the first kMaxEventSummary_bytes, cut on a character boundary and
// saying how long the whole was, so that the event log stays readable and
// a NATS log entry carrying it stays within what followers read
// (kMaxLogEntryText).
TEST(ScheduleBounds, ALongSummaryIsCutInTheEvent) {
  WallClock::time_point wall = kT0;
  LiveWeather w(scenario(), kT0, [&] { return wall; }, [] { return std::int64_t{0}; });
  ChangeRequest req{{}, "test", "api"};
  for (int i = 0; i < 256; ++i) {
    weather::CloudLayer l = layerWithCoverage(0.5);
    l.id = 1 + i % 4;
    req.changes.push_back(SetLayer{l, {}});
  }
  auto r = w.submit(req);
  ASSERT_TRUE(r) << r.error().detail;
  const auto events = w.events(1);
  ASSERT_EQ(events.size(), 1u);
  const std::string& s = events[0].summary;
  EXPECT_LE(s.size(), kMaxEventSummary_bytes);
  EXPECT_GT(s.size(), kMaxEventSummary_bytes - 100);
  EXPECT_NE(s.find(" bytes in all)"), std::string::npos) << s;
  EXPECT_EQ(s.rfind("layer 1 ", 0), 0u) << "the summary's start is kept: " << s.substr(0, 80);
  EXPECT_EQ(r->summary, s);
  // A short one is kept whole.
  auto one = w.submit({{SetLayer{layerWithCoverage(0.4), {}}}, "test", "api"});
  ASSERT_TRUE(one);
  EXPECT_EQ(w.events(1)[0].summary.find("bytes in all"), std::string::npos) << w.events(1)[0].summary;
}

std::vector<std::uint8_t> weatherDatagram(double coverage_pct) {
  cigi::DatagramWriter w(cigi::ByteOrder::Big);
  w.add(cigi::IgControl{});
  cigi::WeatherControl wc;
  wc.layerId = cigi::LayerId::CloudLayer2;
  wc.cloudType = weather::CloudType::Stratocumulus;
  wc.coverage_pct = static_cast<float>(coverage_pct);
  wc.baseElevation_m = 1500;
  wc.thickness_m = 800;
  wc.transitionBand_m = 100;
  w.add(wc);
  return w.bytes();
}

struct CigiRig {
  boost::asio::io_context io;
  WallClock::time_point wall = kT0;
  LiveWeather weather{scenario(), kT0, [this] { return wall; }, [] { return std::int64_t{0}; }};
  std::unique_ptr<CigiWeatherInput> input;
  Rejections rejections;

  void start() {
    auto made = CigiWeatherInput::create(io, "127.0.0.1", 0, weather, &rejections, nullptr);
    ASSERT_TRUE(made) << made.error().detail;
    input = std::move(*made);
  }
};

TEST(CigiBounds, SendersAreCappedAndIdleOnesForgotten) {
  CigiRig rig;
  rig.start();
  const auto datagram = weatherDatagram(50);
  for (std::size_t i = 0; i < kMaxCigiSenders + 1000; ++i)
    rig.input->onDatagram(datagram, "10.0.0.1:" + std::to_string(10000 + i));
  EXPECT_EQ(rig.input->senders(), kMaxCigiSenders);
  EXPECT_EQ(rig.input->counters().senderRefused, 1000u);
  EXPECT_EQ(rig.rejections.get(RejectReason::CigiRefused), 1000u);
  // A known sender is still served while the input is full.
  rig.input->onDatagram(weatherDatagram(60), "10.0.0.1:10000");
  EXPECT_DOUBLE_EQ(rig.weather.view().layers.back().coverage, 0.6);
  rig.input->close();
}

TEST(CigiBounds, ABurstIsOneCommitAndEveryChangeIsOnDiskAfterTheBatch) {
  const fs::path file = freshFile("cigi-batch.db");
  auto store = WeatherStore::open(file);
  ASSERT_TRUE(store) << store.error().detail;
  CigiRig rig;
  rig.weather.attachStore(&*store);
  rig.start();
  const int burst = 100;
  for (int i = 1; i <= burst; ++i) rig.input->onDatagram(weatherDatagram(i % 2 ? 40 : 70), "127.0.0.1:5000");
  EXPECT_EQ(rig.input->counters().applied, std::uint64_t(burst));
  EXPECT_EQ(rig.weather.commitStats().count, 0u);  // nothing waited for a disk
  EXPECT_EQ(rig.weather.unsaved(), std::size_t(burst));
  rig.io.run_for(kCigiCommitBatch * 4);
  EXPECT_EQ(rig.input->counters().commits, 1u);  // the whole burst in one transaction
  EXPECT_EQ(rig.weather.unsaved(), 0u);
  EXPECT_EQ(store->storedEvents().value(), std::size_t(burst));
  // A change after the batch, then close(): close commits it without waiting.
  rig.input->onDatagram(weatherDatagram(55), "127.0.0.1:5000");
  rig.input->close();
  EXPECT_EQ(store->storedEvents().value(), std::size_t(burst + 1));
  auto saved = store->load();
  ASSERT_TRUE(saved && *saved);
  EXPECT_EQ((*saved)->state.at("sequence").get<std::uint64_t>(), std::uint64_t(burst + 1));
}

TEST(CigiBounds, AnApiCommitTakesTheBatchedChangesAlong) {
  const fs::path file = freshFile("cigi-api.db");
  auto store = WeatherStore::open(file);
  ASSERT_TRUE(store) << store.error().detail;
  CigiRig rig;
  rig.weather.attachStore(&*store);
  rig.start();
  rig.input->onDatagram(weatherDatagram(40), "127.0.0.1:5000");
  ASSERT_EQ(rig.weather.unsaved(), 1u);
  // The HTTP path: on disk before it returns, and so is the CIGI change before it.
  ASSERT_TRUE(rig.weather.submit({{SetLayer{layerWithCoverage(0.8), {}}}, "test", "api"}));
  EXPECT_EQ(rig.weather.unsaved(), 0u);
  EXPECT_EQ(store->storedEvents().value(), 2u);
  rig.input->close();
}

TEST(CigiBounds, HostileDatagramsAreDroppedAndCounted) {
  CigiRig rig;
  rig.start();
  auto good = weatherDatagram(50);
  // Every size byte of the second packet: 0 (would loop forever if trusted),
  // 1, and past the end of the datagram.
  const std::size_t sizeAt = good.size() - 56 + 1;  // the Weather Control's size byte (56-byte packet)
  for (int size : {0, 1, 2, 255}) {
    auto bad = good;
    bad[sizeAt] = static_cast<std::uint8_t>(size);
    rig.input->onDatagram(bad, "127.0.0.1:5000");
  }
  rig.input->onDatagram(std::vector<std::uint8_t>{}, "127.0.0.1:5000");
  rig.input->onDatagram(std::vector<std::uint8_t>(1, 0x01), "127.0.0.1:5000");
  EXPECT_GE(rig.input->counters().malformed, 5u);
  EXPECT_EQ(rig.input->counters().applied, 0u);
  rig.input->onDatagram(good, "127.0.0.1:5000");
  EXPECT_EQ(rig.input->counters().applied, 1u);
  rig.input->close();
}

}  // namespace
}  // namespace sky::server
