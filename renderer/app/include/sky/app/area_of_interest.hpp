// Which weather a channel asks the server for: two caps around the camera,
// each asked again when the camera has moved far enough. The detailed area
// (index 0) fills the weather map's fine ring, the wide one at coarse tiles
// (index 1) its coarse ring. Shared by the live loop and the headless replay
// so both see the same tiles.
#pragma once

#include <cstddef>
#include <optional>
#include <vector>

#include "sky/geo/geodetic.hpp"
#include "sky/stream/messages.hpp"
#include "sky/weather/tiling.hpp"

namespace sky::app {

// The weather map's fine ring spans 100 km around the camera: 120 km keeps
// its edge filled.
inline constexpr double kSubscribeRadius_m = 120000.0;
inline constexpr double kResubscribeDistance_m = 30000.0;
// The finest S2 level whose covering of that cap stays within this many tiles
// (level 11 for 120 km: cells about 4.9 km across, ~1900 tiles). The real
// weather tiles (~1 km) come with the weather-texture rings of the renderer issue.
inline constexpr std::size_t kMaxSubscribedTiles = 4096;

inline stream::Subscribe areaAround(const geo::GeodeticPose& pose) {
  stream::Subscribe s;
  s.area = {pose.position.lat_deg, pose.position.lon_deg, kSubscribeRadius_m};
  s.altMin_m = -500;
  s.altMax_m = 20000;
  s.tileLevel = weather::levelForRadius(kSubscribeRadius_m, kMaxSubscribedTiles);
  return s;
}

// Whether the camera has left the area subscribed around `subscribedAt`
// far enough to ask again.
inline bool needsResubscribe(const geo::Geodetic& subscribedAt, const geo::Geodetic& now,
                             double distance_m = kResubscribeDistance_m) {
  return geo::geodesicDistance_m(subscribedAt.lat_deg, subscribedAt.lon_deg, now.lat_deg, now.lon_deg) >
         distance_m;
}

// The coarse ring reaches 600 km east, west, north and south of the map's
// anchor (850 km to its corners), beyond any horizon a deck is seen to from
// an airliner (~550 km for a deck at 2 km seen from 12 km). A 900 km cap
// asked again every 100 km keeps 800 km around the camera filled, the ring's
// sides and most of its corners. S2 level 9 (~18 km cells; the ring's texels
// are 4.7 km, and the procedural cloud map adds the shapes) is ~7000 tiles a
// varying layer, ~450 kB of a frame for four.
inline constexpr double kCoarseSubscribeRadius_m = 900000.0;
inline constexpr double kCoarseResubscribeDistance_m = 100000.0;
inline constexpr std::size_t kMaxCoarseTiles = 12000;

inline stream::Subscribe coarseAreaAround(const geo::GeodeticPose& pose) {
  stream::Subscribe s = areaAround(pose);
  s.area.radius_m = kCoarseSubscribeRadius_m;
  s.tileLevel = weather::levelForRadius(kCoarseSubscribeRadius_m, kMaxCoarseTiles);
  s.areaIndex = 1;
  return s;
}

// When to ask for each area again as the camera moves: update() gives the
// Subscribes to send for this pose (both on the first call).
class AreaTracker {
 public:
  std::vector<stream::Subscribe> update(const geo::GeodeticPose& pose) {
    std::vector<stream::Subscribe> out;
    if (!fineAt_ || needsResubscribe(*fineAt_, pose.position)) {
      out.push_back(areaAround(pose));
      fineAt_ = pose.position;
    }
    if (!coarseAt_ || needsResubscribe(*coarseAt_, pose.position, kCoarseResubscribeDistance_m)) {
      out.push_back(coarseAreaAround(pose));
      coarseAt_ = pose.position;
    }
    return out;
  }

 private:
  std::optional<geo::Geodetic> fineAt_, coarseAt_;
};

}  // namespace sky::app
