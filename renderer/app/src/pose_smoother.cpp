// Pose smoothing for simulator feeds (see pose_smoother.hpp).
#include "sky/app/pose_smoother.hpp"

#include <algorithm>
#include <cmath>

namespace sky::app {

namespace {

// Two samples closer in time than this (one network burst) give no usable
// angular rate or velocity for extrapolation: 20 ms.
constexpr double kMinRateBaseline_s = 0.02;
// A sample not later than the newest is moved just after it, so times stay
// strictly increasing and interpolation never divides by zero.
constexpr auto kMinSampleSpacing = std::chrono::microseconds(1);

double seconds(SteadyTime::duration d) { return std::chrono::duration<double>(d).count(); }

// a + f * (b - a) along the shortest arc, normalised to [-180, 180).
double lerpAngle_deg(double a_deg, double b_deg, double f) {
  return geo::normalizeLon_deg(a_deg + f * geo::angleDiff_deg(a_deg, b_deg));
}

geo::GeodeticPose interpolate(const geo::GeodeticPose& a, const geo::GeodeticPose& b, double f) {
  geo::GeodeticPose p;
  p.position.lat_deg = a.position.lat_deg + f * (b.position.lat_deg - a.position.lat_deg);
  p.position.lon_deg = lerpAngle_deg(a.position.lon_deg, b.position.lon_deg, f);
  p.position.alt_m = a.position.alt_m + f * (b.position.alt_m - a.position.alt_m);
  p.yaw_deg = lerpAngle_deg(a.yaw_deg, b.yaw_deg, f);
  p.pitch_deg = a.pitch_deg + f * (b.pitch_deg - a.pitch_deg);
  p.roll_deg = lerpAngle_deg(a.roll_deg, b.roll_deg, f);
  return p;
}

// Bounds of a usable sample (see PoseSmoother::add): the decoders' ranges,
// with a little slack for float rounding; beyond them a value is garbage.
constexpr double kMinAlt_m = -12000.0, kMaxAlt_m = 1.0e7;
constexpr double kMaxLon_deg = 360.0;
constexpr double kMaxPitch_deg = 90.1;
constexpr double kMaxYawRoll_deg = 720.0;

bool usable(const geo::GeodeticPose& p) {
  const auto within = [](double v, double lo, double hi) { return std::isfinite(v) && v >= lo && v <= hi; };
  return within(p.position.lat_deg, -90.0, 90.0) && within(p.position.lon_deg, -kMaxLon_deg, kMaxLon_deg) &&
         within(p.position.alt_m, kMinAlt_m, kMaxAlt_m) && within(p.pitch_deg, -kMaxPitch_deg, kMaxPitch_deg) &&
         within(p.yaw_deg, -kMaxYawRoll_deg, kMaxYawRoll_deg) && within(p.roll_deg, -kMaxYawRoll_deg, kMaxYawRoll_deg);
}

geo::Vec3d nedToEcef(const geo::Geodetic& at, const geo::Vec3d& ned) {
  const geo::EnuFrame f = geo::enuFrameAt(at);
  return f.north * ned.x + f.east * ned.y - f.up * ned.z;
}

}  // namespace

PoseSmoother::PoseSmoother(PoseSmootherConfig config) : config_(config) {}

bool PoseSmoother::plausible(const PoseSample& from, const PoseSample& to) const {
  const double dt_s = std::max(0.0, seconds(to.receivedAt - from.receivedAt));
  const double distance_m = geo::length(geo::toEcef(to.pose.position) - geo::toEcef(from.pose.position));
  return distance_m <= config_.maxPlausibleSpeed_mps * dt_s + config_.plausibleSlack_m;
}

bool PoseSmoother::add(const PoseSample& in) {
  if (!usable(in.pose)) {
    ++invalid_;
    return false;
  }
  PoseSample s = in;
  s.pose.pitch_deg = std::clamp(s.pose.pitch_deg, -90.0, 90.0);
  if (s.velocityNed_mps) {
    const geo::Vec3d& v = *s.velocityNed_mps;
    const double speed_mps = geo::length(v);
    if (!(std::isfinite(speed_mps) && speed_mps <= config_.maxPlausibleSpeed_mps)) s.velocityNed_mps.reset();
  }
  const auto backstep = std::chrono::duration_cast<SteadyTime::duration>(
      std::chrono::duration<double>(config_.maxBackstep_s));
  // A stamp far before the newest: another time base, never a continuation
  // of the track (nor of candidates stamped in the old one).
  const bool trackInPast = !track_.empty() && s.receivedAt + backstep < track_.back().receivedAt;
  if (!candidates_.empty() && s.receivedAt + backstep < candidates_.back().receivedAt) {
    outliers_ += candidates_.size();
    candidates_.clear();
  }
  const PoseSample* newest = !candidates_.empty()            ? &candidates_.back()
                             : !track_.empty() && !trackInPast ? &track_.back()
                                                               : nullptr;
  if (newest && s.receivedAt <= newest->receivedAt) s.receivedAt = newest->receivedAt + kMinSampleSpacing;

  if (!trackInPast && !track_.empty() && plausible(track_.back(), s)) {
    outliers_ += candidates_.size();  // the jump was not confirmed
    candidates_.clear();
    track_.push_back(s);
    while (track_.size() > std::max<std::size_t>(config_.historySamples, 2)) track_.pop_front();
    ++trackVersion_;
    return true;
  }
  // Implausible from the track (or no track yet): a candidate for a new one.
  if (!candidates_.empty() && !plausible(candidates_.back(), s)) {
    outliers_ += candidates_.size();
    candidates_.clear();
  }
  candidates_.push_back(s);
  if (candidates_.size() >= std::max<std::size_t>(config_.confirmSamples, 1)) {
    if (!track_.empty()) {
      ++teleports_;
      teleported_ = true;
      newTimeBase_ = candidates_.front().receivedAt + backstep < track_.back().receivedAt;
    }
    track_.assign(candidates_.begin(), candidates_.end());
    candidates_.clear();
    ++trackVersion_;
  }
  return true;
}

PoseSmoother::RawPose PoseSmoother::rawAt(SteadyTime t) const {
  const PoseSample& first = track_.front();
  if (t <= first.receivedAt) return {first.pose, SmoothingMode::Interpolated};
  const PoseSample& last = track_.back();
  if (t < last.receivedAt) {
    // The last sample at or before t; track_ is sorted by time.
    const auto after = std::upper_bound(track_.begin(), track_.end(), t,
                                        [](SteadyTime v, const PoseSample& s) { return v < s.receivedAt; });
    const PoseSample& b = *after;
    const PoseSample& a = *(after - 1);
    const double f = seconds(t - a.receivedAt) / seconds(b.receivedAt - a.receivedAt);
    return {interpolate(a.pose, b.pose, std::clamp(f, 0.0, 1.0)), SmoothingMode::Interpolated};
  }

  const double ahead_s = seconds(t - last.receivedAt);
  const double dt_s = std::min(ahead_s, config_.maxExtrapolation_s);
  const SmoothingMode mode = ahead_s <= config_.maxExtrapolation_s ? SmoothingMode::Extrapolated : SmoothingMode::Held;
  const PoseSample* prev = track_.size() >= 2 ? &track_[track_.size() - 2] : nullptr;
  const double baseline_s = prev ? seconds(last.receivedAt - prev->receivedAt) : 0.0;
  const bool haveRates = prev && baseline_s >= kMinRateBaseline_s;

  geo::Vec3d velocityEcef_mps{};
  if (last.velocityNed_mps)
    velocityEcef_mps = nedToEcef(last.pose.position, *last.velocityNed_mps);
  else if (haveRates)
    velocityEcef_mps = (geo::toEcef(last.pose.position) - geo::toEcef(prev->pose.position)) * (1.0 / baseline_s);

  RawPose out{last.pose, mode};
  if (dt_s <= 0) return out;
  // A sample at rest (FlightGear's start-up phase) stays bit-exact: no ECEF round trip.
  if (geo::length(velocityEcef_mps) > 0)
    out.pose.position = geo::fromEcef(geo::toEcef(last.pose.position) + velocityEcef_mps * dt_s);
  if (haveRates) {
    const double k = dt_s / baseline_s;
    out.pose.yaw_deg = geo::normalizeLon_deg(last.pose.yaw_deg + k * geo::angleDiff_deg(prev->pose.yaw_deg, last.pose.yaw_deg));
    out.pose.pitch_deg = std::clamp(last.pose.pitch_deg + k * (last.pose.pitch_deg - prev->pose.pitch_deg), -90.0, 90.0);
    out.pose.roll_deg = geo::normalizeLon_deg(last.pose.roll_deg + k * geo::angleDiff_deg(prev->pose.roll_deg, last.pose.roll_deg));
  }
  return out;
}

std::optional<SmoothedPose> PoseSmoother::poseAt(SteadyTime now) {
  if (track_.empty()) return std::nullopt;
  // After a change of time base the last render time belongs to the old
  // clock: holding to it would freeze the camera until that clock's time.
  if (newTimeBase_) last_.reset();
  newTimeBase_ = false;
  SteadyTime r = now - std::chrono::duration_cast<SteadyTime::duration>(
                           std::chrono::duration<double>(config_.renderDelay_s));
  if (last_ && r < last_->renderTime) r = last_->renderTime;

  if (teleported_ || !last_) {
    offsetEcef_m = {};
    offsetYaw_deg = offsetPitch_deg = offsetRoll_deg = 0;
    teleported_ = false;
  } else if (trackVersion_ != lastTrackVersion_) {
    // New data changed the pose at the last render time: keep what was shown
    // there and fade the difference out from then on.
    const RawPose before = rawAt(last_->renderTime);
    offsetEcef_m = geo::toEcef(last_->pose.position) - geo::toEcef(before.pose.position);
    offsetYaw_deg = geo::angleDiff_deg(before.pose.yaw_deg, last_->pose.yaw_deg);
    offsetPitch_deg = last_->pose.pitch_deg - before.pose.pitch_deg;
    offsetRoll_deg = geo::angleDiff_deg(before.pose.roll_deg, last_->pose.roll_deg);
    offsetSince_ = last_->renderTime;
    if (geo::length(offsetEcef_m) > config_.maxBlendDistance_m) {
      offsetEcef_m = {};
      offsetYaw_deg = offsetPitch_deg = offsetRoll_deg = 0;
    }
  }
  lastTrackVersion_ = trackVersion_;

  const RawPose raw = rawAt(r);
  SmoothedPose out{raw.pose, r, raw.mode};
  const double fade = config_.convergenceTimeConstant_s > 0
                          ? std::exp(-seconds(r - offsetSince_) / config_.convergenceTimeConstant_s)
                          : 0.0;
  if (fade > 0 && geo::length(offsetEcef_m) > 0)
    out.pose.position = geo::fromEcef(geo::toEcef(raw.pose.position) + offsetEcef_m * fade);
  out.pose.yaw_deg = geo::normalizeLon_deg(raw.pose.yaw_deg + offsetYaw_deg * fade);
  out.pose.pitch_deg = std::clamp(raw.pose.pitch_deg + offsetPitch_deg * fade, -90.0, 90.0);
  out.pose.roll_deg = geo::normalizeLon_deg(raw.pose.roll_deg + offsetRoll_deg * fade);
  last_ = out;
  return out;
}

}  // namespace sky::app
