// The vocabulary of changes to the weather: what the console, the HTTP API,
// CIGI Weather Control / Environmental Region Control, METAR batches and
// scenario timelines submit. Every source maps its input onto these; the
// WeatherService validates, commits to disk, then applies them, so every
// source gets the same checks and the same durability.
#pragma once

#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <variant>
#include <vector>

#include "sky/core/result.hpp"
#include "sky/weather/model.hpp"
#include "sky/weather/region.hpp"

namespace sky::server {

// When a change takes effect and how it arrives. Times are on the weather
// clock (so a ramp at rate x60 completes 60 times faster in wall time).
struct Timing {
  std::optional<double> at_s;  // start at this clock; none: now. Not in the past.
  double ramp_s = 0;           // [0, 86400]; 0: at once. Numbers ramp linearly
                               // from their value at the start; types switch
                               // through the tile blend.
};

// Add a global layer, or change one (matched by id).
struct SetLayer {
  weather::CloudLayer layer;
  Timing timing;
};
// Remove a global layer (a ramp first fades its coverage to 0).
struct RemoveLayer {
  std::uint32_t layerId = 0;
  Timing timing;
};
// Add or change a region (matched by id); a ramp grows it from its current
// size (or from zero size for a new region) and fades its layers in.
struct SetRegion {
  weather::Region region;
  Timing timing;
};
struct RemoveRegion {
  std::uint32_t regionId = 0;
  Timing timing;
};
// The weather clock: pause (rate 0), run at a rate, or jump.
struct SetClock {
  std::optional<double> rate;     // [0, 3600]
  std::optional<double> jumpTo_s; // finite
};
using WeatherChange = std::variant<SetLayer, RemoveLayer, SetRegion, RemoveRegion, SetClock>;

// Several changes applied as one (a METAR batch, a scenario's initial
// weather): all are accepted or none is.
struct ChangeRequest {
  std::vector<WeatherChange> changes;  // applied atomically, in order; 1..256
  std::string author;                  // who: a console user, "cigi:127.0.0.1:5000", "scenario"
  std::string source;                  // "console", "api", "cigi", "metar", "scenario"
};

// What a successful submit returns once the change is on disk.
struct AppliedChange {
  std::uint64_t sequence = 0;  // strictly increasing over the server's life, across restarts
  double clock_s = 0;          // weather clock when it was accepted
  std::string summary;         // one line for the event log: "layer 2 coverage 0.30 -> 0.90 over 600 s"
};

// A change accepted but not finished (scheduled for later, or ramping), or
// one a scenario's timeline will make.
struct PendingChange {
  std::uint64_t sequence = 0;     // 0 for a timeline entry (not accepted yet)
  double start_s = 0, end_s = 0;  // weather clock
  std::string summary;
  std::string kind = "ramp";      // "ramp": accepted; "timeline": a scenario will submit it at start_s
};

// One line of the event log.
// The longest summary an event keeps, in bytes: a batch of 256 changes
// names each (about 90 bytes a region), and the event log, the console and
// a NATS log entry take the first of it (LiveWeather::commit).
inline constexpr std::size_t kMaxEventSummary_bytes = 2048;

struct ChangeEvent {
  std::uint64_t sequence = 0;
  double clock_s = 0;
  std::int64_t wallTime_ms = 0;  // Unix time when accepted
  std::string author, source, summary;
};

// The weather as every reader sees it at one clock: layers and regions with
// ramps evaluated, what is still pending, and the clock.
struct WeatherView {
  double clock_s = 0;
  double clockRate = 1;
  std::vector<weather::CloudLayer> layers;
  std::vector<weather::Region> regions;
  std::vector<PendingChange> pending;
  std::uint64_t lastSequence = 0;
  std::uint64_t version = 0;  // changes whenever anything a subscriber sees may have changed
};

// The one place changes enter. Implemented over the SQLite store; used by the
// HTTP API, the CIGI weather input, METAR and scenario loading. Called on the
// server's io thread only.
class WeatherService {
 public:
  virtual ~WeatherService() = default;
  // Validates the whole request against the state it would apply to; commits
  // it to disk; applies it; then returns. On error nothing changed, and the
  // error names the change and field: "changes[1].layer.coverage: 1.4 outside
  // [0, 1]" (InvalidArgument), or Io when the commit failed.
  virtual Result<AppliedChange> submit(const ChangeRequest& request) = 0;
  // As submit, for inputs that acknowledge nothing (CIGI datagrams): the
  // change is applied at once and reaches disk with the next flush() (or the
  // next submit), so a burst of changes costs one commit. Only changes not
  // yet flushed can be lost in a crash. Default: submit.
  virtual Result<AppliedChange> submitBatched(const ChangeRequest& request) { return submit(request); }
  // Commits whatever submitBatched applied since the last commit. Io when
  // the commit failed (the changes stay pending for the next try).
  virtual Result<void> flush() { return {}; }
  // The state at the current clock.
  virtual WeatherView view() const = 0;
  // The newest `limit` events, oldest first.
  virtual std::vector<ChangeEvent> events(std::size_t limit) const = 0;
};

}  // namespace sky::server
