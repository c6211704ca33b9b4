// The weather a running server owns and changes: global layers, regions (with
// their own layers, optionally drifting with their wind) and the weather
// clock, changed through the WeatherService vocabulary (change.hpp) with
// scheduled starts and ramps on the weather clock. With a WeatherStore
// attached every accepted change is on disk before it is acknowledged.
#pragma once

#include <cstdint>
#include <functional>
#include <map>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "sky/server/change.hpp"
#include "sky/server/forecast.hpp"
#include "sky/server/scenario.hpp"
#include "sky/server/weather_clock.hpp"

namespace sky::server {

// Changes scheduled or ramping at once (layer and region ramps together).
// Each holds two layers or regions in memory and in every saved state; a
// cockpit's weather has a few, a scenario at most kMaxTimelineEntries (1024)
// waiting in its timeline (not ramps), so 1024 is far above use and bounds
// the state's size.
inline constexpr std::size_t kMaxPendingRamps = 1024;
// Batched (CIGI) changes that may wait for their commit before a batched
// submit commits at once: bounds memory when commits keep failing.
inline constexpr std::size_t kMaxUnsavedEvents = 256;

// A forecast as the live weather holds it (live_forecast.cpp): the decoded
// layers, where they sit on the weather clock, and the GRIB files they came
// from (kept in the store by key, so a restart decodes them again).
struct LoadedForecast {
  std::shared_ptr<const Forecast> forecast;
  ForecastPlacement placement;
  struct File {
    std::string key;   // the store's key of the file's bytes (weather_store.hpp)
    std::string name;  // as the operator named it: a file name, never a path
  };
  std::vector<File> files;
  std::uint64_t serial = 0;  // set by loadForecast: a new load, a new number
};

// A loaded forecast as the saved state and GET /api/state show it: null, or
// its name, files (key, name), placement, steps and notes. What restore
// needs back is forecastFilesFromJson's and forecastPlacementFromJson's.
nlohmann::json forecastJson(const LoadedForecast* forecast);
Result<std::vector<LoadedForecast::File>> forecastFilesFromJson(const nlohmann::json& saved);
Result<ForecastPlacement> forecastPlacementFromJson(const nlohmann::json& saved);

class LiveWeather;
// GET /api/state's body, and the console feed's state: the view (api_json's
// toJson) with the forecast.
nlohmann::json apiStateJson(const LiveWeather& weather);

class LiveWeather final : public WeatherService {
 public:
  using WallNow = std::function<WallClock::time_point()>;
  using UnixNowMs = std::function<std::int64_t()>;

  // The scenario's weather, its clock at scenario.clock.start_s at wallStart.
  LiveWeather(const Scenario& scenario, WallClock::time_point wallStart, WallNow wallNow, UnixNowMs unixNowMs);

  Result<AppliedChange> submit(const ChangeRequest& request) override;
  // Applied now, on disk with the next flush() or submit() (change.hpp).
  // With more than kMaxUnsavedEvents changes waiting (the disk keeps
  // failing), it commits at once like submit, and fails like it.
  Result<AppliedChange> submitBatched(const ChangeRequest& request) override;
  Result<void> flush() override;
  // Changes applied by submitBatched and not yet on disk.
  std::size_t unsaved() const { return unsaved_.size(); }
  WeatherView view() const override;

  // Scenario timelines (live_timeline.cpp). An entry waits here until the
  // weather clock reaches its at_s, then is submitted like any change.
  struct TimelineItem {
    double at_s = 0;       // weather clock
    WeatherChange change;  // timing: no at_s (it starts when made), the entry's ramp_s
    std::string where;     // "file:line:col: timeline[i]"
    std::string scenario;  // the scenario's name (its file, or what POST /api/scenario named it)
    std::string summary;   // what it will do, for GET /api/state's pending list
  };
  // Replaces the weather with the scenario's start (its layers and no
  // others, no regions, the clock at clock.start_s and its rate) and its
  // timeline, as one accepted change, all or nothing. Each timeline entry is
  // first tried against the weather it would meet at its time if nothing
  // else changed meanwhile: one the model would refuse refuses the scenario
  // (InvalidArgument naming the entry's file, line and field).
  Result<AppliedChange> loadScenario(const Scenario& scenario, const std::string& name, const std::string& author);
  // At start, for the scenario the constructor was given: its timeline,
  // checked the same way. Not a change (no event); with a store, the caller
  // saves the initial state after this.
  Result<void> scheduleTimeline(const Scenario& scenario, const std::string& name);
  // When the next timeline entry is due (weather clock), if one waits.
  std::optional<double> nextTimelineAt() const;
  struct TimelineOutcome {
    double at_s = 0;
    std::string where;
    Result<AppliedChange> result;  // what submitting it gave
  };
  // Submits every due entry (at_s reached) in order, the entries of one
  // at_s as one batch (source "scenario", author "scenario:<name>"), each
  // removed from the timeline in the same commit. A batch the model refuses
  // now (the weather moved on since it was checked) is dropped: its outcome
  // says why.
  std::vector<TimelineOutcome> runTimeline();

