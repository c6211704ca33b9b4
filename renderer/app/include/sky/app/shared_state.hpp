// What the network side of a renderer channel hands to its render loop: the
// latest ownship pose from the host and the latest weather from the server.
// Written by the io thread, read by the render loop; guarded by one mutex.
#pragma once

#include <chrono>
#include <cstdint>
#include <mutex>
#include <optional>

#include "sky/geo/geodetic.hpp"
#include "sky/weather/clock.hpp"
#include "sky/weather/model.hpp"

namespace sky::app {

struct HostPose {
  geo::GeodeticPose pose;
  std::uint32_t hostFrame = 0;
  double hostTime_s = 0;  // CIGI IG Control timestamp, s (0 when not valid)
  std::uint64_t sequence = 0;  // increments with every pose received
  std::chrono::steady_clock::time_point receivedAt;
};

struct WeatherView {
  weather::WeatherSnapshot snapshot;
  std::uint64_t version = 0;  // increments with every snapshot received
  // The server's weather clock, re-anchored on every Hello, Snapshot, Delta
  // and Heartbeat (protocol/'s WeatherClock: the same formula as the server's).
  weather::WeatherClock clock;
  bool connected = false;

  double clockNow(std::chrono::steady_clock::time_point now) const { return clock.at(now); }
};

class SharedState {
 public:
  void setPose(const HostPose& p) {
    std::lock_guard lock(mutex_);
    HostPose next = p;
    next.sequence = pose_ ? pose_->sequence + 1 : 1;
    pose_ = next;
  }
  std::optional<HostPose> pose() const {
    std::lock_guard lock(mutex_);
    return pose_;
  }

  void setSnapshot(weather::WeatherSnapshot s, std::chrono::steady_clock::time_point now) {
    std::lock_guard lock(mutex_);
    weather_.clock = weather::WeatherClock(s.weatherClock_s, weather_.clock.rate(), now);
    weather_.snapshot = std::move(s);
    ++weather_.version;
  }
  // Applies a Delta to the held snapshot; on error nothing changes.
  Result<void> applyDelta(const weather::WeatherDelta& d, std::chrono::steady_clock::time_point now) {
    std::lock_guard lock(mutex_);
    if (weather_.version == 0)
      return fail(ErrorCode::InvalidArgument, "Delta before any Snapshot");
    if (auto r = weather::applyDelta(weather_.snapshot, d); !r) return r;
    weather_.clock = weather::WeatherClock(d.weatherClock_s, weather_.clock.rate(), now);
    ++weather_.version;
    return {};
  }
  void setClock(double clock_s, double rate, std::chrono::steady_clock::time_point now) {
    std::lock_guard lock(mutex_);
    weather_.clock = weather::WeatherClock(clock_s, rate, now);
  }
  void setConnected(bool c) {
    std::lock_guard lock(mutex_);
    weather_.connected = c;
  }
  WeatherView weather() const {
    std::lock_guard lock(mutex_);
    return weather_;
  }
  std::uint64_t weatherVersion() const {
    std::lock_guard lock(mutex_);
    return weather_.version;
  }

 private:
  mutable std::mutex mutex_;
  std::optional<HostPose> pose_;
  WeatherView weather_;
};

}  // namespace sky::app
