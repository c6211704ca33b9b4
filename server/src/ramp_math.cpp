// Ramp interpolation (see ramp_math.hpp).
#include "ramp_math.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <set>

namespace sky::server {

namespace {

// Longest ramp, weather seconds (a day).
constexpr double kMaxRamp_s = 86400.0;
// A start this far in the past (weather seconds) still counts as now: the
// clock moves between a client reading it and its request arriving.
constexpr double kPastTolerance_s = 5.0;

std::string fmt(const char* f, double v) {
  char buf[64];
  std::snprintf(buf, sizeof buf, f, v);
  return buf;
}

double mix(double x, double y, double f) { return x + f * (y - x); }

// From a towards b the shorter way round a circle of `period` degrees.
double mixAngle(double a, double b, double f, double period) {
  const double d = std::fmod(b - a + 1.5 * period, period) - period / 2;
  return a + f * d;
}

double wrap360(double deg) {
  const double w = std::fmod(deg, 360.0);
  return w < 0 ? w + 360.0 : w;
}

double wrap180(double deg) { return wrap360(deg + 180.0) - 180.0; }

}  // namespace

Result<void> checkTiming(const Timing& t, const std::string& at, double now_s) {
  if (!std::isfinite(t.ramp_s) || t.ramp_s < 0 || t.ramp_s > kMaxRamp_s)
    return fail(ErrorCode::InvalidArgument, at + ".ramp_s: " + fmt("%g", t.ramp_s) + " outside [0, 86400]");
  if (t.at_s && (!std::isfinite(*t.at_s) || *t.at_s < now_s - kPastTolerance_s))
    return fail(ErrorCode::InvalidArgument,
                at + ".at_s: " + fmt("%.1f", *t.at_s) + " is in the past (weather clock now " + fmt("%.1f", now_s) + ")");
  if (t.at_s && *t.at_s > now_s + kMaxScheduleAhead_s)
    return fail(ErrorCode::InvalidArgument, at + ".at_s: " + fmt("%.1f", *t.at_s) + " is more than " +
                                                fmt("%.0f", kMaxScheduleAhead_s) +
                                                " s (30 days) ahead of the weather clock now (" + fmt("%.1f", now_s) + ")");
  return {};
}

std::size_t distinctLayerIds(const std::vector<weather::CloudLayer>& layers,
                             const std::vector<weather::Region>& regions) {
  std::set<std::uint32_t> ids;
  for (const auto& l : layers) ids.insert(l.id);
  for (const auto& r : regions)
    for (const auto& l : r.layers) ids.insert(l.id);
  return ids.size();
}

weather::CloudLayer lerpLayer(const weather::CloudLayer& a, const weather::CloudLayer& b, double f) {
  weather::CloudLayer o = b;
  o.base_m = mix(a.base_m, b.base_m, f);
  o.thickness_m = mix(a.thickness_m, b.thickness_m, f);
  o.transitionBand_m = mix(a.transitionBand_m, b.transitionBand_m, f);
  o.coverage = mix(a.coverage, b.coverage, f);
  o.density = mix(a.density, b.density, f);
  o.wind.speed_mps = mix(a.wind.speed_mps, b.wind.speed_mps, f);
  o.wind.fromDirection_deg = wrap360(mixAngle(a.wind.fromDirection_deg, b.wind.fromDirection_deg, f, 360.0));
  o.wind.vertical_mps = mix(a.wind.vertical_mps, b.wind.vertical_mps, f);
  return o;
}

weather::Region lerpRegion(const weather::Region& a, const weather::Region& b, double f) {
  weather::Region o = b;
  o.centerLat_deg = mix(a.centerLat_deg, b.centerLat_deg, f);
  o.centerLon_deg = wrap180(mixAngle(a.centerLon_deg, b.centerLon_deg, f, 360.0));
  o.sizeX_m = mix(a.sizeX_m, b.sizeX_m, f);
  o.sizeY_m = mix(a.sizeY_m, b.sizeY_m, f);
  o.cornerRadius_m = std::min(mix(a.cornerRadius_m, b.cornerRadius_m, f), std::min(o.sizeX_m, o.sizeY_m) / 2);
  o.rotation_deg = wrap180(mixAngle(a.rotation_deg, b.rotation_deg, f, 360.0));
  o.transition_m = mix(a.transition_m, b.transition_m, f);
  o.layers.clear();
  for (const weather::CloudLayer& to : b.layers) {
    const auto from = std::find_if(a.layers.begin(), a.layers.end(),
                                   [&](const weather::CloudLayer& l) { return l.id == to.id; });
    weather::CloudLayer start = to;
    if (from != a.layers.end())
      start = *from;
    else
      start.coverage = 0;
    o.layers.push_back(lerpLayer(start, to, f));
  }
  if (f < 1.0)
    for (const weather::CloudLayer& gone : a.layers) {
      const bool kept = std::any_of(b.layers.begin(), b.layers.end(),
                                    [&](const weather::CloudLayer& l) { return l.id == gone.id; });
      if (kept) continue;
      weather::CloudLayer end = gone;
      end.coverage = 0;
      o.layers.push_back(lerpLayer(gone, end, f));
    }
  return o;
}

weather::Region shrunk(const weather::Region& r) {
  weather::Region o = r;
  o.sizeX_m = 0;
  o.sizeY_m = 0;
  o.cornerRadius_m = 0;
  o.transition_m = 0;
  return o;
}

}  // namespace sky::server
