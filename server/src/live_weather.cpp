// The server's live weather (see live_weather.hpp).
#include "sky/server/live_weather.hpp"

#include "sky/server/api_json.hpp"
#include "sky/server/weather_store.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace sky::server {

namespace {

// Longest ramp, weather seconds (a day).
constexpr double kMaxRamp_s = 86400.0;
// A start this far in the past (weather seconds) still counts as now: the
// clock moves between a client reading it and its request arriving.
constexpr double kPastTolerance_s = 5.0;
// Events kept in memory for /api/events.
constexpr std::size_t kMaxEvents = 10000;

std::string fmt(const char* f, double v) {
  char buf[64];
  std::snprintf(buf, sizeof buf, f, v);
  return buf;
}

weather::CloudLayer lerp(const weather::CloudLayer& a, const weather::CloudLayer& b, double f) {
  weather::CloudLayer o = b;
  auto mix = [f](double x, double y) { return x + f * (y - x); };
  o.base_m = mix(a.base_m, b.base_m);
  o.thickness_m = mix(a.thickness_m, b.thickness_m);
  o.transitionBand_m = mix(a.transitionBand_m, b.transitionBand_m);
  o.coverage = mix(a.coverage, b.coverage);
  o.density = mix(a.density, b.density);
  o.wind.speed_mps = mix(a.wind.speed_mps, b.wind.speed_mps);
  // Direction along the shorter way round.
  double d = std::fmod(b.wind.fromDirection_deg - a.wind.fromDirection_deg + 540.0, 360.0) - 180.0;
  o.wind.fromDirection_deg = std::fmod(a.wind.fromDirection_deg + f * d + 360.0, 360.0);
  o.wind.vertical_mps = mix(a.wind.vertical_mps, b.wind.vertical_mps);
  // The type switches at once (tiles blend it); until the end of a ramp that
  // removes the layer it keeps its own.
  return o;
}

Result<void> checkTiming(const Timing& t, const std::string& at, double now_s) {
  if (!std::isfinite(t.ramp_s) || t.ramp_s < 0 || t.ramp_s > kMaxRamp_s)
    return fail(ErrorCode::InvalidArgument, at + ".ramp_s: " + fmt("%g", t.ramp_s) + " outside [0, 86400]");
  if (t.at_s && (!std::isfinite(*t.at_s) || *t.at_s < now_s - kPastTolerance_s))
    return fail(ErrorCode::InvalidArgument,
                at + ".at_s: " + fmt("%.1f", *t.at_s) + " is in the past (weather clock now " + fmt("%.1f", now_s) + ")");
  return {};
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
    out[r.layerId] = lerp(from, r.to, f);
  }
  std::vector<weather::CloudLayer> v;
  for (auto& [id, l] : out) v.push_back(l);
  return v;
}

std::vector<weather::CloudLayer> LiveWeather::layersAt(double clock_s) const {
  return evaluate(State{layers_, ramps_, clock_}, clock_s);
}

bool LiveWeather::changing(double clock_s) const {
  for (const Ramp& r : ramps_)
    if (clock_s < r.end_s || (r.end_s == r.start_s && clock_s < r.start_s)) return true;
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
}

Result<std::string> LiveWeather::apply(State& s, const WeatherChange& change, std::size_t i, double now_s,
                                       std::uint64_t sequence) const {
  const std::string at = "changes[" + std::to_string(i) + "]";
  if (const auto* set = std::get_if<SetLayer>(&change)) {
    if (auto ok = checkTiming(set->timing, at, now_s); !ok) return tl::unexpected(ok.error());
    if (auto ok = weather::validate(set->layer); !ok)
      return fail(ErrorCode::InvalidArgument, at + ".layer: " + ok.error().detail);
    const auto current = evaluate(s, set->timing.at_s.value_or(now_s));
    const auto it = std::find_if(current.begin(), current.end(),
                                 [&](const weather::CloudLayer& l) { return l.id == set->layer.id; });
    if (it == current.end() && current.size() >= kMaxScenarioLayers)
      return fail(ErrorCode::InvalidArgument,
                  at + ".layer.id: " + std::to_string(set->layer.id) + " would be layer " +
                      std::to_string(current.size() + 1) + ", at most " + std::to_string(kMaxScenarioLayers));
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
  return fail(ErrorCode::Unsupported, at + ": regional weather is not implemented yet");
}

Result<AppliedChange> LiveWeather::submit(const ChangeRequest& request) {
  if (request.changes.empty() || request.changes.size() > 256) {
    ++rejected_;
    return fail(ErrorCode::InvalidArgument,
                "changes: " + std::to_string(request.changes.size()) + " changes, expected 1 to 256");
  }
  const double now_s = clockNow();
  settle(now_s);
  // All or nothing: apply to a copy, keep it only if every change passed.
  State next{layers_, ramps_, clock_};
  std::string summary;
  for (std::size_t i = 0; i < request.changes.size(); ++i) {
    auto one = apply(next, request.changes[i], i, now_s, sequence_ + 1);
    if (!one) {
      ++rejected_;
      return tl::unexpected(one.error());
    }
    summary += (summary.empty() ? "" : "; ") + *one;
  }
  ChangeEvent e{sequence_ + 1, now_s, unixNowMs_(), request.author, request.source, summary};
  if (store_) {
    // Commit first: only a change on disk is acknowledged and applied.
    if (auto ok = store_->save(stateJson(next, sequence_ + 1, version_ + 1), &e); !ok) return tl::unexpected(ok.error());
  }
  layers_ = std::move(next.layers);
  ramps_ = std::move(next.ramps);
  clock_ = next.clock;
  ++sequence_;
  ++version_;
  events_.push_back(e);
  if (events_.size() > kMaxEvents) events_.erase(events_.begin());
  return AppliedChange{sequence_, now_s, summary};
}

WeatherView LiveWeather::view() const {
  WeatherView v;
  v.clock_s = clockNow();
  v.clockRate = clock_.rate();
  v.layers = layersAt(v.clock_s);
  for (const Ramp& r : ramps_)
    if (v.clock_s < r.end_s || v.clock_s < r.start_s) v.pending.push_back({r.sequence, r.start_s, r.end_s, r.summary});
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

nlohmann::json LiveWeather::stateJson(const State& s, std::uint64_t sequence, std::uint64_t version) const {
  nlohmann::json layers = nlohmann::json::array();
  for (const auto& [id, l] : s.layers) layers.push_back(server::toJson(l));
  nlohmann::json ramps = nlohmann::json::array();
  for (const Ramp& r : s.ramps)
    ramps.push_back(rampJson(r.sequence, r.layerId, r.start_s, r.end_s, r.fromAbsent, r.from, r.to, r.removeAtEnd,
                             r.summary));
  return {{"layers", layers},
          {"ramps", ramps},
          {"sequence", sequence},
          {"version", version},
          {"clock", {{"clock_s", s.clock.at(wallNow_())}, {"rate", s.clock.rate()}, {"unix_ms", unixNowMs_()}}}};
}

nlohmann::json LiveWeather::toJson() const { return stateJson(State{layers_, ramps_, clock_}, sequence_, version_); }

Result<void> LiveWeather::restore(const nlohmann::json& j, std::vector<ChangeEvent> events) {
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
    const auto& c = j.at("clock");
    const double rate = c.at("rate").get<double>();
    const double downtime_s = double(unixNowMs_() - c.at("unix_ms").get<std::int64_t>()) / 1000.0;
    const double clockNow_s = c.at("clock_s").get<double>() + rate * std::max(0.0, downtime_s);
    layers_ = std::move(layers);
    ramps_ = std::move(ramps);
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
