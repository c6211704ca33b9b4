// Attitude of a flight recorded without one (IGC, GPX): heading from the
// track, pitch from the climb angle, bank from the turn rate of a coordinated
// turn, each smoothed and clamped. See deriveAttitude in flight.hpp.
#include <algorithm>
#include <cmath>
#include <numbers>
#include <vector>

#include "sky/core/assert.hpp"
#include "sky/flight/flight.hpp"

namespace sky::flight {

namespace {

constexpr double kRadToDeg = 180.0 / std::numbers::pi;
constexpr double kDegToRad = std::numbers::pi / 180.0;
// Standard gravity (3rd CGPM, 1901); the few 0.1 % of local variation do not
// show in a derived bank angle.
constexpr double kGravity_mps2 = 9.80665;
// Centred moving average width. A 1 Hz consumer GNSS track makes the raw
// per-second heading jitter by several degrees; a thermalling turn takes
// 20-30 s, so averaging over 5 s keeps the turn and removes the jitter.
constexpr double kSmoothingWindow_s = 5.0;
// A stationary GNSS logger wanders by a few metres over seconds (up to about
// 1 m/s); nothing we replay flies slower than 5 m/s. Below this the heading
// is held and pitch and bank are 0.
constexpr double kMinSpeedForHeading_mps = 2.0;
// Limits of normal flight in gliders, paragliders and light aircraft: a 60 deg
// coordinated bank is a 2 g turn (load factor 1/cos), the normal category's
// manoeuvring regime; sustained climb or dive angles beyond 30 deg are not
// flown with them. Derived values beyond are GNSS noise, not attitude.
constexpr double kMaxBank_deg = 60.0;
constexpr double kMaxPitch_deg = 30.0;

// Centred moving average of v over a time window; the half-width shrinks
// symmetrically near segment ends (gaps and the record's ends), so a series
// linear in time is returned unchanged.
std::vector<double> smooth(const std::vector<double>& v, const std::vector<Fix>& fx,
                           const std::vector<std::size_t>& segmentOf, const std::vector<std::size_t>& segFirst,
                           const std::vector<std::size_t>& segLast) {
  const std::size_t n = v.size();
  std::vector<double> out(n);
  constexpr double kTimeSlack_s = 1e-6;  // fixes are whole seconds or close to
  for (std::size_t i = 0; i < n; ++i) {
    const std::size_t s = segmentOf[i];
    const double t = fx[i].time_s;
    const double half = std::min({kSmoothingWindow_s / 2, t - fx[segFirst[s]].time_s, fx[segLast[s]].time_s - t}) +
                        kTimeSlack_s;
    double sum = 0;
    std::size_t count = 0;
    for (std::size_t j = i + 1; j-- > segFirst[s] && fx[j].time_s >= t - half;) {
      sum += v[j];
      ++count;
    }
    for (std::size_t j = i + 1; j <= segLast[s] && fx[j].time_s <= t + half; ++j) {
      sum += v[j];
      ++count;
    }
    out[i] = sum / static_cast<double>(count);
  }
  return out;
}

}  // namespace

void deriveAttitude(Flight& flight) {
  auto& fx = flight.fixes;
  const std::size_t n = fx.size();
  SKY_ASSERT(n >= 2);

  // Segments: runs of fixes without a gap longer than kGapWarning_s.
  std::vector<std::size_t> segmentOf(n), segFirst{0}, segLast;
  for (std::size_t i = 1; i < n; ++i) {
    if (fx[i].time_s - fx[i - 1].time_s > kGapWarning_s) {
      segLast.push_back(i - 1);
      segFirst.push_back(i);
    }
    segmentOf[i] = segFirst.size() - 1;
  }
  segLast.push_back(n - 1);

  // Central differences over the neighbours within the segment.
  std::vector<double> speed(n, 0), climb(n, 0), heading(n, 0);
  std::vector<bool> moving(n, false);
  for (std::size_t i = 0; i < n; ++i) {
    const std::size_t s = segmentOf[i];
    const std::size_t a = i > segFirst[s] ? i - 1 : i, b = i < segLast[s] ? i + 1 : i;
    if (a == b) continue;  // a lone fix between gaps
    const geo::Geodetic& pa = fx[a].pose.position;
    const geo::Geodetic& pb = fx[b].pose.position;
    const double dt = fx[b].time_s - fx[a].time_s;
    speed[i] = geo::geodesicDistance_m(pa.lat_deg, pa.lon_deg, pb.lat_deg, pb.lon_deg) / dt;
    climb[i] = (pb.alt_m - pa.alt_m) / dt;
    moving[i] = speed[i] >= kMinSpeedForHeading_mps;
    if (moving[i]) heading[i] = geo::geodesicAzimuth_deg(pa.lat_deg, pa.lon_deg, pb.lat_deg, pb.lon_deg);
  }
  // Hold the heading while not moving (back-fill before the first movement),
  // then unwrap so that averaging and differencing see no 360 deg jumps.
  const auto firstMoving = std::find(moving.begin(), moving.end(), true);
  double held = firstMoving == moving.end() ? 0.0 : heading[static_cast<std::size_t>(firstMoving - moving.begin())];
  for (std::size_t i = 0; i < n; ++i) {
    if (moving[i]) held = heading[i];
    heading[i] = held;
  }
  for (std::size_t i = 1; i < n; ++i) heading[i] = heading[i - 1] + geo::angleDiff_deg(heading[i - 1], heading[i]);

  const std::vector<double> speedS = smooth(speed, fx, segmentOf, segFirst, segLast);
  const std::vector<double> climbS = smooth(climb, fx, segmentOf, segFirst, segLast);
  const std::vector<double> headingS = smooth(heading, fx, segmentOf, segFirst, segLast);

  std::vector<double> bank(n, 0);
  for (std::size_t i = 0; i < n; ++i) {
    const std::size_t s = segmentOf[i];
    const std::size_t a = i > segFirst[s] ? i - 1 : i, b = i < segLast[s] ? i + 1 : i;
    if (a == b || !moving[i]) continue;
    const double turnRate_radps = (headingS[b] - headingS[a]) * kDegToRad / (fx[b].time_s - fx[a].time_s);
    // Coordinated turn: tan(bank) = v * omega / g (lift tilted to supply the
    // centripetal force); right turn (heading increasing) = right wing down.
    bank[i] = std::atan(speedS[i] * turnRate_radps / kGravity_mps2) * kRadToDeg;
  }
  const std::vector<double> bankS = smooth(bank, fx, segmentOf, segFirst, segLast);

  for (std::size_t i = 0; i < n; ++i) {
    geo::GeodeticPose& p = fx[i].pose;
    p.yaw_deg = std::fmod(std::fmod(headingS[i], 360.0) + 360.0, 360.0);
    const double pitch = speedS[i] >= kMinSpeedForHeading_mps ? std::atan2(climbS[i], speedS[i]) * kRadToDeg : 0.0;
    p.pitch_deg = std::clamp(pitch, -kMaxPitch_deg, kMaxPitch_deg);
    p.roll_deg = std::clamp(bankS[i], -kMaxBank_deg, kMaxBank_deg);
  }
}

std::int64_t daysFromCivil(std::int64_t y, unsigned m, unsigned d) {
  // H. Hinnant, days_from_civil: years start on 1 March so that the leap day
  // is the last of the year; eras are 400-year cycles of 146097 days.
  y -= m <= 2;
  const std::int64_t era = (y >= 0 ? y : y - 399) / 400;
  const auto yoe = static_cast<unsigned>(y - era * 400);             // [0, 399]
  const unsigned doy = (153 * (m > 2 ? m - 3 : m + 9) + 2) / 5 + d - 1;  // [0, 365]
  const unsigned doe = yoe * 365 + yoe / 4 - yoe / 100 + doy;         // [0, 146096]
  return era * 146097 + static_cast<std::int64_t>(doe) - 719468;
}

}  // namespace sky::flight
