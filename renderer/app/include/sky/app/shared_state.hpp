// What the network side of a renderer channel hands to its render loop: the
// latest ownship pose from the host (with its time of day), the host's
// atmosphere, the latest state of the channel's view (View Definition, View
// Control), the host's camera exposure and the latest weather from the server.
// Written by the io thread, read by the render loop; guarded by one mutex.
#pragma once

#include <chrono>
#include <cstdint>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

#include "sky/app/host_atmosphere.hpp"
#include "sky/app/host_clock.hpp"
#include "sky/app/view_state.hpp"
#include "sky/cigi/packets.hpp"
#include "sky/geo/geodetic.hpp"
#include "sky/stream/messages.hpp"
#include "sky/weather/clock.hpp"
#include "sky/weather/lightning.hpp"
#include "sky/weather/model.hpp"

namespace sky::app {

struct HostPose {
  geo::GeodeticPose pose;
  std::uint32_t hostFrame = 0;
  double hostTime_s = 0;  // CIGI IG Control timestamp, s (0 when not valid)
  bool hostTimeValid = false;  // the host marked its timestamp valid
  std::string host;  // the host's address, as its datagrams came from (keys its shared clock)
  std::uint64_t sequence = 0;  // increments with every pose received
  std::chrono::steady_clock::time_point receivedAt;
  // The time of day at this pose (s since 1970) and where it came from
  // (host_clock.hpp); none: the fixed --sun angles light the frame.
  std::optional<double> utc_s;
  TimeSource timeSource = TimeSource::Fixed;
};

struct WeatherView {
  weather::WeatherSnapshot snapshot;  // of the detailed area around the camera (area index 0)
  // Of the wide area at coarse tiles (area index 1), for the weather map's
  // coarse ring; none before it arrives or from a server without areas.
  std::optional<weather::WeatherSnapshot> coarse;
  std::uint64_t version = 0;  // increments with every snapshot and delta applied, of either area
  std::uint64_t coarseVersion = 0;  // of the coarse area's alone
  // The server's weather clock, re-anchored on every Hello, Snapshot, Delta
  // and Heartbeat (protocol/'s WeatherClock: the same formula as the server's).
  weather::WeatherClock clock;
  bool connected = false;
  // Lightning flashes the server sent, oldest first: those still giving
  // light (kFlashLifetime_s plus kFlashGrace_s after the newest message's
  // clock), at most kMaxHeldFlashes.
  std::vector<weather::LightningFlash> flashes;

  double clockNow(std::chrono::steady_clock::time_point now) const { return clock.at(now); }
};

// Flashes a channel holds at most (a storm flashes a few times a second),
// and how long past its light one is kept (a frame drawn a little behind
// the stream's clock still sees it).
inline constexpr std::size_t kMaxHeldFlashes = 256;
inline constexpr double kFlashGrace_s = 2.0;

class SharedState {
 public:
  void setPose(const HostPose& p) {
    std::lock_guard lock(mutex_);
    HostPose next = p;
    next.sequence = (pose_ ? pose_->sequence : lastSequence_) + 1;
    pose_ = next;
  }
  std::optional<HostPose> pose() const {
    std::lock_guard lock(mutex_);
    return pose_;
  }
  // The host put the IG in Reset/Standby: forgets the pose (no frame is
  // drawn until the next one) and counts a reset, after which the render
  // loop drops the renderer's temporal history.
  void resetChannel() {
    std::lock_guard lock(mutex_);
    if (pose_) lastSequence_ = pose_->sequence;
    pose_.reset();
    ++resets_;
  }
  std::uint64_t resets() const {
    std::lock_guard lock(mutex_);
    return resets_;
  }

  // The host's global atmosphere (Atmosphere Control), latest wins.
  void setAtmosphere(const HostAtmosphere& a) {
    std::lock_guard lock(mutex_);
    atmosphere_ = a;
  }
  // The host's camera exposure for this channel (CIGI camera exposure
  // component): held until the host sends another.
  void setHostExposure(const cigi::CameraExposureControl& e) {
    std::lock_guard lock(mutex_);
    hostExposure_ = e;
  }
  std::optional<cigi::CameraExposureControl> hostExposure() const {
    std::lock_guard lock(mutex_);
    return hostExposure_;
  }
  HostAtmosphere atmosphere() const {
    std::lock_guard lock(mutex_);
    return atmosphere_;
  }

  // The view this channel draws; main sets its id and the command line's
  // frustum before the listener starts.
  void setView(const ChannelView& v) {
    std::lock_guard lock(mutex_);
    view_ = v;
  }
  ChannelView view() const {
    std::lock_guard lock(mutex_);
    return view_;
  }
  // Applies a View Definition or View Control (applyViewPacket) to the view held.
  template <class ViewPacket>
  ViewUpdate applyView(const ViewPacket& packet) {
    std::lock_guard lock(mutex_);
    return applyViewPacket(view_, packet);
  }

