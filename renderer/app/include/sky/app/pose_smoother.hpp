// Turns the irregular pose samples of a simulator feed (FlightGear's
// --native-fdm: a few Hz, stalls of seconds, a stray first packet) into a
// camera pose at any render time: interpolated between samples, extrapolated
// for a bounded time, held after that, outliers dropped. Pure: every time is
// passed in, nothing is read from a clock, so it is unit-tested directly.
#pragma once

#include <chrono>
#include <cstdint>
#include <deque>
#include <optional>
#include <vector>

#include "sky/geo/geodetic.hpp"
#include "sky/geo/vec3.hpp"

namespace sky::app {

using SteadyTime = std::chrono::steady_clock::time_point;

struct PoseSample {
  SteadyTime receivedAt;  // arrival time at the renderer (the only clock the feed shares with us)
  geo::GeodeticPose pose;
  // Ground velocity in the local north-east-down frame, m/s, when the feed
  // carries it (FGNetFDM v_north/v_east/v_down); else estimated from the last
  // two samples.
  std::optional<geo::Vec3d> velocityNed_mps;
};

struct PoseSmootherConfig {
  // Render time lags the clock by this much so that it usually falls between
  // two received samples. 0.15 s: the FlightGear capture in tests/data has a
  // median packet interval of 0.11 s (about 9 Hz at --native-fdm rate 10);
  // about one and a half intervals.
  double renderDelay_s = 0.15;
  // Beyond the newest sample the pose is extrapolated at most this long, then
  // held: 2 s bridges FlightGear's frequent sub-second hiccups at full speed,
  // while a multi-second stall (seen: 5.9 s) does not fly the camera off on a
  // guess.
  double maxExtrapolation_s = 2.0;
  // A sample implying a faster move than this from the track is an outlier
  // until confirmed. 1000 m/s: no aircraft a sky renderer serves flies faster
  // (Mach 3 at altitude is ~890 m/s), while FlightGear's stray first packet
  // (default airport, thousands of km away) is far beyond it.
  double maxPlausibleSpeed_mps = 1000.0;
  // Distance always plausible between two samples regardless of their time
  // difference: absorbs arrival jitter (two packets in one burst) and the
  // metre-level noise of a flight model. 50 m.
  double plausibleSlack_m = 50.0;
  // Consecutive mutually plausible samples that confirm a jump as a teleport
  // (or the very first position): 2, i.e. one packet of confirmation.
  std::size_t confirmSamples = 2;
  // When new data changes the pose at the current render time (a late
  // packet, the end of a stall), the difference fades out exponentially with
  // this time constant instead of jumping: 0.5 s hides a metre of correction
  // per frame at 30 Hz and absorbs a ~100 m post-stall catch-up within ~2 s.
  double convergenceTimeConstant_s = 0.5;
  // Corrections larger than this are not blended but applied at once (a
  // confirmed teleport, a reposition in the simulator): 1000 m.
  double maxBlendDistance_m = 1000.0;
  // Samples kept; the render time only ever needs the last few. 64.
  std::size_t historySamples = 64;
  // A sample stamped earlier than the newest by more than this is not a late
  // packet but another clock (or a bogus stamp before it): it starts a
  // candidate track in the new time base, confirmed like a teleport. 1 s:
  // ten FlightGear packet intervals, far beyond the reordering of loopback
  // or a LAN.
  double maxBackstep_s = 1.0;
};

enum class SmoothingMode { Interpolated, Extrapolated, Held };

struct SmoothedPose {
  geo::GeodeticPose pose;
  SteadyTime renderTime;  // the time this pose is for (never decreases between calls)
  SmoothingMode mode = SmoothingMode::Interpolated;
};

class PoseSmoother {
 public:
  explicit PoseSmoother(PoseSmootherConfig config = {});

  // Adds a received sample. Samples should arrive in receivedAt order; one
  // not later than the newest is moved just after it, unless it is more than
  // maxBackstep_s earlier (then it is a candidate in a new time base, as
  // below). An implausible jump is kept apart until confirmSamples
  // consecutive samples confirm it (then it replaces the track: a teleport)
  // or a plausible sample shows it was an outlier.
  // A sample with a non-finite or out-of-range value (latitude outside
  // [-90, 90], longitude outside [-360, 360], altitude outside (-12000 m,
  // 1e7 m), pitch beyond +-90.1 deg, yaw or roll beyond +-720 deg) is
  // dropped and counted (invalidDropped) and changes nothing; a velocity that
  // is non-finite or faster than maxPlausibleSpeed_mps is ignored (the
  // velocity is estimated from the track instead). Returns whether the
  // sample was taken (into the track or as a candidate).
  bool add(const PoseSample& sample);

  // The camera at render time now - renderDelay_s (clamped so it never goes
  // back), or nullopt while no position has been confirmed. Not const: it
  // remembers the last output to keep the pose continuous when data changes.
  std::optional<SmoothedPose> poseAt(SteadyTime now);

  const PoseSmootherConfig& config() const { return config_; }
  std::uint64_t outliersDropped() const { return outliers_; }
  std::uint64_t teleports() const { return teleports_; }
  std::uint64_t invalidDropped() const { return invalid_; }

 private:
  struct RawPose {
    geo::GeodeticPose pose;
    SmoothingMode mode;
  };
  RawPose rawAt(SteadyTime t) const;
  bool plausible(const PoseSample& from, const PoseSample& to) const;

  PoseSmootherConfig config_;
  std::deque<PoseSample> track_;          // confirmed samples, oldest first
  std::vector<PoseSample> candidates_;    // an unconfirmed jump away from the track
  std::uint64_t trackVersion_ = 0;        // changes whenever track_ does
  bool teleported_ = false;               // the track was replaced since the last poseAt
  bool newTimeBase_ = false;              // ... by one in another time base: render time restarts

  // Continuity: the last output, and the correction fading out since.
  std::optional<SmoothedPose> last_;
  std::uint64_t lastTrackVersion_ = 0;
  geo::Vec3d offsetEcef_m{};
  double offsetYaw_deg = 0, offsetPitch_deg = 0, offsetRoll_deg = 0;
  SteadyTime offsetSince_{};

  std::uint64_t outliers_ = 0;
  std::uint64_t teleports_ = 0;
  std::uint64_t invalid_ = 0;
};

}  // namespace sky::app
