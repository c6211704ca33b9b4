// The server's lightning (see lightning_service.hpp).
#include "sky/server/lightning_service.hpp"

#include <algorithm>
#include <cmath>
#include <iterator>
#include <map>

#include "sky/server/conditions_api.hpp"
#include "sky/server/live_weather.hpp"
#include "sky/server/snapshot_builder.hpp"

namespace sky::server {

namespace {

bool anyCumulonimbus(const std::vector<weather::CloudLayer>& layers, const std::vector<weather::Region>& regions) {
  auto cb = [](const weather::CloudLayer& l) { return l.type == weather::CloudType::Cumulonimbus; };
  if (std::any_of(layers.begin(), layers.end(), cb)) return true;
  return std::any_of(regions.begin(), regions.end(),
                     [&](const weather::Region& r) { return std::any_of(r.layers.begin(), r.layers.end(), cb); });
}

bool same(const weather::SphericalCap& a, const weather::SphericalCap& b) {
  return a.centerLat_deg == b.centerLat_deg && a.centerLon_deg == b.centerLon_deg && a.radius_m == b.radius_m;
}

// The storm cells of the caps, one per S2 cell whichever caps hold it.
std::vector<weather::StormCell> stormCellsIn(const LiveWeather& weather, double clock_s,
                                             std::span<const weather::SphericalCap> caps, double rate,
                                             TileCache* cache) {
  const std::vector<weather::CloudLayer> layers = weather.layersAt(clock_s);
  const std::vector<weather::Region> regions = weather.regionsAt(clock_s);
  // A forecast's convective layer is cumulus whose tiles blend into
  // cumulonimbus: with a forecast loaded the tiles decide.
  if (!anyCumulonimbus(layers, regions) && !weather.forecast()) return {};
  std::map<std::uint64_t, weather::StormCell> cells;
  for (const weather::SphericalCap& cap : caps) {
    const weather::WeatherSnapshot snapshot = subscriberSnapshot(weather, clock_s, cap, kLightningTileLevel, cache);
    if (snapshot.tileLevel != kLightningTileLevel) continue;  // not at the process's level: none drawn
    // The cache's covering at the level is coverCap's at it.
    const TileCache::Entry* entry = cache ? &cache->covering(cap, kLightningTileLevel, kDefaultMaxCells) : nullptr;
    const std::vector<std::uint64_t> covering = entry && entry->covering.level == kLightningTileLevel
                                                    ? entry->covering.cells
                                                    : weather::coverCap(cap, kLightningTileLevel, kDefaultMaxCells);
    for (const weather::StormCell& c : weather::stormCells(snapshot, covering, rate)) cells.emplace(c.cellId, c);
  }
  std::vector<weather::StormCell> list;
  list.reserve(cells.size());
  for (const auto& [id, c] : cells) list.push_back(c);
  return list;
}

// The areas' caps, each cut to kLightningReach_m and taken once (the
// channels of one simulator watch the same areas), at most kMaxLightningAreas.
std::vector<weather::SphericalCap> distinctCaps(std::span<const weather::SphericalCap> areas) {
  std::vector<weather::SphericalCap> caps;
  for (const weather::SphericalCap& a : areas) {
    weather::SphericalCap cap = a;
    cap.radius_m = std::min(cap.radius_m, kLightningReach_m);
    const bool seen = std::any_of(caps.begin(), caps.end(), [&](const weather::SphericalCap& c) { return same(c, cap); });
    if (!seen && caps.size() < kMaxLightningAreas) caps.push_back(cap);
  }
  return caps;
}

}  // namespace

std::vector<weather::LightningFlash> LightningService::tick(const LiveWeather& weather, double clock_s,
                                                            std::span<const weather::SphericalCap> areas) {
  const std::optional<double> last = last_s_;
  last_s_ = clock_s;
  if (!last || !(clock_s > *last) || clock_s - *last > kMaxLightningGap_s || !(options_.rate_perMin100km2 > 0))
    return {};
  const std::vector<weather::SphericalCap> caps = distinctCaps(areas);
  // The storm cells change with the weather (a change, a ramp) and as
  // drifting regions move: computed again then, or kStormCellRefresh_s on.
  const bool fresh = cells_ && cellsAccepted_ == weather.accepted() && !weather.changing(clock_s) &&
                     clock_s >= cellsAt_s_ && clock_s - cellsAt_s_ < kStormCellRefresh_s &&
                     std::equal(caps.begin(), caps.end(), cellsCaps_.begin(), cellsCaps_.end(), same);
  if (!fresh) {
    cells_ = stormCellsIn(weather, clock_s, caps, options_.rate_perMin100km2, cache_);
    cellsCaps_ = caps;
    cellsAccepted_ = weather.accepted();
    cellsAt_s_ = clock_s;
  }
  const std::vector<weather::StormCell>& list = *cells_;
  std::size_t dropped = 0;
  std::vector<weather::LightningFlash> flashes =
      weather::drawFlashes(options_.seed, list, *last, clock_s, kMaxFlashesPerTick, &dropped);
  counters_.drawn += flashes.size();
  counters_.dropped += dropped;
  for (const auto& f : flashes) record(f);
  return flashes;
}

weather::LightningFlash LightningService::trigger(const LiveWeather& weather, double clock_s,
                                                  const FlashRequest& request) {
  // The cloud at the place, as a subscriber there would hold it.
  const weather::WeatherSnapshot snapshot =
      subscriberSnapshot(weather, clock_s, {request.lat_deg, request.lon_deg, 1.0}, kLightningTileLevel);
  std::vector<weather::CloudLayer> present;
  for (const weather::CloudLayer& l : snapshot.layers) {
    bool tiled = false, covered = false;
    for (const weather::CoverageTile& t : snapshot.tiles)
      if (t.layerId == l.id) {
        tiled = true;
        covered = covered || t.coverage > 0;
      }
    if (tiled ? covered : l.coverage > 0) present.push_back(l);
  }
  ++counters_.triggered;
  // The seed: the asked-for flashes counted, apart from the process's.
  const weather::LightningFlash f = weather::triggeredFlash(options_.seed ^ (counters_.triggered << 32), clock_s,
                                                            request.lat_deg, request.lon_deg, request.kind, present,
                                                            request.energy_j);
  record(f);
  triggered_.push_back(f);
  while (triggered_.size() > kMaxTriggeredKept) triggered_.pop_front();
  return f;
}

std::vector<weather::LightningFlash> LightningService::drawIn(const LiveWeather& weather, double from_s, double to_s,
                                                              std::span<const weather::SphericalCap> areas,
                                                              bool* computed) {
  if (computed) *computed = false;
  std::vector<weather::LightningFlash> out;
  if (!(to_s > from_s)) return out;
  const std::vector<weather::SphericalCap> caps = distinctCaps(areas);
  if (options_.rate_perMin100km2 > 0) {
    const double start_s = std::floor(to_s / kStormCellRefresh_s) * kStormCellRefresh_s;
    auto kept = std::find_if(requestCells_.begin(), requestCells_.end(), [&](const RequestCells& r) {
      return r.intervalStart_s == start_s && r.accepted == weather.accepted() &&
             std::equal(caps.begin(), caps.end(), r.caps.begin(), r.caps.end(), same);
    });
    if (kept == requestCells_.end()) {
      if (computed) *computed = true;
      ++counters_.requestCellsComputed;
      requestCells_.push_back({start_s, caps, weather.accepted(),
                               stormCellsIn(weather, start_s, caps, options_.rate_perMin100km2, cache_)});
      while (requestCells_.size() > kRequestCellsKept) requestCells_.pop_front();
      kept = std::prev(requestCells_.end());
    }
    out = weather::drawFlashes(options_.seed, kept->cells, from_s, to_s, kMaxFlashesPerRequest);
  }
  for (const weather::LightningFlash& f : triggered_)
    if (f.time_s > from_s && f.time_s <= to_s && out.size() < kMaxFlashesPerRequest &&
        std::any_of(caps.begin(), caps.end(), [&](const weather::SphericalCap& c) { return flashReaches(c, f); }))
      out.push_back(f);
  std::sort(out.begin(), out.end(), [](const auto& a, const auto& b) { return a.time_s < b.time_s; });
  return out;
}

std::vector<weather::LightningFlash> LightningService::recent(std::size_t limit) const {
  const std::size_t n = std::min(limit, recent_.size());
  return {recent_.end() - static_cast<std::ptrdiff_t>(n), recent_.end()};
}

void LightningService::record(const weather::LightningFlash& flash) {
  recent_.push_back(flash);
  while (recent_.size() > kMaxRecentFlashes) recent_.pop_front();
}

bool flashReaches(const weather::SphericalCap& area, const weather::LightningFlash& flash) {
  return sphereDistance_m(area.centerLat_deg, area.centerLon_deg, flash.lat_deg, flash.lon_deg) <=
         area.radius_m + kLightningReach_m;
}

}  // namespace sky::server
