// The server's lightning: the flash process (sky/weather/lightning.hpp) run
// on the weather clock over the storms of the areas renderers watch, the
// flashes an operator asks for, and the recent flashes for the API. Each
// flash is an event sent once to the subscribers it reaches; a storm nobody
// watches draws no flashes (the process is seeded per cell and second, so a
// renderer that subscribes later sees the same flashes another already did).
// Runs on the io thread; pure bookkeeping, no I/O.
#pragma once

#include <cstddef>
#include <cstdint>
#include <deque>
#include <optional>
#include <span>
#include <vector>

#include "sky/weather/lightning.hpp"
#include "sky/weather/tiling.hpp"

namespace sky::server {

class LiveWeather;
class TileCache;

struct LightningOptions {
  // Flashes a minute per 100 km^2 of cumulonimbus at density 1; 0 draws none
  // (asked-for flashes still go out).
  double rate_perMin100km2 = weather::kDefaultFlashRate_perMin100km2;
  std::uint64_t seed = 1;
};

// Storm cells are S2 cells of this level (~80 km^2, a thunderstorm cell's
// size), whatever a subscriber's own tile level: so every area that holds a
// storm draws the same flashes from it.
inline constexpr int kLightningTileLevel = 10;
// Flashes are drawn within this distance of an area's centre (a flash
// farther than that is below the horizon of a camera near it, or hidden in
// haze): it bounds the cells per area to ~900.
inline constexpr double kLightningReach_m = 150e3;
inline constexpr std::size_t kMaxLightningAreas = 64;
inline constexpr std::size_t kMaxFlashesPerTick = 256;
inline constexpr std::size_t kMaxRecentFlashes = 1000;
inline constexpr std::size_t kMaxFlashesPerRequest = 1024;  // stream::kMaxMessageFlashes
inline constexpr std::size_t kMaxTriggeredKept = 256;
// A clock that moved by more than this between ticks (set, jumped, or
// frozen and restarted) draws nothing for the gap.
inline constexpr double kMaxLightningGap_s = 60;
// The storm cells are computed again at least this often (s of weather
// clock) while the weather stands still: drifting regions move a few
// hundred metres in that time, a small part of a 9 km cell.
inline constexpr double kStormCellRefresh_s = 10;
// The storm cells of LightningRequests kept: one per (refresh interval,
// areas, weather version); a replay's frames ask within one interval for
// hundreds of frames, several channels of it for the same areas.
inline constexpr std::size_t kRequestCellsKept = 16;

// What an operator asks for (POST /api/events).
struct FlashRequest {
  double lat_deg = 0, lon_deg = 0;
  weather::FlashKind kind = weather::FlashKind::CloudToGround;
  double energy_j = weather::kTypicalFlashEnergy_j;
};

class LightningService {
 public:
  // cache (if given, outliving the service, used on the calling thread
  // only): where the storm cells' snapshots keep their coverings and the
  // tiles of layers no change touched, as the subscribers' do. Without it
  // the storm cells of 64 areas took ~100 ms of the server's io thread once
  // a second during a storm of changes (measured with sky_weatherd_bench
  // --regional 1 at 256 subscribers).
  explicit LightningService(LightningOptions options, TileCache* cache = nullptr)
      : options_(options), cache_(cache) {}

  // The process's flashes since the last tick, with first strokes up to
  // clock_s, in the storms of `areas`.
  std::vector<weather::LightningFlash> tick(const LiveWeather& weather, double clock_s,
                                            std::span<const weather::SphericalCap> areas);
  // A flash now at the request's place, under the cloud there.
  weather::LightningFlash trigger(const LiveWeather& weather, double clock_s, const FlashRequest& request);
  // Every flash of the process in the weather-clock interval (from_s, to_s]
  // over the storms of `areas` (the weather as it stands at to_s), and the
  // asked-for flashes of that interval that reach them, at most
  // kMaxFlashesPerRequest, the earliest: what a renderer drawing frames at
  // its own clock asks for (stream::LightningRequest). The same process as
  // tick's, so it draws the same flashes for the same storms and seconds;
  // nothing is recorded or counted as drawn. The storm cells are those at
  // the start of to_s's kStormCellRefresh_s interval of weather clock,
  // whatever was asked before (an answer depends only on the weather and
  // the interval): kept, so the frames of one interval compute them once.
  // `computed` (if given) says whether this call had to compute them, the
  // cost (~6 ms per 150 km area over storms) a session's budget counts.
  std::vector<weather::LightningFlash> drawIn(const LiveWeather& weather, double from_s, double to_s,
                                              std::span<const weather::SphericalCap> areas,
                                              bool* computed = nullptr);
  // The newest flashes, oldest first, at most `limit`.
  std::vector<weather::LightningFlash> recent(std::size_t limit) const;

  struct Counters {
    std::uint64_t drawn = 0, triggered = 0, dropped = 0;
    std::uint64_t requestCellsComputed = 0;  // drawIn calls that computed their storm cells
  };
  const Counters& counters() const { return counters_; }

 private:
  void record(const weather::LightningFlash& flash);

  LightningOptions options_;
  TileCache* cache_;
  std::optional<double> last_s_;
  // The storm cells of the last areas (a tick costs ~3 ms per 150 km area
  // to compute them, measured in lightning_test.cpp): kept while the
  // weather, its changes and the areas stand still.
  std::optional<std::vector<weather::StormCell>> cells_;
  std::vector<weather::SphericalCap> cellsCaps_;
  std::uint64_t cellsAccepted_ = 0;
  double cellsAt_s_ = 0;
  std::deque<weather::LightningFlash> recent_;
  std::deque<weather::LightningFlash> triggered_;  // the asked-for ones, for drawIn
  struct RequestCells {
    double intervalStart_s = 0;
    std::vector<weather::SphericalCap> caps;
    std::uint64_t accepted = 0;
    std::vector<weather::StormCell> cells;
  };
  std::deque<RequestCells> requestCells_;  // newest last, at most kRequestCellsKept
  Counters counters_;
};

// Whether a flash is within an area a subscriber asked for (its cap, widened
// by kLightningReach_m: a flash lights the sky beyond the tiles one holds).
bool flashReaches(const weather::SphericalCap& area, const weather::LightningFlash& flash);

}  // namespace sky::server
