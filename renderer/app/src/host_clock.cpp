// A channel's time of day from its host (see host_clock.hpp).
#include "sky/app/host_clock.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "sky/cigi/celestial_time.hpp"

namespace sky::app {

const char* toString(TimeSource source) {
  switch (source) {
    case TimeSource::CommandLine: return "command-line";
    case TimeSource::Cigi: return "cigi";
    case TimeSource::FlightGear: return "flightgear";
    case TimeSource::FlightFile: return "flight-file";
    case TimeSource::Fixed: break;
  }
  return "fixed";
}

std::optional<double> parseUtc(const char* text) {
  int y = 0, mo = 0, d = 0, h = 0, mi = 0, s = 0, used = 0;
  if (std::sscanf(text, "%4d-%2d-%2dT%2d:%2d:%2dZ%n", &y, &mo, &d, &h, &mi, &s, &used) != 6 || used != 20 ||
      text[used] != '\0' || s < 0 || s > 59)
    return std::nullopt;
  cigi::CelestialSphereControl c;
  c.dateMmddyyyy = static_cast<std::uint32_t>(mo * 1000000 + d * 10000 + y);
  if (mo < 1 || mo > 12 || d < 1 || d > 31 || y < 0 || h < 0 || h > 23 || mi < 0 || mi > 59) return std::nullopt;
  c.hour = static_cast<std::uint8_t>(h);
  c.minute = static_cast<std::uint8_t>(mi);
  const auto minute = cigi::celestialUtc(c);
  if (!minute) return std::nullopt;
  return static_cast<double>(*minute + s);
}

double HostTimeline::advance(bool timestampValid, std::uint32_t timestamp_10us,
                             std::chrono::steady_clock::time_point arrival) {
  double step_s = 0;
  if (timestampValid && lastStamp_) {
    // The difference of two 32-bit tick counts as a signed 32-bit number:
    // right across the counter's wrap, and negative for a host going back.
    step_s = static_cast<std::int32_t>(timestamp_10us - *lastStamp_) * 1.0e-5;
  } else if (lastArrival_) {
    step_s = std::chrono::duration<double>(arrival - *lastArrival_).count();
  }
  if (std::abs(step_s) <= kMaxHostStep_s) now_s_ += step_s;
  lastStamp_ = timestampValid ? std::optional(timestamp_10us) : std::nullopt;
  lastArrival_ = arrival;
  return now_s_;
}

HostClock::HostClock(std::optional<double> startUtc_s) : anchorUtc_s_(startUtc_s) {
  if (startUtc_s) source_ = TimeSource::CommandLine;
}

void HostClock::advanceTo(double hostTime_s) {
  if (!hostSeen_) anchorHost_s_ = hostTime_s;  // --utc is the time of the first host time
  hostSeen_ = true;
  hostNow_s_ = hostTime_s;
}

void HostClock::set(double utc_s, double resolution_s, TimeSource source) {
  const auto running = utcAt(hostNow_s_);
  anchorUtc_s_ = running ? std::clamp(*running, utc_s, utc_s + resolution_s) : utc_s;
  anchorHost_s_ = hostNow_s_;
  hostSeen_ = true;
  source_ = source;
}

std::optional<double> HostClock::utcAt(double hostTime_s) const {
  if (!anchorUtc_s_) return std::nullopt;
  return *anchorUtc_s_ + (hostSeen_ ? hostTime_s - anchorHost_s_ : 0.0);
}

}  // namespace sky::app