  // Forecasts (live_forecast.cpp). Loading one is one accepted change: the
  // forecast's layers (slots 30-34, forecast.hpp) become global layers,
  // replacing the layers of those ids (and the forecast loaded before); its
  // valid time is placement.anchorValid_unix at placement.anchorClock_s.
  // Removing it removes its layers. With a store, the files' bytes must be
  // in it (WeatherStore::putFile) before; files no state names are pruned
  // after the commit.
  Result<AppliedChange> loadForecast(LoadedForecast forecast, const std::string& author, const std::string& source);
  Result<AppliedChange> removeForecast(const std::string& author, const std::string& source);
  // The forecast loaded, if any, and the field its tiles come from at clock c.
  std::shared_ptr<const LoadedForecast> forecast() const { return forecast_; }
  std::shared_ptr<const ForecastField> fieldAt(double clock_s) const;
  // Decodes a saved state's forecast (its "forecast" JSON) for restore.
  using ForecastLoader = std::function<Result<LoadedForecast>(const nlohmann::json& saved)>;
  const std::vector<TimelineItem>& timeline() const { return timeline_; }
  std::vector<ChangeEvent> events(std::size_t limit) const override;

  double clockNow() const { return clock_.at(wallNow_()); }
  const WeatherClock& clock() const { return clock_; }
  // The layers as they stand at weather clock c (ramps evaluated).
  std::vector<weather::CloudLayer> layersAt(double clock_s) const;
  // The regions as they stand at weather clock c (ramps evaluated, drifting
  // regions carried by their wind to c), by id.
  std::vector<weather::Region> regionsAt(double clock_s) const;
  // Whether a scheduled or ramping change is still under way at clock c: the
  // stream then refreshes its subscribers as the weather moves.
  bool changing(double clock_s) const;
  // Whether a ramp is running at clock c (started, not ended): the weather
  // moves continuously, and the console's state follows it.
  bool rampRunning(double clock_s) const;
  // Whether a region drifts with a wind while the clock runs: its position
  // in the state moves continuously.
  bool drifting(double clock_s) const;
  std::uint64_t rejected() const { return rejected_; }
  // Changes accepted since this object was made (every input).
  std::uint64_t accepted() const { return accepted_; }

  // Called on the io thread after every accepted change from any input, once
  // it is committed and applied: the stream and the console push it on.
  using Listener = std::function<void(const ChangeEvent&)>;
  std::size_t addListener(Listener listener);  // returns an id for removeListener
  void removeListener(std::size_t id);
  // Tells the listeners of a change accepted elsewhere and restored here (a
  // follower folding its leader's log), as if accepted here.
  void announce(const ChangeEvent& event);
  // Commits to the store: how many, and their total and longest duration.
  struct CommitStats {
    std::uint64_t count = 0;
    double total_s = 0, max_s = 0;
  };
  const CommitStats& commitStats() const { return commitStats_; }

  // Durability: with a store attached, every accepted change is committed to
  // it (state and event, one transaction) before submit returns; a failed
  // commit refuses the change (Io) and leaves the state as it was.
  void attachStore(class WeatherStore* store) { store_ = store; }
  class WeatherStore* store() const { return store_; }
  // Replication (nats_weather.hpp): with a committer attached, every accepted
  // change (batched ones too: a replicated log has no later flush) is handed
  // to it, the whole state it makes and its event, before it is applied; an
  // error from it refuses the change and leaves the state as it was. Used
  // instead of a store.
  using Committer = std::function<Result<void>(const nlohmann::json& state, const ChangeEvent& event)>;
  void attachCommitter(Committer committer) { committer_ = std::move(committer); }
  // A loaded forecast's files go to the keeper, when one is attached,
  // before the change that loads it is committed (applyForecast): the NATS
  // cluster's files stream, from which the followers decode it again.
  using FileKeeper = std::function<Result<void>(const std::string& key, std::span<const std::byte> bytes)>;
  void attachFileKeeper(FileKeeper keeper) { fileKeeper_ = std::move(keeper); }
  const FileKeeper& fileKeeper() const { return fileKeeper_; }
  // While held, no timeline entry is ever due: a follower keeps its leader's
  // timeline in its state but only the leader runs it.
  void holdTimeline(bool held) { timelineHeld_ = held; }
  bool timelineHeld() const { return timelineHeld_; }
  // The whole state as JSON: layers, ramps in progress, sequence, version,
  // and the clock as (clock_s, rate) at unix_ms.
  nlohmann::json toJson() const;
  // Replaces the state with a saved one; the weather clock goes on from the
  // saved value at its rate for the time the server was down (the weather
  // outside did not stop). Malformed when the JSON is not a saved state.
  // A saved forecast is decoded again by `loader` (none: the state must
  // have no forecast).
  Result<void> restore(const nlohmann::json& state, std::vector<ChangeEvent> events,
                       const ForecastLoader& loader = {});
  // Whether restore would keep the forecast held for this saved one (the
  // same files at the same place on the clock) rather than decode it.
  bool holdsForecast(const nlohmann::json& saved) const;
  // FNV-1a of the canonical state without the clock's position (layers,
  // ramps, sequence, clock rate): equal before a shutdown and after restore.
  std::uint64_t stateHash() const;

