// LiveWeather's regions: adding, changing and removing them with ramps, and
// evaluating them (drift included) at a clock. See live_weather.hpp.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <set>

#include "ramp_math.hpp"
#include "sky/server/live_weather.hpp"

namespace sky::server {

namespace {

std::string fmt(const char* f, double v) {
  char buf[64];
  std::snprintf(buf, sizeof buf, f, v);
  return buf;
}

std::string describe(const weather::Region& r) {
  std::string layers;
  for (const auto& l : r.layers)
    layers += (layers.empty() ? "" : ", ") + std::to_string(l.id) + " " + std::string(weather::toString(l.type)) +
              " " + fmt("%.2f", l.coverage);
  return fmt("%.4f", r.centerLat_deg) + " " + fmt("%.4f", r.centerLon_deg) + ", " + fmt("%.0f", r.sizeX_m / 1000) +
         " x " + fmt("%.0f", r.sizeY_m / 1000) + " km, transition " + fmt("%.0f", r.transition_m / 1000) + " km" +
         (r.driftsWithWind ? ", drifting" : "") + ", layers [" + layers + "]";
}

}  // namespace

std::vector<weather::Region> LiveWeather::evaluateRegions(const State& s, double c) {
  std::map<std::uint32_t, weather::Region> out;
  for (const auto& [id, r] : s.regions) out[id] = weather::regionAt(r, c);
  for (const RegionRamp& r : s.regionRamps) {
    if (c < r.start_s) continue;
    const double f = r.end_s > r.start_s ? std::clamp((c - r.start_s) / (r.end_s - r.start_s), 0.0, 1.0) : 1.0;
    if (f >= 1.0 && r.removeAtEnd) {
      out.erase(r.regionId);
      continue;
    }
    const weather::Region to = weather::regionAt(r.to, c);
    const weather::Region from = r.fromAbsent ? shrunk(to) : weather::regionAt(r.from, c);
    out[r.regionId] = lerpRegion(from, to, f);
  }
  std::vector<weather::Region> v;
  for (auto& [id, r] : out) v.push_back(std::move(r));
  return v;
}

std::optional<weather::Region> LiveWeather::evaluateRegion(const State& s, std::uint32_t id, double c) {
  std::optional<weather::Region> out;
  if (auto it = s.regions.find(id); it != s.regions.end()) out = weather::regionAt(it->second, c);
  for (const RegionRamp& r : s.regionRamps) {
    if (r.regionId != id || c < r.start_s) continue;
    const double f = r.end_s > r.start_s ? std::clamp((c - r.start_s) / (r.end_s - r.start_s), 0.0, 1.0) : 1.0;
    if (f >= 1.0 && r.removeAtEnd) {
      out.reset();
      continue;
    }
    const weather::Region to = weather::regionAt(r.to, c);
    const weather::Region from = r.fromAbsent ? shrunk(to) : weather::regionAt(r.from, c);
    out = lerpRegion(from, to, f);
  }
  return out;
}

std::vector<weather::Region> LiveWeather::regionsAt(double clock_s) const {
  return evaluateRegions(state(), clock_s);
}

Result<std::string> LiveWeather::applyRegion(State& s, const WeatherChange& change, const std::string& at,
                                             double now_s, std::uint64_t sequence) const {
  if (const auto* set = std::get_if<SetRegion>(&change)) {
    if (auto ok = checkTiming(set->timing, at, now_s); !ok) return tl::unexpected(ok.error());
    const double start_s = set->timing.at_s.value_or(now_s);
    weather::Region to = set->region;
    to.centerLon_deg = std::isfinite(to.centerLon_deg) ? std::remainder(to.centerLon_deg, 360.0) : to.centerLon_deg;
    to.placedAtClock_s = start_s;  // the centre given is where it is when the change starts
    if (auto ok = weather::validate(to); !ok)
      return fail(ErrorCode::InvalidArgument, at + ".region: " + ok.error().detail);
    // This region alone, not all of them: a continent's METAR stations are
    // thousands of regions, changed hundreds at a time.
    const std::optional<weather::Region> now = evaluateRegion(s, to.id, start_s);
    RegionRamp r;
    r.sequence = sequence;
    r.regionId = to.id;
    r.start_s = start_s;
    r.end_s = start_s + set->timing.ramp_s;
    r.fromAbsent = !now;
    if (now) r.from = *now;
    r.to = to;
    // Only a layer id no layer or region has yet can pass the bound: look
    // for each of `to`'s ids, stopping when all are found.
    std::set<std::uint32_t> unseen;
    for (const auto& l : to.layers) unseen.insert(l.id);
    for (const auto& l : evaluate(s, start_s)) unseen.erase(l.id);
    if (now)
      for (const auto& l : now->layers) unseen.erase(l.id);
    auto seen = [&](const weather::Region& region) {
      for (const auto& l : region.layers) unseen.erase(l.id);
      return unseen.empty();
    };
    for (auto it = s.regions.begin(); !unseen.empty() && it != s.regions.end(); ++it) seen(it->second);
    for (auto it = s.regionRamps.begin(); !unseen.empty() && it != s.regionRamps.end(); ++it) seen(it->to) || seen(it->from);
    if (!unseen.empty()) {
      auto regions = evaluateRegions(s, start_s);
      std::erase_if(regions, [&](const weather::Region& x) { return x.id == to.id; });
      regions.push_back(to);
      const std::size_t ids = distinctLayerIds(evaluate(s, start_s), regions);
      if (ids > kMaxScenarioLayers)
        return fail(ErrorCode::InvalidArgument, at + ".region.layers: " + std::to_string(ids) +
                                                    " distinct layer ids with the global layers, at most " +
                                                    std::to_string(kMaxScenarioLayers));
    }
    r.summary = "region " + std::to_string(to.id) + (r.fromAbsent ? " added: " : " changed: ") + describe(to) +
                (set->timing.ramp_s > 0 ? " over " + fmt("%.0f", set->timing.ramp_s) + " s" : "") +
                (set->timing.at_s ? " from clock " + fmt("%.0f", start_s) : "");
    s.regionRamps.push_back(r);
    return r.summary;
  }
  const auto& remove = std::get<RemoveRegion>(change);
  if (auto ok = checkTiming(remove.timing, at, now_s); !ok) return tl::unexpected(ok.error());
  const double start_s = remove.timing.at_s.value_or(now_s);
  const std::optional<weather::Region> it = evaluateRegion(s, remove.regionId, start_s);
  if (!it) return fail(ErrorCode::InvalidArgument, at + ".id: no region " + std::to_string(remove.regionId));
  RegionRamp r;
  r.sequence = sequence;
  r.regionId = remove.regionId;
  r.start_s = start_s;
  r.end_s = start_s + remove.timing.ramp_s;
  r.from = *it;
  r.to = shrunk(*it);
  r.removeAtEnd = true;
  r.summary = "region " + std::to_string(r.regionId) + " removed" +
              (remove.timing.ramp_s > 0 ? ", shrinking over " + fmt("%.0f", remove.timing.ramp_s) + " s" : "");
  s.regionRamps.push_back(r);
  return r.summary;
}

}  // namespace sky::server
