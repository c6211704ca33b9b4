// Interpolation of layers and regions along a ramp (LiveWeather's ramps):
// numbers linearly, directions the shorter way round, types switching at once
// (the coverage tiles blend them).
#pragma once

#include <string>
#include <vector>

#include "sky/core/result.hpp"
#include "sky/server/change.hpp"
#include "sky/weather/model.hpp"
#include "sky/weather/region.hpp"

namespace sky::server {

// Furthest ahead of the weather clock now that a change or a timeline entry
// may be scheduled, weather seconds (30 days). A training exercise spans
// hours to days; a start beyond a month is a mistake (or a hostile value
// that would sit in memory and on disk forever), refused with the field named.
inline constexpr double kMaxScheduleAhead_s = 30.0 * 86400.0;

// A change's timing against the weather clock now: ramp in [0, 86400] s, a
// start not in the past (beyond a few seconds of slack) and at most
// kMaxScheduleAhead_s ahead. Errors name `at`.
Result<void> checkTiming(const Timing& timing, const std::string& at, double now_s);

// Layer ids in use by the global layers and every region's layers together
// (each becomes one layer of a snapshot).
std::size_t distinctLayerIds(const std::vector<weather::CloudLayer>& layers,
                             const std::vector<weather::Region>& regions);

// a at f = 0, b at f = 1; identity fields (id, type) are b's.
weather::CloudLayer lerpLayer(const weather::CloudLayer& a, const weather::CloudLayer& b, double f);

// Both regions as they stand at the same clock (weather::regionAt). Geometry
// interpolates (centre along the shorter way in longitude, rotation the
// shorter way round); a layer in both interpolates, a layer only in b fades in
// from coverage 0, a layer only in a fades out to coverage 0 and is gone at
// f = 1. Drift and placement are b's.
weather::Region lerpRegion(const weather::Region& a, const weather::Region& b, double f);

// The region at zero size (size, corner radius and transition perimeter 0):
// where a new region grows from and a removed one shrinks to.
weather::Region shrunk(const weather::Region& r);

}  // namespace sky::server
