// What the subscribers of one area share while the weather stands still:
// the snapshot built for the area, and each frame (Delta or Snapshot) that
// takes a peer from what it holds to it, encoded once. The channels of one
// simulator subscribe the same area around the same camera, so after a
// change they get the same bytes from one build and one encoding. Pure
// bookkeeping on the server's io thread: no I/O.
#pragma once

#include <chrono>
#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <tuple>
#include <utility>
#include <vector>

#include "sky/server/outbox.hpp"
#include "sky/server/snapshot_builder.hpp"
#include "sky/stream/messages.hpp"

namespace sky::server {

// A snapshot as the server keeps it for the subscriptions of one area, and
// the subscription it answers.
struct AreaSnapshot {
  stream::Subscribe request;
  BuiltSnapshot built;
};

// Whether two subscriptions ask for the same snapshot (area index, cap,
// altitudes, tile level).
bool sameArea(const stream::Subscribe& a, const stream::Subscribe& b);

// The frame taking a peer that holds `held` (null: nothing yet) to `now`:
// the Delta from it when the peer holds the same area, a delta can say it
// and it resends under 3/4 of the tiles (tiles are nearly all of either's
// size), else the whole Snapshot.
Frame encodeWeatherFrame(const AreaSnapshot* held, const AreaSnapshot& now);

// How long what AreaFrames keeps answers when the weather does not change
// (it is all dropped then). A fan-out to 512 subscribers takes ~14 ms of
// the io thread (sky_weatherd_bench), so it is served from one build per area; a
// subscriber asking later gets a snapshot no older than this (its clock is
// when it was built: the weather standing still, a renderer advects from
// it).
inline constexpr std::chrono::milliseconds kAreaSnapshotReuse{50};
// Areas kept at most (a peer re-subscribing fast must not grow it without
// bound): past this, everything kept is dropped.
inline constexpr std::size_t kMaxAreaSnapshots = 4096;

class AreaFrames {
 public:
  using Clock = std::chrono::steady_clock;
  using Build = std::function<BuiltSnapshot()>;

  // The snapshot answering `request` at `now`: the one built for its area
  // since the last clear(), else `build()`'s (kept for the next subscriber
  // of the area). What was kept is dropped first when the last clear() is
  // kAreaSnapshotReuse before `now`.
  std::shared_ptr<const AreaSnapshot> snapshot(const stream::Subscribe& request, Clock::time_point now,
                                               const Build& build);
  // encodeWeatherFrame(held, now), encoded once for every peer that holds
  // the same snapshot object and is sent the same one.
  std::shared_ptr<const Frame> frame(const std::shared_ptr<const AreaSnapshot>& held,
                                     const std::shared_ptr<const AreaSnapshot>& now);
  // The weather changed at `now`: nothing kept answers a subscription any more.
  void clear(Clock::time_point now);

  struct Counters {
    std::uint64_t built = 0, reused = 0;    // snapshots
    std::uint64_t encoded = 0, shared = 0;  // frames
  };
  const Counters& counters() const { return counters_; }

 private:
  // By sameArea's fields.
  using AreaKey = std::tuple<std::uint8_t, double, double, double, double, double, int>;
  std::map<AreaKey, std::shared_ptr<const AreaSnapshot>> snapshots_;
  Clock::time_point clearedAt_{};
  // By (held, now): both kept alive here, so no other snapshot takes their address.
  struct Encoded {
    std::shared_ptr<const AreaSnapshot> held, now;
    std::shared_ptr<const Frame> frame;
  };
  std::map<std::pair<const AreaSnapshot*, const AreaSnapshot*>, Encoded> frames_;
  Counters counters_;
};

}  // namespace sky::server
