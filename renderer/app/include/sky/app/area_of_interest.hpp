// Which weather a channel asks the server for: a cap around the camera, wide
// enough that the edge of what it draws is never empty, asked again when the
// camera has moved a quarter of its radius. Shared by the live loop and the
// headless replay so both see the same tiles.
#pragma once

#include <cstddef>

#include "sky/geo/geodetic.hpp"
#include "sky/stream/messages.hpp"
#include "sky/weather/tiling.hpp"

namespace sky::app {

// The weather map's fine ring spans 100 km around the camera: 120 km keeps
// its edge filled. (Its coarse ring reaches 600 km; of tiled layers it holds
// only what this area brings.)
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
inline bool needsResubscribe(const geo::Geodetic& subscribedAt, const geo::Geodetic& now) {
  return geo::geodesicDistance_m(subscribedAt.lat_deg, subscribedAt.lon_deg, now.lat_deg, now.lon_deg) >
         kResubscribeDistance_m;
}

}  // namespace sky::app