  // Takes the snapshot of its area (WeatherSnapshot::areaIndex: 0 detailed,
  // 1 coarse; no other index gets past the stream's decoder).
  void setSnapshot(weather::WeatherSnapshot s, std::chrono::steady_clock::time_point now) {
    std::lock_guard lock(mutex_);
    weather_.clock = weather::WeatherClock(s.weatherClock_s, weather_.clock.rate(), now);
    if (s.areaIndex == 1) {
      weather_.coarse = std::move(s);
      ++weather_.coarseVersion;
    } else {
      weather_.snapshot = std::move(s);
      detailedSeen_ = true;
    }
    ++weather_.version;
  }
  // Keeps the flashes of a Lightning message (events: each arrives once).
  // A flash already held (the same seed and time: a replay's answer that
  // overlaps the last, or the live stream's copy of one asked for) is kept once.
  void addFlashes(const std::vector<weather::LightningFlash>& flashes, double clock_s) {
    std::lock_guard lock(mutex_);
    auto& held = weather_.flashes;
    for (const weather::LightningFlash& f : flashes)
      if (std::none_of(held.begin(), held.end(),
                       [&](const weather::LightningFlash& h) { return h.seed == f.seed && h.time_s == f.time_s; }))
        held.push_back(f);
    std::stable_sort(held.begin(), held.end(),
                     [](const weather::LightningFlash& a, const weather::LightningFlash& b) { return a.time_s < b.time_s; });
    std::erase_if(held, [clock_s](const weather::LightningFlash& f) {
      return f.time_s + weather::kFlashLifetime_s < clock_s - kFlashGrace_s;
    });
    if (held.size() > kMaxHeldFlashes) held.erase(held.begin(), held.end() - static_cast<std::ptrdiff_t>(kMaxHeldFlashes));
  }
  // Applies a Delta to the held snapshot of its area; on error nothing changes.
  Result<void> applyDelta(const weather::WeatherDelta& d, std::chrono::steady_clock::time_point now) {
    std::lock_guard lock(mutex_);
    weather::WeatherSnapshot* target = d.areaIndex == 1 ? (weather_.coarse ? &*weather_.coarse : nullptr)
                                                        : (detailedSeen_ ? &weather_.snapshot : nullptr);
    if (target == nullptr)
      return fail(ErrorCode::InvalidArgument, "Delta of area " + std::to_string(d.areaIndex) + " before its Snapshot");
    if (auto r = weather::applyDelta(*target, d); !r) return r;
    weather_.clock = weather::WeatherClock(d.weatherClock_s, weather_.clock.rate(), now);
    if (d.areaIndex == 1) ++weather_.coarseVersion;
    ++weather_.version;
    return {};
  }
  // Forgets the coarse area's snapshot (a server that does not answer it
  // would leave it stale for good).
  void dropCoarse() {
    std::lock_guard lock(mutex_);
    if (!weather_.coarse) return;
    weather_.coarse.reset();
    ++weather_.version;
  }
  void setClock(double clock_s, double rate, std::chrono::steady_clock::time_point now) {
    std::lock_guard lock(mutex_);
    weather_.clock = weather::WeatherClock(clock_s, rate, now);
  }
  // The offset the server holds for a host's clock (host_locked_clock.hpp),
  // latest wins; none after a (re)connect until the server sends one.
  void setHostClock(std::optional<stream::HostClock> h) {
    std::lock_guard lock(mutex_);
    hostClock_ = std::move(h);
  }
  // The end of the last interval the server answered a LightningRequest for
  // (WeatherClient::requestLightning); unset before the first answer.
  void setLightningAnsweredTo(double to_s) {
    std::lock_guard lock(mutex_);
    lightningAnsweredTo_s_ = to_s;
  }
  std::optional<double> lightningAnsweredTo() const {
    std::lock_guard lock(mutex_);
    return lightningAnsweredTo_s_;
  }
  std::optional<stream::HostClock> hostClock() const {
    std::lock_guard lock(mutex_);
    return hostClock_;
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
  std::uint64_t coarseVersion() const {
    std::lock_guard lock(mutex_);
    return weather_.coarseVersion;
  }

 private:
  mutable std::mutex mutex_;
  std::optional<cigi::CameraExposureControl> hostExposure_;
  std::optional<HostPose> pose_;
  std::uint64_t lastSequence_ = 0;  // of the pose a reset forgot: sequences never repeat
  std::uint64_t resets_ = 0;
  HostAtmosphere atmosphere_;
  ChannelView view_;
  WeatherView weather_;
  bool detailedSeen_ = false;  // a Snapshot of area 0 has arrived
  std::optional<stream::HostClock> hostClock_;
  std::optional<double> lightningAnsweredTo_s_;
};

}  // namespace sky::app
