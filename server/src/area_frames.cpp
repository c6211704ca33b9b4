// Snapshots and frames shared by the subscribers of one area (see
// area_frames.hpp).
#include "sky/server/area_frames.hpp"

#include "sky/stream/framing.hpp"

namespace sky::server {

bool sameArea(const stream::Subscribe& a, const stream::Subscribe& b) {
  return a.areaIndex == b.areaIndex && a.area.centerLat_deg == b.area.centerLat_deg &&
         a.area.centerLon_deg == b.area.centerLon_deg && a.area.radius_m == b.area.radius_m &&
         a.altMin_m == b.altMin_m && a.altMax_m == b.altMax_m && a.tileLevel == b.tileLevel;
}

Frame encodeWeatherFrame(const AreaSnapshot* held, const AreaSnapshot& now) {
  if (held && sameArea(held->request, now.request)) {
    if (auto delta = diffBuilt(held->built, now.built);
        delta && (delta->tiles.empty() || 4 * delta->tiles.size() < 3 * tileCount(now.built)))
      return stream::encodeFrame(stream::encodeMessage(*delta));
  }
  return stream::encodeFrame(stream::encodeMessage(wholeSnapshot(now.built)));
}

std::shared_ptr<const AreaSnapshot> AreaFrames::snapshot(const stream::Subscribe& request, Clock::time_point now,
                                                         const Build& build) {
  if (now - clearedAt_ >= kAreaSnapshotReuse || snapshots_.size() >= kMaxAreaSnapshots) clear(now);
  const AreaKey key{request.areaIndex, request.area.centerLat_deg, request.area.centerLon_deg,
                    request.area.radius_m,  request.altMin_m,         request.altMax_m,
                    request.tileLevel};
  auto& kept = snapshots_[key];
  if (kept) {
    ++counters_.reused;
    return kept;
  }
  ++counters_.built;
  kept = std::make_shared<const AreaSnapshot>(AreaSnapshot{request, build()});
  return kept;
}

std::shared_ptr<const Frame> AreaFrames::frame(const std::shared_ptr<const AreaSnapshot>& held,
                                               const std::shared_ptr<const AreaSnapshot>& now) {
  auto& e = frames_[{held.get(), now.get()}];
  if (e.frame) {
    ++counters_.shared;
    return e.frame;
  }
  ++counters_.encoded;
  e = {held, now, std::make_shared<const Frame>(encodeWeatherFrame(held.get(), *now))};
  return e.frame;
}

void AreaFrames::clear(Clock::time_point now) {
  snapshots_.clear();
  frames_.clear();
  clearedAt_ = now;
}

}  // namespace sky::server
