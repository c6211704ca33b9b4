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
    auto regions = evaluateRegions(s, start_s);
    const auto it = std::find_if(regions.begin(), regions.end(),
                                 [&](const weather::Region& r) { return r.id == to.id; });
    RegionRamp r;
    r.sequence = sequence;
    r.regionId = to.id;
    r.start_s = start_s;
    r.end_s = start_s + set->timing.ramp_s;
    r.fromAbsent = it == regions.end();
    if (!r.fromAbsent) {
      r.from = *it;
      *it = to;
    } else {
      regions.push_back(to);
    }
    r.to = to;
    const std::size_t ids = distinctLayerIds(evaluate(s, start_s), regions);
    if (ids > kMaxScenarioLayers)
      return fail(ErrorCode::InvalidArgument, at + ".region.layers: " + std::to_string(ids) +
                                                  " distinct layer ids with the global layers, at most " +
                                                  std::to_string(kMaxScenarioLayers));
    r.summary = "region " + std::to_string(to.id) + (r.fromAbsent ? " added: " : " changed: ") + describe(to) +
                (set->timing.ramp_s > 0 ? " over " + fmt("%.0f", set->timing.ramp_s) + " s" : "") +
                (set->timing.at_s ? " from clock " + fmt("%.0f", start_s) : "");
    s.regionRamps.push_back(r);
    return r.summary;
  }
  const auto& remove = std::get<RemoveRegion>(change);
  if (auto ok = checkTiming(remove.timing, at, now_s); !ok) return tl::unexpected(ok.error());
  const double start_s = remove.timing.at_s.value_or(now_s);
  const auto regions = evaluateRegions(s, start_s);
  const auto it = std::find_if(regions.begin(), regions.end(),
                               [&](const weather::Region& r) { return r.id == remove.regionId; });
  if (it == regions.end())
    return fail(ErrorCode::InvalidArgument, at + ".id: no region " + std::to_string(remove.regionId));
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
