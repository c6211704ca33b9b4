// LiveWeather's scenario timelines: loading a scenario (its start and its
// timeline, checked entry by entry against the weather each will meet),
// making due entries, and saving what waits. See live_weather.hpp.
#include <algorithm>
#include <cstdio>

#include "sky/server/api_json.hpp"
#include "sky/server/live_weather.hpp"
#include "sky/server/weather_store.hpp"
#include "ramp_math.hpp"

namespace sky::server {

namespace {

std::string fmt(const char* f, double v) {
  char buf[64];
  std::snprintf(buf, sizeof buf, f, v);
  return buf;
}

WeatherChange toChange(const weather::TimelineEntry& e) {
  const Timing t{std::nullopt, e.ramp_s};
  switch (e.op) {
    case weather::TimelineEntry::Op::SetLayer: return SetLayer{e.layer, t};
    case weather::TimelineEntry::Op::RemoveLayer: return RemoveLayer{e.id, t};
    case weather::TimelineEntry::Op::SetRegion: return SetRegion{e.region, t};
    case weather::TimelineEntry::Op::RemoveRegion: return RemoveRegion{e.id, t};
    case weather::TimelineEntry::Op::SetClock: return SetClock{e.rate, e.jumpTo_s};
  }
  return SetClock{};
}

// What an entry will do, for the pending list ("what is scheduled next").
std::string describe(const WeatherChange& c, const std::string& scenario) {
  auto over = [](const Timing& t) { return t.ramp_s > 0 ? " over " + fmt("%.0f", t.ramp_s) + " s" : std::string(); };
  std::string what;
  if (const auto* s = std::get_if<SetLayer>(&c))
    what = "layer " + std::to_string(s->layer.id) + " (" + std::string(weather::toString(s->layer.type)) +
           ") coverage -> " + fmt("%.2f", s->layer.coverage) + over(s->timing);
  else if (const auto* r = std::get_if<RemoveLayer>(&c))
    what = "layer " + std::to_string(r->layerId) + " removed" + over(r->timing);
  else if (const auto* g = std::get_if<SetRegion>(&c))
    what = "region " + std::to_string(g->region.id) + " at " + fmt("%.4f", g->region.centerLat_deg) + " " +
           fmt("%.4f", g->region.centerLon_deg) + ", " + fmt("%.0f", g->region.sizeX_m / 1000) + " x " +
           fmt("%.0f", g->region.sizeY_m / 1000) + " km" + over(g->timing);
  else if (const auto* x = std::get_if<RemoveRegion>(&c))
    what = "region " + std::to_string(x->regionId) + " removed" + over(x->timing);
  else {
    const auto& k = std::get<SetClock>(c);
    what = std::string("weather clock") + (k.jumpTo_s ? " jumps to " + fmt("%.0f", *k.jumpTo_s) + " s" : "") +
           (k.rate ? " rate x" + fmt("%g", *k.rate) : "");
  }
  return scenario + ": " + what;
}

}  // namespace

double LiveWeather::rampOf(const WeatherChange& c) {
  if (const auto* s = std::get_if<SetLayer>(&c)) return s->timing.ramp_s;
  if (const auto* r = std::get_if<RemoveLayer>(&c)) return r->timing.ramp_s;
  if (const auto* g = std::get_if<SetRegion>(&c)) return g->timing.ramp_s;
  if (const auto* x = std::get_if<RemoveRegion>(&c)) return x->timing.ramp_s;
  return 0;
}

std::vector<LiveWeather::TimelineItem> LiveWeather::timelineItems(const Scenario& scenario, const std::string& name) {
  std::vector<TimelineItem> items;
  for (const auto& e : scenario.timeline) {
    const WeatherChange change = toChange(e);
    items.push_back({e.at_s, change, e.where, name, describe(change, name)});
  }
  return items;
}

Result<void> LiveWeather::dryRun(State s, const std::vector<TimelineItem>& items) const {
  // The timeline starts from the clock of the weather it is given (the
  // scenario's start, or now); an entry past the horizon would wait forever.
  const double start_s = s.clock.at(wallNow_());
  for (const TimelineItem& item : items)
    if (item.at_s > start_s + kMaxScheduleAhead_s)
      return fail(ErrorCode::InvalidArgument, item.where + ".at_s: " + fmt("%.1f", item.at_s) + " is more than " +
                                                  fmt("%.0f", kMaxScheduleAhead_s) + " s (30 days) after clock " +
                                                  fmt("%.1f", start_s));
  // Each entry meets the weather the ones before it left, at its own clock.
  for (const TimelineItem& item : items)
    if (auto r = apply(s, item.change, item.where, item.at_s, 0); !r)
      return fail(ErrorCode::InvalidArgument, r.error().detail);
  return {};
}

Result<void> LiveWeather::scheduleTimeline(const Scenario& scenario, const std::string& name) {
  auto items = timelineItems(scenario, name);
  if (auto ok = dryRun(state(), items); !ok) return ok;
  timeline_ = std::move(items);
  return {};
}

Result<AppliedChange> LiveWeather::loadScenario(const Scenario& scenario, const std::string& name,
                                                const std::string& author) {
  const double now_s = clockNow();
  settle(now_s);
  // The scenario's start: its layers and nothing else, its clock.
  State next;
  for (const auto& l : scenario.layers) next.layers[l.id] = l;
  next.clock = WeatherClock(scenario.clock.start_s, scenario.clock.rate, wallNow_());
  auto items = timelineItems(scenario, name);
  if (auto ok = dryRun(next, items); !ok) {
    ++rejected_;
    return tl::unexpected(ok.error());
  }
  const std::string summary = "scenario " + name + " loaded: " + std::to_string(scenario.layers.size()) +
                              " layer(s), " + std::to_string(items.size()) + " timeline entr" +
                              (items.size() == 1 ? "y" : "ies") + ", clock " + fmt("%.0f", scenario.clock.start_s) +
                              " s at x" + fmt("%g", scenario.clock.rate);
  return commit(std::move(next), std::move(items), author, "scenario", summary, now_s);
}

std::optional<double> LiveWeather::nextTimelineAt() const {
  if (timeline_.empty() || timelineHeld_) return std::nullopt;
  return timeline_.front().at_s;
}

std::vector<LiveWeather::TimelineOutcome> LiveWeather::runTimeline() {
  std::vector<TimelineOutcome> out;
  while (!timeline_.empty() && !timelineHeld_) {
    const double now_s = clockNow();
    const double at_s = timeline_.front().at_s;
    if (at_s > now_s) break;
    std::size_t n = 0;
    while (n < timeline_.size() && timeline_[n].at_s == at_s) ++n;
    const TimelineItem first = timeline_.front();
    std::vector<TimelineItem> rest(timeline_.begin() + static_cast<std::ptrdiff_t>(n), timeline_.end());
    settle(now_s);
    State next = state();
    std::string summary;
    Result<AppliedChange> result = AppliedChange{};
    for (std::size_t i = 0; i < n && result; ++i) {
      auto one = apply(next, timeline_[i].change, timeline_[i].where, now_s, sequence_ + 1);
      if (!one)
        result = tl::unexpected(one.error());
      else
        summary += (summary.empty() ? "" : "; ") + *one;
    }
    if (result) {
      result = commit(std::move(next), rest, "scenario:" + first.scenario, "scenario",
                      "timeline at clock " + fmt("%.0f", at_s) + " s: " + summary, now_s);
    }
    if (!result) {
      ++rejected_;
      // Dropped either way: an entry is made once. (If saving the drop fails
      // the entry is tried again after a restart, and refused again.)
      timeline_ = std::move(rest);
      if (store_) (void)store_->save(toJson(), nullptr);
    }
    out.push_back({at_s, first.where, std::move(result)});
  }
  return out;
}

nlohmann::json LiveWeather::timelineJson(const std::vector<TimelineItem>& timeline) {
  nlohmann::json list = nlohmann::json::array();
  for (const TimelineItem& t : timeline)
    list.push_back({{"at_s", t.at_s}, {"change", server::toJson(t.change)}, {"where", t.where},
                    {"scenario", t.scenario}, {"summary", t.summary}});
  return list;
}

Result<std::vector<LiveWeather::TimelineItem>> LiveWeather::timelineFromJson(const nlohmann::json& j) {
  std::vector<TimelineItem> out;
  try {
    for (const auto& t : j) {
      auto change = changeFromJson(t.at("change"), "timeline[].change");
      if (!change) return tl::unexpected(change.error());
      out.push_back({t.at("at_s").get<double>(), *change, t.at("where").get<std::string>(),
                     t.at("scenario").get<std::string>(), t.at("summary").get<std::string>()});
    }
  } catch (const nlohmann::json::exception& e) {
    return fail(ErrorCode::Malformed, std::string("saved state: timeline: ") + e.what());
  }
  return out;
}

}  // namespace sky::server
