// The NATS change log's entries (nats_entry.hpp): what a leader writes reads
// back to the same state, and what another process could have written wrong
// is refused with a reason, never thrown or half-read. And the live
// weather's committer, the hook the NATS mode appends through: a refusal
// leaves the weather as it was, a batched (CIGI) change goes through it too,
// a state folded from the log restores to the leader's state hash and is
// announced to the follower's listeners, and a held timeline never fires.
#include <gtest/gtest.h>

#include "sky/server/live_weather.hpp"
#include "sky/server/nats_entry.hpp"

namespace sky::server {
namespace {

using namespace std::chrono_literals;

const WallClock::time_point kT0{std::chrono::hours(1000)};

weather::CloudLayer stratus(std::uint32_t id, double coverage) {
  weather::CloudLayer l;
  l.id = id;
  l.type = weather::CloudType::Stratus;
  l.base_m = 400;
  l.thickness_m = 300;
  l.coverage = coverage;
  l.density = 0.7;
  l.wind = {5, 200, 0};
  return l;
}

struct Fixture {
  WallClock::time_point now = kT0;
  LiveWeather weather;
  Fixture()
      : weather(
            [] {
              Scenario s;
              s.clock = {1000.0, 1.0};
              s.layers = {stratus(1, 0.3)};
              return s;
            }(),
            kT0, [this] { return now; }, [] { return std::int64_t{1700000000000}; }) {}
  ChangeRequest one(WeatherChange c) { return ChangeRequest{{std::move(c)}, "test", "api"}; }
};

LogEntry sampleEntry(const LiveWeather& w) {
  LogEntry e;
  e.kind = LogEntry::Kind::Change;
  e.term = 42;
  e.leaderId = "skyshell-weatherd@host:123";
  e.leaderApi = "http://127.0.0.1:8080";
  e.state = w.toJson();
  e.event = ChangeEvent{7, 1003.5, 1700000000123, "console", "api", "layer 2 (stratus) added, coverage 0.00 -> 0.80"};
  return e;
}

TEST(NatsLogEntry, RoundTrips) {
  Fixture f;
  const LogEntry e = sampleEntry(f.weather);
  auto back = decodeLogEntry(encodeLogEntry(e));
  ASSERT_TRUE(back) << describe(back.error());
  EXPECT_EQ(back->kind, LogEntry::Kind::Change);
  EXPECT_EQ(back->term, 42u);
  EXPECT_EQ(back->leaderId, e.leaderId);
  EXPECT_EQ(back->leaderApi, e.leaderApi);
  EXPECT_EQ(back->state, e.state);
  ASSERT_TRUE(back->event);
  EXPECT_EQ(back->event->sequence, 7u);
  EXPECT_DOUBLE_EQ(back->event->clock_s, 1003.5);
  EXPECT_EQ(back->event->wallTime_ms, 1700000000123);
  EXPECT_EQ(back->event->summary, e.event->summary);

  LogEntry term = e;
  term.kind = LogEntry::Kind::Term;
  term.event.reset();
  auto termBack = decodeLogEntry(encodeLogEntry(term));
  ASSERT_TRUE(termBack) << describe(termBack.error());
  EXPECT_EQ(termBack->kind, LogEntry::Kind::Term);
  EXPECT_FALSE(termBack->event);
}

// A state too large for an entry: the entry names its file (key and size)
// and carries no state; the key is the state's content key.
TEST(NatsLogEntry, AStateFileIsNamedNotCarried) {
  Fixture f;
  LogEntry e = sampleEntry(f.weather);
  const std::string json = e.state.dump();
  e.stateFile = LogEntry::StateFile{stateFileKey(json), json.size()};
  e.state = nullptr;
  auto back = decodeLogEntry(encodeLogEntry(e));
  ASSERT_TRUE(back) << describe(back.error());
  ASSERT_TRUE(back->stateFile);
  EXPECT_EQ(back->stateFile->key, e.stateFile->key);
  EXPECT_EQ(back->stateFile->bytes, json.size());
  EXPECT_TRUE(back->state.is_null());
  EXPECT_EQ(e.stateFile->key.rfind("state-", 0), 0u);
  EXPECT_NE(stateFileKey(json + " "), e.stateFile->key);

  const nlohmann::json good = nlohmann::json::parse(encodeLogEntry(e));
  auto with = [&](auto edit) {
    nlohmann::json j = good;
    edit(j);
    return decodeLogEntry(j.dump());
  };
  EXPECT_EQ(with([](auto& j) { j["state_file"]["key"] = "0123-45"; }).error().code, ErrorCode::Malformed);
  EXPECT_EQ(with([](auto& j) { j["state_file"]["key"] = "state-a.b"; }).error().code, ErrorCode::Malformed);
  EXPECT_EQ(with([](auto& j) { j["state_file"]["key"] = "state->"; }).error().code, ErrorCode::Malformed);
  EXPECT_EQ(with([](auto& j) { j["state_file"]["bytes"] = -1; }).error().code, ErrorCode::Malformed);
  EXPECT_EQ(with([](auto& j) { j["state_file"]["bytes"] = kMaxStateFile_bytes + 1; }).error().code,
            ErrorCode::TooLarge);
  EXPECT_EQ(with([](auto& j) { j["state_file"] = "state-1"; }).error().code, ErrorCode::Malformed);
  EXPECT_EQ(with([&](auto& j) { j["state"] = f.weather.toJson(); }).error().code, ErrorCode::Malformed)
      << "both a state and a state file";
}

TEST(NatsLogEntry, RefusesWhatALeaderNeverWrites) {
  Fixture f;
  const nlohmann::json good = nlohmann::json::parse(encodeLogEntry(sampleEntry(f.weather)));
  auto with = [&](auto edit) {
    nlohmann::json j = good;
    edit(j);
    return decodeLogEntry(j.dump());
  };
  EXPECT_EQ(decodeLogEntry("").error().code, ErrorCode::Malformed);
  EXPECT_EQ(decodeLogEntry("{\"format\": 1").error().code, ErrorCode::Malformed);
  EXPECT_EQ(decodeLogEntry("[1, 2]").error().code, ErrorCode::Malformed);
  EXPECT_EQ(with([](auto& j) { j["format"] = 2; }).error().code, ErrorCode::Unsupported);
  EXPECT_EQ(with([](auto& j) { j.erase("format"); }).error().code, ErrorCode::Unsupported);
  EXPECT_EQ(with([](auto& j) { j["kind"] = "snapshot"; }).error().code, ErrorCode::Malformed);
  EXPECT_EQ(with([](auto& j) { j["term"] = 0; }).error().code, ErrorCode::Malformed);
  EXPECT_EQ(with([](auto& j) { j["term"] = -3; }).error().code, ErrorCode::Malformed);
  EXPECT_EQ(with([](auto& j) { j["term"] = "7"; }).error().code, ErrorCode::Malformed);
  EXPECT_EQ(with([](auto& j) { j["state"] = "{}"; }).error().code, ErrorCode::Malformed);
  EXPECT_EQ(with([](auto& j) { j.erase("event"); }).error().code, ErrorCode::Malformed);
  EXPECT_EQ(with([](auto& j) { j["kind"] = "term"; }).error().code, ErrorCode::Malformed);  // with an event
  EXPECT_EQ(with([](auto& j) { j["event"]["clock_s"] = "now"; }).error().code, ErrorCode::Malformed);
  EXPECT_EQ(with([](auto& j) { j["event"]["wall_ms"] = 1.5; }).error().code, ErrorCode::Malformed);
  EXPECT_EQ(with([](auto& j) { j["event"]["summary"] = 3; }).error().code, ErrorCode::Malformed);
  EXPECT_EQ(with([](auto& j) { j["leader"] = std::string(kMaxLogEntryText + 1, 'x'); }).error().code,
            ErrorCode::TooLarge);
  EXPECT_EQ(decodeLogEntry(std::string(kMaxLogEntry_bytes + 1, ' ')).error().code, ErrorCode::TooLarge);
  // Nesting far deeper than any state: refused as not an entry, not a crash.
  EXPECT_FALSE(decodeLogEntry(std::string(100000, '[') + std::string(100000, ']')));
}

TEST(LiveWeatherCommitter, ARefusalLeavesTheWeatherAsItWas) {
  Fixture f;
  const std::uint64_t before = f.weather.stateHash();
  f.weather.attachCommitter([](const nlohmann::json&, const ChangeEvent&) -> Result<void> {
    return fail(ErrorCode::Io, "not the leader: b leads");
  });
  auto refused = f.weather.submit(f.one(SetLayer{stratus(2, 0.8), Timing{}}));
  ASSERT_FALSE(refused);
  EXPECT_EQ(refused.error().detail, "not the leader: b leads");
  EXPECT_EQ(f.weather.stateHash(), before);
  EXPECT_EQ(f.weather.view().lastSequence, 0u);
  EXPECT_FALSE(f.weather.submitBatched(f.one(SetLayer{stratus(2, 0.8), Timing{}})));
  EXPECT_EQ(f.weather.stateHash(), before);
}

TEST(LiveWeatherCommitter, EveryChangeBatchedOrNotIsHandedOverAndFoldsToTheSameState) {
  Fixture leader, follower;
  std::vector<std::pair<nlohmann::json, ChangeEvent>> log;
  leader.weather.attachCommitter([&](const nlohmann::json& state, const ChangeEvent& e) -> Result<void> {
    log.emplace_back(state, e);
    return {};
  });
  ASSERT_TRUE(leader.weather.submit(leader.one(SetLayer{stratus(2, 0.8), Timing{std::nullopt, 600}})));
  ASSERT_TRUE(leader.weather.submitBatched(leader.one(RemoveLayer{1, Timing{}})));
  ASSERT_EQ(log.size(), 2u);
  EXPECT_EQ(log[1].second.sequence, 2u);
  EXPECT_EQ(leader.weather.unsaved(), 0u);
  // The follower folds the last entry (through the bytes, as over NATS).
  LogEntry e{LogEntry::Kind::Change, 1, "a", "", log.back().first, log.back().second, std::nullopt};
  auto read = decodeLogEntry(encodeLogEntry(e));
  ASSERT_TRUE(read);
  ASSERT_TRUE(follower.weather.restore(read->state, {*read->event}));
  EXPECT_EQ(follower.weather.stateHash(), leader.weather.stateHash());
  EXPECT_EQ(follower.weather.view().lastSequence, 2u);
  // The follower's consoles and subscribers hear of it as of a change made there.
  std::vector<std::uint64_t> heard;
  follower.weather.addListener([&](const ChangeEvent& c) { heard.push_back(c.sequence); });
  follower.weather.announce(*read->event);
  EXPECT_EQ(heard, std::vector<std::uint64_t>{2});
}

TEST(LiveWeatherCommitter, AHeldTimelineIsNeverDue) {
  Fixture f;
  Scenario s;
  s.clock = {1000.0, 1.0};
  s.layers = {stratus(1, 0.3)};
  weather::TimelineEntry entry;
  entry.at_s = 1001.0;
  entry.op = weather::TimelineEntry::Op::SetLayer;
  entry.layer = stratus(3, 0.5);
  entry.where = "test:1:1";
  s.timeline.push_back(entry);
  ASSERT_TRUE(f.weather.scheduleTimeline(s, "t"));
  ASSERT_TRUE(f.weather.nextTimelineAt());
  f.weather.holdTimeline(true);
  f.now = kT0 + 5s;
  EXPECT_FALSE(f.weather.nextTimelineAt());
  EXPECT_TRUE(f.weather.runTimeline().empty());
  EXPECT_EQ(f.weather.timeline().size(), 1u);
  f.weather.holdTimeline(false);
  EXPECT_EQ(f.weather.runTimeline().size(), 1u);
}

}  // namespace
}  // namespace sky::server
