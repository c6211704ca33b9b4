// A channel's time of day (UTC), which places the sun and the moon
// (FrameInputs::utc_s): set by the host (CIGI Celestial Sphere Control, to
// the minute; FlightGear's cur_time, to the second) or by --utc, and
// advanced between those by the host's own time line, so a paused host
// holds the sun and a host at 10x moves it ten times as fast. The weather
// clock is another clock (shared_state.hpp) and is not touched here.
// Pure and single-threaded: the listeners own one each.
#pragma once

#include <chrono>
#include <cstdint>
#include <optional>

namespace sky::app {

// Where a frame's UTC came from (frames.jsonl "utc_source").
enum class TimeSource { Fixed, CommandLine, Cigi, FlightGear, FlightFile };
// "fixed" (the --sun-azimuth/--sun-elevation angles), "command-line",
// "cigi", "flightgear", "flight-file".
const char* toString(TimeSource source);

// Parses --utc's YYYY-MM-DDTHH:MM:SSZ into s since 1970 (years 1900-2100,
// a calendar date); nullopt for anything else.
std::optional<double> parseUtc(const char* text);

// A host step of more than this between two datagrams, s, either way, is a
// restart or a jump of the host's time line, not time passing: the time of
// day holds across it. 60 s: a host at 10x sending 1 datagram per second
// moves 10 s; a host restart jumps by its uptime.
inline constexpr double kMaxHostStep_s = 60;

// The host's own time line, s, continuous: CIGI IG Control's timestamp
// (10 us ticks, unwrapped across its 11.9 h wrap) while it is valid, so the
// host's pause and speed-up are the time line's; else the arrival (wall)
// time of its datagrams: a host that sends no timestamps is taken to run in
// real time (its frame rate is not known, so its frame counter is not used).
class HostTimeline {
 public:
  // The time line at a datagram received at `arrival`; timestamp_10us used
  // when timestampValid. Steps beyond kMaxHostStep_s count as 0.
  double advance(bool timestampValid, std::uint32_t timestamp_10us, std::chrono::steady_clock::time_point arrival);
  double now_s() const { return now_s_; }

 private:
  double now_s_ = 0;
  std::optional<std::uint32_t> lastStamp_;  // of the previous datagram, when it was valid
  std::optional<std::chrono::steady_clock::time_point> lastArrival_;
};

class HostClock {
 public:
  // startUtc_s: --utc (s since 1970), the time of day from the first host
  // time on; none: no time of day until a host gives one (source Fixed).
  explicit HostClock(std::optional<double> startUtc_s = std::nullopt);

  // The host's time line reached hostTime_s (HostTimeline::advance).
  void advanceTo(double hostTime_s);

  // The host says the time of day is in [utc_s, utc_s + resolution_s) now
  // (CIGI: the minute, 60 s; FlightGear: the second, 1 s). A running time
  // inside that window is kept (so the sub-minute part keeps advancing and a
  // host repeating the same minute does not pull the sun back); outside it,
  // the time is moved to the nearer end of the window, so the first minute
  // change after a start sets it to the second.
  void set(double utc_s, double resolution_s, TimeSource source);

  // UTC at host time hostTime_s (s since 1970), nullopt without one.
  std::optional<double> utcAt(double hostTime_s) const;
  // UTC at the newest host time.
  std::optional<double> utc_s() const { return utcAt(hostNow_s_); }
  TimeSource source() const { return source_; }

 private:
  double hostNow_s_ = 0;
  bool hostSeen_ = false;
  std::optional<double> anchorUtc_s_;  // UTC at host time anchorHost_s_
  double anchorHost_s_ = 0;
  TimeSource source_ = TimeSource::Fixed;
};

}  // namespace sky::app
