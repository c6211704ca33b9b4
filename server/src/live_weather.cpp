// The server's live weather (see live_weather.hpp).
#include "sky/server/live_weather.hpp"

#include "sky/core/utf8.hpp"
#include "sky/server/api_json.hpp"
#include "sky/server/weather_store.hpp"
#include "ramp_math.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>

namespace sky::server {

namespace {

// Events kept in memory for /api/events.
constexpr std::size_t kMaxEvents = 10000;

std::string fmt(const char* f, double v) {
  char buf[64];
  std::snprintf(buf, sizeof buf, f, v);
  return buf;
}

}  // namespace

LiveWeather::LiveWeather(const Scenario& scenario, WallClock::time_point wallStart, WallNow wallNow,
                         UnixNowMs unixNowMs)
    : wallNow_(std::move(wallNow)),
      unixNowMs_(std::move(unixNowMs)),
      clock_(scenario.clock.start_s, scenario.clock.rate, wallStart) {
  for (const auto& l : scenario.layers) layers_[l.id] = l;
}

std::vector<weather::CloudLayer> LiveWeather::evaluate(const State& s, double c) {
  std::map<std::uint32_t, weather::CloudLayer> out = s.layers;
  std::map<std::uint32_t, bool> present;
  for (const auto& [id, l] : out) present[id] = true;
  for (const Ramp& r : s.ramps) {
    if (c < r.start_s) continue;
    const double f = r.end_s > r.start_s ? std::clamp((c - r.start_s) / (r.end_s - r.start_s), 0.0, 1.0) : 1.0;
    if (f >= 1.0 && r.removeAtEnd) {
      out.erase(r.layerId);
      continue;
    }
    weather::CloudLayer from = r.from;
    if (r.fromAbsent) {
      from = r.to;
      from.coverage = 0;
    }
    out[r.layerId] = lerpLayer(from, r.to, f);
  }
  std::vector<weather::CloudLayer> v;
  for (auto& [id, l] : out) v.push_back(l);
  return v;
}

std::vector<weather::CloudLayer> LiveWeather::layersAt(double clock_s) const {
  return evaluate(state(), clock_s);
}

bool LiveWeather::changing(double clock_s) const {
  for (const Ramp& r : ramps_)
    if (clock_s < r.end_s || (r.end_s == r.start_s && clock_s < r.start_s)) return true;
  for (const RegionRamp& r : regionRamps_)
    if (clock_s < r.end_s || (r.end_s == r.start_s && clock_s < r.start_s)) return true;
  // A forecast between two of its steps evolves with the clock.
  if (forecast_ && clock_.rate() > 0 && forecast_->forecast->stepCount() > 1) {
    const double valid = forecast_->placement.validAt(clock_s);
    if (valid < static_cast<double>(forecast_->forecast->lastValid_unix()) &&
        valid > static_cast<double>(forecast_->forecast->firstValid_unix()) - kForecastTimeQuantum_s)
      return true;
  }
  return false;
}

void LiveWeather::settle(double c) {
  // Ramps that have ended become the settled state, in order.
  std::vector<Ramp> still;
  for (const Ramp& r : ramps_) {
    if (c < r.end_s || c < r.start_s) {
      still.push_back(r);
      continue;
    }
    if (r.removeAtEnd)
      layers_.erase(r.layerId);
    else
      layers_[r.layerId] = r.to;
  }
  ramps_ = std::move(still);
  std::vector<RegionRamp> stillRegions;
  for (const RegionRamp& r : regionRamps_) {
    if (c < r.end_s || c < r.start_s) {
      stillRegions.push_back(r);
      continue;
    }
    if (r.removeAtEnd)
      regions_.erase(r.regionId);
    else
      regions_[r.regionId] = r.to;
  }
  regionRamps_ = std::move(stillRegions);
}

Result<std::string> LiveWeather::apply(State& s, const WeatherChange& change, const std::string& at, double now_s,
                                       std::uint64_t sequence) const {
  if (const auto* set = std::get_if<SetLayer>(&change)) {
    if (auto ok = checkTiming(set->timing, at, now_s); !ok) return tl::unexpected(ok.error());
    if (auto ok = weather::validate(set->layer); !ok)
      return fail(ErrorCode::InvalidArgument, at + ".layer: " + ok.error().detail);
    const auto current = evaluate(s, set->timing.at_s.value_or(now_s));
    const auto it = std::find_if(current.begin(), current.end(),
                                 [&](const weather::CloudLayer& l) { return l.id == set->layer.id; });
    if (it == current.end()) {
      auto withNew = current;
      withNew.push_back(set->layer);
      const std::size_t ids = distinctLayerIds(withNew, evaluateRegions(s, set->timing.at_s.value_or(now_s)));
      if (ids > kMaxScenarioLayers)
        return fail(ErrorCode::InvalidArgument,
                    at + ".layer.id: " + std::to_string(set->layer.id) + " would be layer " + std::to_string(ids) +
                        " (global and regional), at most " + std::to_string(kMaxScenarioLayers));
    }
    Ramp r;
    r.sequence = sequence;
    r.layerId = set->layer.id;
    r.start_s = set->timing.at_s.value_or(now_s);
    r.end_s = r.start_s + set->timing.ramp_s;
    r.fromAbsent = it == current.end();
    if (!r.fromAbsent) r.from = *it;
    r.to = set->layer;
    const double fromCoverage = r.fromAbsent ? 0.0 : r.from.coverage;
    r.summary = "layer " + std::to_string(r.layerId) + " (" + std::string(weather::toString(r.to.type)) + ") " +
                (r.fromAbsent ? "added, " : "") + "coverage " + fmt("%.2f", fromCoverage) + " -> " +
                fmt("%.2f", r.to.coverage) +
                (set->timing.ramp_s > 0 ? " over " + fmt("%.0f", set->timing.ramp_s) + " s" : "") +
                (set->timing.at_s ? " from clock " + fmt("%.0f", r.start_s) : "");
    s.ramps.push_back(r);
    return r.summary;
  }
  if (const auto* remove = std::get_if<RemoveLayer>(&change)) {
    if (auto ok = checkTiming(remove->timing, at, now_s); !ok) return tl::unexpected(ok.error());
    const auto current = evaluate(s, remove->timing.at_s.value_or(now_s));
    const auto it = std::find_if(current.begin(), current.end(),
                                 [&](const weather::CloudLayer& l) { return l.id == remove->layerId; });
    if (it == current.end())
      return fail(ErrorCode::InvalidArgument, at + ".id: no layer " + std::to_string(remove->layerId));
    Ramp r;
    r.sequence = sequence;
    r.layerId = remove->layerId;
    r.start_s = remove->timing.at_s.value_or(now_s);
    r.end_s = r.start_s + remove->timing.ramp_s;
    r.from = *it;
    r.to = *it;
    r.to.coverage = 0;
    r.removeAtEnd = true;
    r.summary = "layer " + std::to_string(r.layerId) + " removed" +
                (remove->timing.ramp_s > 0 ? ", fading over " + fmt("%.0f", remove->timing.ramp_s) + " s" : "");
    s.ramps.push_back(r);
    return r.summary;
  }
  if (const auto* clock = std::get_if<SetClock>(&change)) {
    if (clock->rate && (!std::isfinite(*clock->rate) || *clock->rate < 0 || *clock->rate > 3600))
      return fail(ErrorCode::InvalidArgument, at + ".rate: " + fmt("%g", *clock->rate) + " outside [0, 3600]");
    if (clock->jumpTo_s && !std::isfinite(*clock->jumpTo_s))
      return fail(ErrorCode::InvalidArgument, at + ".jump_to_s: must be finite");
    if (!clock->rate && !clock->jumpTo_s)
      return fail(ErrorCode::InvalidArgument, at + ": set_clock needs rate or jump_to_s");
    const double rate = clock->rate.value_or(s.clock.rate());
    const double start = clock->jumpTo_s.value_or(now_s);
    s.clock = WeatherClock(start, rate, wallNow_());
    return std::string("weather clock ") + (clock->jumpTo_s ? "jumps to " + fmt("%.0f", start) + " s" : "") +
           (clock->jumpTo_s && clock->rate ? ", " : "") + (clock->rate ? "rate x" + fmt("%g", rate) : "");
  }
  return applyRegion(s, change, at, now_s, sequence);
}

Result<AppliedChange> LiveWeather::submit(const ChangeRequest& request) { return submitImpl(request, true); }

Result<AppliedChange> LiveWeather::submitBatched(const ChangeRequest& request) {
  return submitImpl(request, unsaved_.size() >= kMaxUnsavedEvents);
}

Result<void> LiveWeather::flush() {
  if (!store_ || unsaved_.empty()) return {};
  const auto started = std::chrono::steady_clock::now();
  auto ok = store_->save(toJson(), unsaved_);
  const double took_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
  ++commitStats_.count;
  commitStats_.total_s += took_s;
  commitStats_.max_s = std::max(commitStats_.max_s, took_s);
  if (!ok) return ok;
  unsaved_.clear();
  return {};
}

Result<AppliedChange> LiveWeather::submitImpl(const ChangeRequest& request, bool durableNow) {
  if (request.changes.empty() || request.changes.size() > 256) {
    ++rejected_;
    return fail(ErrorCode::InvalidArgument,
                "changes: " + std::to_string(request.changes.size()) + " changes, expected 1 to 256");
  }
  const double now_s = clockNow();
  settle(now_s);
  // All or nothing: apply to a copy, keep it only if every change passed.
  State next = state();
  std::string summary;
  for (std::size_t i = 0; i < request.changes.size(); ++i) {
    auto one = apply(next, request.changes[i], "changes[" + std::to_string(i) + "]", now_s, sequence_ + 1);
    if (!one) {
      ++rejected_;
      return tl::unexpected(one.error());
    }
    summary += (summary.empty() ? "" : "; ") + *one;
  }
  if (const std::size_t pending = next.ramps.size() + next.regionRamps.size(); pending > kMaxPendingRamps) {
    ++rejected_;
    return fail(ErrorCode::InvalidArgument, "changes: " + std::to_string(pending) +
                                                " changes would be scheduled or ramping, at most " +
                                                std::to_string(kMaxPendingRamps));
  }
  return commit(std::move(next), timeline_, request.author, request.source, summary, now_s, durableNow);
}

Result<AppliedChange> LiveWeather::commit(State next, std::vector<TimelineItem> timeline, const std::string& author,
                                          const std::string& source, const std::string& fullSummary, double now_s,
                                          bool durableNow) {
  std::string summary = fullSummary;
  if (summary.size() > kMaxEventSummary_bytes) {
    const std::string tail = " ... (" + std::to_string(fullSummary.size()) + " bytes in all)";
    summary = std::string(utf8::cut(fullSummary, kMaxEventSummary_bytes - tail.size())) + tail;
  }
  ChangeEvent e{sequence_ + 1, now_s, unixNowMs_(), author, source, summary};
  if (committer_) {
    const auto started = std::chrono::steady_clock::now();
    auto ok = committer_(stateJson(next, timeline, sequence_ + 1, version_ + 1), e);
    const double took_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
    ++commitStats_.count;
    commitStats_.total_s += took_s;
    commitStats_.max_s = std::max(commitStats_.max_s, took_s);
    if (!ok) return tl::unexpected(ok.error());
  } else if (store_ && durableNow) {
    // Commit first: only a change on disk is acknowledged and applied. The
    // state saved holds every batched change applied before it, so their
    // events go in the same transaction.
    std::vector<ChangeEvent> events = unsaved_;
    events.push_back(e);
    const auto started = std::chrono::steady_clock::now();
    auto ok = store_->save(stateJson(next, timeline, sequence_ + 1, version_ + 1), events);
    const double took_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
    ++commitStats_.count;
    commitStats_.total_s += took_s;
    commitStats_.max_s = std::max(commitStats_.max_s, took_s);
    if (!ok) return tl::unexpected(ok.error());
    unsaved_.clear();
  } else if (store_) {
    unsaved_.push_back(e);
  }
  layers_ = std::move(next.layers);
  ramps_ = std::move(next.ramps);
  regions_ = std::move(next.regions);
  regionRamps_ = std::move(next.regionRamps);
  clock_ = next.clock;
  forecast_ = std::move(next.forecast);
  timeline_ = std::move(timeline);
  ++sequence_;
  ++version_;
  events_.push_back(e);
  if (events_.size() > kMaxEvents) events_.erase(events_.begin());
  ++accepted_;
  // A copy: a listener may add or remove listeners.
  const auto listeners = listeners_;
  for (const auto& [id, f] : listeners) f(e);
  return AppliedChange{sequence_, now_s, summary};
}

std::size_t LiveWeather::addListener(Listener listener) {
  listeners_[nextListenerId_] = std::move(listener);
  return nextListenerId_++;
}

void LiveWeather::removeListener(std::size_t id) { listeners_.erase(id); }

void LiveWeather::announce(const ChangeEvent& event) {
  const auto listeners = listeners_;
  for (const auto& [id, f] : listeners) f(event);
}

bool LiveWeather::rampRunning(double c) const {
  for (const Ramp& r : ramps_)
    if (c >= r.start_s && c < r.end_s) return true;
  for (const RegionRamp& r : regionRamps_)
    if (c >= r.start_s && c < r.end_s) return true;
  return false;
}

bool LiveWeather::drifting(double c) const {
  if (clock_.rate() == 0) return false;
  for (const auto& r : regionsAt(c))
    if (r.driftsWithWind && !r.layers.empty() && r.layers.front().wind.speed_mps > 0) return true;
  return false;
}

WeatherView LiveWeather::view() const {
  WeatherView v;
  v.clock_s = clockNow();
  v.clockRate = clock_.rate();
  v.layers = layersAt(v.clock_s);
  v.regions = regionsAt(v.clock_s);
  for (const Ramp& r : ramps_)
    if (v.clock_s < r.end_s || v.clock_s < r.start_s) v.pending.push_back({r.sequence, r.start_s, r.end_s, r.summary});
  for (const RegionRamp& r : regionRamps_)
    if (v.clock_s < r.end_s || v.clock_s < r.start_s) v.pending.push_back({r.sequence, r.start_s, r.end_s, r.summary});
  std::stable_sort(v.pending.begin(), v.pending.end(),
                   [](const PendingChange& a, const PendingChange& b) { return a.sequence < b.sequence; });
  // Then what the timeline will do, soonest first (not accepted yet: sequence 0).
  for (const TimelineItem& t : timeline_)
    v.pending.push_back({0, t.at_s, t.at_s + rampOf(t.change), t.summary, "timeline"});
  v.lastSequence = sequence_;
  v.version = version_;
  return v;
}

std::vector<ChangeEvent> LiveWeather::events(std::size_t limit) const {
  const std::size_t n = std::min(limit, events_.size());
  return {events_.end() - static_cast<std::ptrdiff_t>(n), events_.end()};
}

namespace {

nlohmann::json rampJson(std::uint64_t sequence, std::uint32_t layerId, double start_s, double end_s, bool fromAbsent,
                        const weather::CloudLayer& from, const weather::CloudLayer& to, bool removeAtEnd,
                        const std::string& summary) {
  return {{"sequence", sequence}, {"layer_id", layerId},   {"start_s", start_s},          {"end_s", end_s},
          {"from_absent", fromAbsent}, {"from", toJson(from)}, {"to", toJson(to)}, {"remove_at_end", removeAtEnd},
          {"summary", summary}};
}

}  // namespace

nlohmann::json LiveWeather::stateJson(const State& s, const std::vector<TimelineItem>& timeline, std::uint64_t sequence,
                                      std::uint64_t version) const {
  nlohmann::json layers = nlohmann::json::array();
  for (const auto& [id, l] : s.layers) layers.push_back(server::toJson(l));
  nlohmann::json ramps = nlohmann::json::array();
  for (const Ramp& r : s.ramps)
    ramps.push_back(rampJson(r.sequence, r.layerId, r.start_s, r.end_s, r.fromAbsent, r.from, r.to, r.removeAtEnd,
                             r.summary));
  nlohmann::json regions = nlohmann::json::array();
  for (const auto& [id, r] : s.regions) regions.push_back(server::toJson(r));
  // By sequence, then region id: a relay that joins a state cut by cell
  // (state_cells.hpp) puts them back in this order. Ramps of one region run
  // in the order of their changes, which this keeps.
  std::vector<const RegionRamp*> byChange;
  for (const RegionRamp& r : s.regionRamps) byChange.push_back(&r);
  std::stable_sort(byChange.begin(), byChange.end(), [](const RegionRamp* a, const RegionRamp* b) {
    return std::pair(a->sequence, a->regionId) < std::pair(b->sequence, b->regionId);
  });
  nlohmann::json regionRamps = nlohmann::json::array();
  for (const RegionRamp* rp : byChange) {
    const RegionRamp& r = *rp;
    regionRamps.push_back({{"sequence", r.sequence}, {"region_id", r.regionId}, {"start_s", r.start_s},
                           {"end_s", r.end_s}, {"from_absent", r.fromAbsent}, {"from", server::toJson(r.from)},
                           {"to", server::toJson(r.to)}, {"remove_at_end", r.removeAtEnd}, {"summary", r.summary}});
  }
  return {{"layers", layers},
          {"ramps", ramps},
          {"regions", regions},
          {"region_ramps", regionRamps},
          {"timeline", timelineJson(timeline)},
          {"forecast", forecastJson(s.forecast.get())},
          {"sequence", sequence},
          {"version", version},
          {"clock", {{"clock_s", s.clock.at(wallNow_())}, {"rate", s.clock.rate()}, {"unix_ms", unixNowMs_()}}}};
}

nlohmann::json LiveWeather::toJson() const { return stateJson(state(), timeline_, sequence_, version_); }

namespace {

// Whether a saved forecast is the one held: the same files at the same
// place on the clock (what restore decodes it from).
bool sameForecast(const LoadedForecast* held, const nlohmann::json& saved) {
  if (!held || !held->forecast) return false;
  auto files = forecastFilesFromJson(saved);
  auto placement = forecastPlacementFromJson(saved);
  if (!files || !placement || files->size() != held->files.size() ||
      saved.value("name", std::string()) != held->forecast->name())
    return false;
  for (std::size_t k = 0; k < files->size(); ++k)
    if ((*files)[k].key != held->files[k].key || (*files)[k].name != held->files[k].name) return false;
  return placement->anchorClock_s == held->placement.anchorClock_s &&
         placement->anchorValid_unix == held->placement.anchorValid_unix;
}

}  // namespace

bool LiveWeather::holdsForecast(const nlohmann::json& saved) const { return sameForecast(forecast_.get(), saved); }

Result<void> LiveWeather::restore(const nlohmann::json& j, std::vector<ChangeEvent> events,
                                  const ForecastLoader& loader) {
  auto bad = [](const std::string& what) { return fail(ErrorCode::Malformed, "saved state: " + what); };
  try {
    std::map<std::uint32_t, weather::CloudLayer> layers;
    for (const auto& l : j.at("layers")) {
      auto layer = layerFromJson(l, "layers[]");
      if (!layer) return tl::unexpected(layer.error());
      layers[layer->id] = *layer;
    }
    std::vector<Ramp> ramps;
    for (const auto& r : j.at("ramps")) {
      Ramp ramp;
      ramp.sequence = r.at("sequence").get<std::uint64_t>();
      ramp.layerId = r.at("layer_id").get<std::uint32_t>();
      ramp.start_s = r.at("start_s").get<double>();
      ramp.end_s = r.at("end_s").get<double>();
      ramp.fromAbsent = r.at("from_absent").get<bool>();
      auto from = layerFromJson(r.at("from"), "ramps[].from");
      auto to = layerFromJson(r.at("to"), "ramps[].to");
      if (!from || !to) return bad("a ramp's layers");
      ramp.from = *from;
      ramp.to = *to;
      ramp.removeAtEnd = r.at("remove_at_end").get<bool>();
      ramp.summary = r.at("summary").get<std::string>();
      ramps.push_back(ramp);
    }
    // Regions came with format 2 of the saved state; a state saved before
    // has none.
    std::map<std::uint32_t, weather::Region> regions;
    std::vector<RegionRamp> regionRamps;
    if (j.contains("regions")) {
      for (const auto& r : j.at("regions")) {
        auto region = regionFromJson(r, "regions[]", true);
        if (!region) return tl::unexpected(region.error());
        regions[region->id] = *region;
      }
      for (const auto& r : j.at("region_ramps")) {
        RegionRamp ramp;
        ramp.sequence = r.at("sequence").get<std::uint64_t>();
        ramp.regionId = r.at("region_id").get<std::uint32_t>();
        ramp.start_s = r.at("start_s").get<double>();
        ramp.end_s = r.at("end_s").get<double>();
        ramp.fromAbsent = r.at("from_absent").get<bool>();
        auto from = regionFromJson(r.at("from"), "region_ramps[].from", true);
        auto to = regionFromJson(r.at("to"), "region_ramps[].to", true);
        if (!from || !to) return bad("a region ramp's regions");
        ramp.from = *from;
        ramp.to = *to;
        ramp.removeAtEnd = r.at("remove_at_end").get<bool>();
        ramp.summary = r.at("summary").get<std::string>();
        regionRamps.push_back(ramp);
      }
    }
    // The timeline came with format 3 of the saved state.
    std::vector<TimelineItem> timeline;
    if (j.contains("timeline")) {
      auto t = timelineFromJson(j.at("timeline"));
      if (!t) return tl::unexpected(t.error());
      timeline = std::move(*t);
    }
    // The forecast came with format 4 of the saved state.
    std::shared_ptr<const LoadedForecast> forecast;
    if (j.contains("forecast") && !j.at("forecast").is_null() && sameForecast(forecast_.get(), j.at("forecast"))) {
      // The forecast held already (a follower folding the next change of
      // the same weather): not decoded again, and its tiles stay cached.
      forecast = forecast_;
    } else if (j.contains("forecast") && !j.at("forecast").is_null()) {
      if (!loader) return bad("a forecast, and no way to decode it");
      auto f = loader(j.at("forecast"));
      if (!f) return fail(f.error().code, "saved state: forecast: " + f.error().detail);
      f->serial = ++forecastSerial_;
      forecast = std::make_shared<const LoadedForecast>(std::move(*f));
    }
    const auto& c = j.at("clock");
    const double rate = c.at("rate").get<double>();
    const double downtime_s = double(unixNowMs_() - c.at("unix_ms").get<std::int64_t>()) / 1000.0;
    const double clockNow_s = c.at("clock_s").get<double>() + rate * std::max(0.0, downtime_s);
    layers_ = std::move(layers);
    ramps_ = std::move(ramps);
    regions_ = std::move(regions);
    regionRamps_ = std::move(regionRamps);
    timeline_ = std::move(timeline);
    forecast_ = std::move(forecast);
    sequence_ = j.at("sequence").get<std::uint64_t>();
    version_ = j.at("version").get<std::uint64_t>() + 1;
    clock_ = WeatherClock(clockNow_s, rate, wallNow_());
    events_ = std::move(events);
  } catch (const nlohmann::json::exception& e) {
    return bad(e.what());
  }
  return {};
}

std::uint64_t LiveWeather::stateHash() const {
  nlohmann::json j = toJson();
  j.erase("version");
  j["clock"] = {{"rate", clock_.rate()}};
  const std::string text = j.dump();
  std::uint64_t h = 1469598103934665603ull;
  for (unsigned char ch : text) {
    h ^= ch;
    h *= 1099511628211ull;
  }
  return h;
}

}  // namespace sky::server