 private:
  struct Ramp {
    std::uint64_t sequence = 0;
    std::uint32_t layerId = 0;
    double start_s = 0, end_s = 0;
    bool fromAbsent = false;  // a new layer: ramps in from coverage 0
    weather::CloudLayer from, to;
    bool removeAtEnd = false;
    std::string summary;
  };
  // A region appearing, changing or going: geometry and layers interpolate
  // from `from` (a new region grows from zero size) to `to`.
  struct RegionRamp {
    std::uint64_t sequence = 0;
    std::uint32_t regionId = 0;
    double start_s = 0, end_s = 0;
    bool fromAbsent = false;
    weather::Region from, to;  // placed (placedAtClock_s) where they drift from
    bool removeAtEnd = false;
    std::string summary;
  };
  struct State {
    std::map<std::uint32_t, weather::CloudLayer> layers;  // settled values
    std::vector<Ramp> ramps;                              // in submission order
    std::map<std::uint32_t, weather::Region> regions;     // settled
    std::vector<RegionRamp> regionRamps;                  // in submission order
    WeatherClock clock;
    std::shared_ptr<const LoadedForecast> forecast;
  };
  State state() const { return State{layers_, ramps_, regions_, regionRamps_, clock_, forecast_}; }
  static std::vector<weather::CloudLayer> evaluate(const State& s, double clock_s);
  static std::vector<weather::Region> evaluateRegions(const State& s, double clock_s);
  static std::optional<weather::Region> evaluateRegion(const State& s, std::uint32_t id, double clock_s);
  Result<std::string> applyRegion(State& s, const WeatherChange& change, const std::string& at, double now_s,
                                  std::uint64_t sequence) const;
  // `at` names the change in errors ("changes[2]").
  Result<std::string> apply(State& s, const WeatherChange& change, const std::string& at, double now_s,
                            std::uint64_t sequence) const;
  void settle(double clock_s);
  // Commits `next` (with `timeline` as the timeline to come) and its event,
  // then makes it the weather and tells the listeners.
  // durableNow false (a batched submit): applied, its event kept in unsaved_
  // for the next commit.
  Result<AppliedChange> commit(State next, std::vector<TimelineItem> timeline, const std::string& author,
                               const std::string& source, const std::string& summary, double now_s,
                               bool durableNow = true);
  Result<AppliedChange> submitImpl(const ChangeRequest& request, bool durableNow);
  Result<void> dryRun(State s, const std::vector<TimelineItem>& items) const;
  static std::vector<TimelineItem> timelineItems(const Scenario& scenario, const std::string& name);
  static nlohmann::json timelineJson(const std::vector<TimelineItem>& timeline);
  static Result<std::vector<TimelineItem>> timelineFromJson(const nlohmann::json& j);
  static double rampOf(const WeatherChange& change);
  nlohmann::json stateJson(const State& s, const std::vector<TimelineItem>& timeline, std::uint64_t sequence,
                           std::uint64_t version) const;

  WallNow wallNow_;
  UnixNowMs unixNowMs_;
  std::map<std::uint32_t, weather::CloudLayer> layers_;
  std::vector<Ramp> ramps_;
  std::map<std::uint32_t, weather::Region> regions_;
  std::vector<RegionRamp> regionRamps_;
  WeatherClock clock_;
  std::shared_ptr<const LoadedForecast> forecast_;
  std::uint64_t forecastSerial_ = 0;
  std::vector<TimelineItem> timeline_;  // by at_s
  std::vector<ChangeEvent> events_;
  std::vector<ChangeEvent> unsaved_;  // applied by submitBatched, not yet on disk (oldest first)
  std::uint64_t sequence_ = 0;
  std::uint64_t version_ = 1;
  std::uint64_t rejected_ = 0;
  std::uint64_t accepted_ = 0;
  std::map<std::size_t, Listener> listeners_;  // by id, called in id order
  std::size_t nextListenerId_ = 1;
  CommitStats commitStats_;
  class WeatherStore* store_ = nullptr;
  Committer committer_;
  FileKeeper fileKeeper_;
  bool timelineHeld_ = false;
};

}  // namespace sky::server
