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
// The rate windows (flight.hpp's kLoggerRateWindow_s, kAdsbRateWindow_s):
// the turn rate and the climb rate are a weighted least-squares slope of the
// heading and of the altitude over them, and the speed their average. Bank
// is a second derivative of position: from 1 Hz ADS-B (10 m of position
// noise, positions up to 0.5 s older or newer than their row, 25 ft
// altitude steps; attitude_noise_test.cpp) a 5 s window left the derived
// bank jumping by up to 12 deg/s on a straight line and 11 deg off a
// standard-rate turn's; with 20 s it still changed by up to 0.76 deg/s; with
// 30 s by 0.3 deg/s, and stays within 0.7 deg of the turn's closed form. A
// steady turn's heading is linear in time, so its slope is exact at any
// width; what the width costs is a roll-in spread over it instead of the
// 5-10 s an airliner or a glider takes, and wobbles within a thermalling
// circle (20-30 s) smoothed away: a logger's track, far less noisy, keeps
// 10 s.
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

struct Segments {
  std::vector<std::size_t> of, first, last;  // segment of each fix; first and last fix of each segment
};

// Calls f(j, u) for every fix j in the centred window of width window_s
// about fix i, u = (t_j - t_i) / half-width in [-1, 1]; the half-width
// shrinks symmetrically near segment ends (gaps and the record's ends), so
// that a series linear in time keeps its value and its slope.
template <class F>
void forWindow(const std::vector<Fix>& fx, const Segments& seg, std::size_t i, double window_s, F&& f) {
  constexpr double kTimeSlack_s = 1e-6;  // fixes are whole seconds or close to
  const std::size_t s = seg.of[i];
  const double t = fx[i].time_s;
  const double half =
      std::min({window_s / 2, t - fx[seg.first[s]].time_s, fx[seg.last[s]].time_s - t}) + kTimeSlack_s;
  for (std::size_t j = i + 1; j-- > seg.first[s] && fx[j].time_s >= t - half;) f(j, (fx[j].time_s - t) / half);
  for (std::size_t j = i + 1; j <= seg.last[s] && fx[j].time_s <= t + half; ++j) f(j, (fx[j].time_s - t) / half);
}

// Centred moving average of v over window_s.
std::vector<double> smooth(const std::vector<double>& v, const std::vector<Fix>& fx, const Segments& seg,
                           double window_s) {
  std::vector<double> out(v.size());
  for (std::size_t i = 0; i < v.size(); ++i) {
    double sum = 0;
    std::size_t count = 0;
    forWindow(fx, seg, i, window_s, [&](std::size_t j, double) {
      sum += v[j];
      ++count;
    });
    out[i] = sum / static_cast<double>(count);
  }
  return out;
}

// Slope of v against time (per s) over the centred window: least squares
// weighted by 1 - u^2 (Epanechnikov), so that a fix entering or leaving the
// window as it slides moves the slope by little (with equal weights the
// fixes at the window's edges have the most leverage, and the derived bank
// stepped by up to 0.8 deg/s on noisy straight flight). Symmetric weights
// keep the slope of a linear series exact. Where the window holds one fix
// with weight (the ends of a segment): fallback[i].
std::vector<double> slope(const std::vector<double>& v, const std::vector<Fix>& fx, const Segments& seg,
                          double window_s, const std::vector<double>& fallback) {
  std::vector<double> out(v.size());
  for (std::size_t i = 0; i < v.size(); ++i) {
    double sw = 0, st = 0, sv = 0, stt = 0, stv = 0;
    forWindow(fx, seg, i, window_s, [&](std::size_t j, double u) {
      const double w = std::max(0.0, 1 - u * u);
      const double t = fx[j].time_s - fx[i].time_s;  // centred: no cancellation at large times
      sw += w;
      st += w * t;
      sv += w * v[j];
      stt += w * t * t;
      stv += w * t * v[j];
    });
    const double den = sw * stt - st * st;
    out[i] = den > 1e-12 ? (sw * stv - st * sv) / den : fallback[i];
  }
  return out;
}

}  // namespace

void deriveAttitude(Flight& flight, double rateWindow_s) {
  auto& fx = flight.fixes;
  const std::size_t n = fx.size();
  SKY_ASSERT(n >= 2);

  // Segments: runs of fixes without a gap longer than kGapWarning_s.
  Segments seg{std::vector<std::size_t>(n), {0}, {}};
  for (std::size_t i = 1; i < n; ++i) {
    if (fx[i].time_s - fx[i - 1].time_s > kGapWarning_s) {
      seg.last.push_back(i - 1);
      seg.first.push_back(i);
    }
    seg.of[i] = seg.first.size() - 1;
  }
  seg.last.push_back(n - 1);

  // Central differences over the neighbours within the segment.
  std::vector<double> speed(n, 0), climb(n, 0), heading(n, 0);
  std::vector<bool> moving(n, false);
  for (std::size_t i = 0; i < n; ++i) {
    const std::size_t s = seg.of[i];
    const std::size_t a = i > seg.first[s] ? i - 1 : i, b = i < seg.last[s] ? i + 1 : i;
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

  // Moving or not by the short window; the values by the long ones.
  const std::vector<double> speedS = smooth(speed, fx, seg, kSmoothingWindow_s);
  const std::vector<double> speedL = smooth(speed, fx, seg, rateWindow_s);
  std::vector<double> alt(n);
  for (std::size_t i = 0; i < n; ++i) alt[i] = fx[i].pose.position.alt_m;
  const std::vector<double> climbL = slope(alt, fx, seg, rateWindow_s, climb);
  const std::vector<double> headingS = smooth(heading, fx, seg, kSmoothingWindow_s);
  std::vector<double> turn(n, 0);  // central differences, for the ends
  for (std::size_t i = 0; i < n; ++i) {
    const std::size_t s = seg.of[i];
    const std::size_t a = i > seg.first[s] ? i - 1 : i, b = i < seg.last[s] ? i + 1 : i;
    if (a != b) turn[i] = (heading[b] - heading[a]) / (fx[b].time_s - fx[a].time_s);
  }
  const std::vector<double> turnRate_degps = slope(heading, fx, seg, rateWindow_s, turn);

  std::vector<double> bank(n, 0);
  for (std::size_t i = 0; i < n; ++i) {
    if (!moving[i]) continue;
    // Coordinated turn: tan(bank) = v * omega / g (lift tilted to supply the
    // centripetal force); right turn (heading increasing) = right wing down.
    bank[i] = std::atan(speedL[i] * turnRate_degps[i] * kDegToRad / kGravity_mps2) * kRadToDeg;
  }
  const std::vector<double> bankS = smooth(bank, fx, seg, kSmoothingWindow_s);

  for (std::size_t i = 0; i < n; ++i) {
    geo::GeodeticPose& p = fx[i].pose;
    p.yaw_deg = std::fmod(std::fmod(headingS[i], 360.0) + 360.0, 360.0);
    const double pitch = speedS[i] >= kMinSpeedForHeading_mps ? std::atan2(climbL[i], speedL[i]) * kRadToDeg : 0.0;
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
