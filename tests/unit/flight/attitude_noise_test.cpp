// Attitude from a noisy ADS-B track: a standard-rate turn must still bank at
// the coordinated-turn angle atan(v * omega / g), and straight flight must
// not shake (bounded roll and pitch rates), with the noise ADS-B tracks
// carry. The noise model, per fix at whole seconds:
//  * the position is where the aircraft was up to 0.5 s before or after the
//    row's time (OpenSky state vectors stamp the row, not the position
//    message, which comes about twice a second);
//  * a horizontal error of 10 m (1 sigma per axis: NACp 9's 30 m 95 % bound
//    is about 2.45 sigma);
//  * latitude and longitude rounded to 1e-5 deg (1.1 m, coarser than the 6
//    decimals readsb writes);
//  * altitude barometric, in 25 ft steps (the ADS-B / Mode S altitude code).
// The random numbers are mt19937's, whose sequence the C++ standard fixes,
// turned into uniform and normal values here (not by <random>'s
// distributions, which differ between libraries).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdint>
#include <numbers>
#include <random>

#include "sky/flight/flight.hpp"

namespace sky::flight {
namespace {

constexpr double kPi = std::numbers::pi;
constexpr double kG_mps2 = 9.80665;
constexpr double kFt_m = 0.3048;
const geo::Geodetic kOrigin{46.0, 12.0, 3000.0};

class AdsbNoise {
 public:
  double uniform() { return static_cast<double>(rng_() >> 8) * 0x1p-24; }  // [0, 1)
  double normal() {  // Box-Muller
    const double u1 = 1.0 - uniform(), u2 = uniform();
    return std::sqrt(-2 * std::log(u1)) * std::cos(2 * kPi * u2);
  }
  // A fix at time t of an aircraft whose east/north position (m, in
  // kOrigin's tangent plane) at any time is track(t), at altitude alt_m.
  template <class Track>
  Fix fix(double t_s, Track track, double alt_m) {
    const auto [east_m, north_m] = track(t_s + (uniform() - 0.5));
    const geo::EnuFrame enu = geo::enuFrameAt(kOrigin);
    geo::Geodetic g = geo::fromEcef(enu.originEcef_m + enu.east * (east_m + kSigma_m * normal()) +
                                    enu.north * (north_m + kSigma_m * normal()));
    g.lat_deg = std::round(g.lat_deg / kLatLonStep_deg) * kLatLonStep_deg;
    g.lon_deg = std::round(g.lon_deg / kLatLonStep_deg) * kLatLonStep_deg;
    g.alt_m = std::round(alt_m / (25 * kFt_m)) * (25 * kFt_m);
    return Fix{t_s, {g, 0, 0, 0}};
  }

 private:
  static constexpr double kSigma_m = 10.0;
  static constexpr double kLatLonStep_deg = 1e-5;
  std::mt19937 rng_{20261205};
};

struct Rates {
  double maxRoll_degps = 0, maxPitch_degps = 0;
};
Rates maxRates(const Flight& f, std::size_t from, std::size_t to) {
  Rates r;
  for (std::size_t i = from + 1; i < to; ++i) {
    const double dt = f.fixes[i].time_s - f.fixes[i - 1].time_s;
    r.maxRoll_degps = std::max(r.maxRoll_degps, std::abs(f.fixes[i].pose.roll_deg - f.fixes[i - 1].pose.roll_deg) / dt);
    r.maxPitch_degps =
        std::max(r.maxPitch_degps, std::abs(f.fixes[i].pose.pitch_deg - f.fixes[i - 1].pose.pitch_deg) / dt);
  }
  return r;
}

// Level flight as an autopilot holds it, wandering +-3 m about 3004 m so
// that the 25 ft codes toggle across 3006.1 m (394.5 x 7.62 m).
double levelAltitude_m(double t_s) { return 3004 + 3 * std::sin(0.9 * t_s); }

// Fixes at least this far from either end are judged: the smoothing windows
// narrow towards the ends.
constexpr std::size_t kEdge = 30;

TEST(AttitudeNoise, AStandardRateTurnBanksAtTheCoordinatedTurnAngle) {
  // 120 m/s turning right at 3 deg/s (standard rate): radius v/omega = 2292 m,
  // tan(bank) = v omega / g = 120 x 0.05236 / 9.80665 = 0.6407: 32.64 deg.
  const double v = 120, omega = 3 * kPi / 180, radius = v / omega;
  const double bank_deg = std::atan(v * omega / kG_mps2) * 180 / kPi;
  ASSERT_NEAR(bank_deg, 32.64, 0.01);
  AdsbNoise noise;
  Flight f;
  for (int t = 0; t <= 360; ++t)  // three full turns
    f.fixes.push_back(noise.fix(t, [&](double s) {
      return std::pair{radius * std::sin(omega * s), radius * std::cos(omega * s)};
    }, levelAltitude_m(t)));
  deriveAttitude(f, kAdsbRateWindow_s);
  double sum = 0;
  std::size_t n = 0;
  for (std::size_t i = kEdge; i + kEdge < f.fixes.size(); ++i) {
    // Each fix within 2 deg of the closed form (measured: 0.7), their mean
    // within 0.5 deg; roll and pitch change by less than 0.5 deg/s (0.3).
    EXPECT_NEAR(f.fixes[i].pose.roll_deg, bank_deg, 2.0) << "t=" << f.fixes[i].time_s;
    EXPECT_NEAR(f.fixes[i].pose.pitch_deg, 0, 1.0) << "t=" << f.fixes[i].time_s;
    sum += f.fixes[i].pose.roll_deg;
    ++n;
  }
  EXPECT_NEAR(sum / static_cast<double>(n), bank_deg, 0.5);
  const Rates r = maxRates(f, kEdge, f.fixes.size() - kEdge);
  EXPECT_LT(r.maxRoll_degps, 0.5);
  EXPECT_LT(r.maxPitch_degps, 0.5);
}

TEST(AttitudeNoise, StraightLevelFlightDoesNotShake) {
  // 120 m/s due north, level: roll and pitch are 0; the noise may tilt them
  // a little but not shake them. An airliner rolls at up to ~5 deg/s and
  // pitches at ~2 deg/s in normal flight; the camera should move far less
  // on a straight line: under 0.5 deg/s (measured: 0.3), within 1.5 deg of
  // level. (With the 5 s windows used before, roll changed by up to 9.7 deg/s.)
  AdsbNoise noise;
  Flight f;
  for (int t = 0; t <= 600; ++t)
    f.fixes.push_back(noise.fix(t, [](double s) { return std::pair{0.0, 120.0 * s}; }, levelAltitude_m(t)));
  deriveAttitude(f, kAdsbRateWindow_s);
  for (std::size_t i = kEdge; i + kEdge < f.fixes.size(); ++i) {
    EXPECT_NEAR(f.fixes[i].pose.roll_deg, 0, 1.5) << "t=" << f.fixes[i].time_s;
    EXPECT_NEAR(f.fixes[i].pose.pitch_deg, 0, 1.5) << "t=" << f.fixes[i].time_s;
  }
  const Rates r = maxRates(f, kEdge, f.fixes.size() - kEdge);
  EXPECT_LT(r.maxRoll_degps, 0.5);
  EXPECT_LT(r.maxPitch_degps, 0.5);
}

}  // namespace
}  // namespace sky::flight

namespace sky::flight {
namespace {

// The rate window's cost, and why a logger's track keeps a narrower one: a
// clean 1 Hz track flying north and rolling into a standard-rate turn at
// t = 60 s. The derived bank rises from 10 % to 90 % of the turn's from 3 s
// before to 4 s after the roll-in with the logger's window (measured), and
// from 7 s before to 8 s after with ADS-B's: a roll-in twice as long, half
// of it before the aircraft turned.
TEST(AttitudeNoise, ALoggersTrackRollsInWithinItsNarrowerWindow) {
  const double v = 60, omega = 3 * kPi / 180, radius = v / omega, t0 = 60;
  const double bank_deg = std::atan(v * omega / kG_mps2) * 180 / kPi;
  const geo::EnuFrame enu = geo::enuFrameAt(kOrigin);
  Flight f;
  for (int t = 0; t <= 180; ++t) {
    const double s = t - t0;
    const double east = s <= 0 ? 0.0 : radius - radius * std::cos(omega * s);
    const double north = s <= 0 ? v * t : v * t0 + radius * std::sin(omega * s);
    geo::Geodetic g = geo::fromEcef(enu.originEcef_m + enu.east * east + enu.north * north);
    g.alt_m = kOrigin.alt_m;
    f.fixes.push_back(Fix{double(t), {g, 0, 0, 0}});
  }
  auto firstAbove = [&](const Flight& d, double share) {
    for (const Fix& x : d.fixes)
      if (x.pose.roll_deg >= share * bank_deg) return x.time_s - t0;
    return 1e9;
  };
  Flight logger = f, adsb = f;
  deriveAttitude(logger, kLoggerRateWindow_s);
  deriveAttitude(adsb, kAdsbRateWindow_s);
  std::printf("[ roll-in  ] logger 10%% %.0f s 90%% %.0f s; adsb 10%% %.0f s 90%% %.0f s\n", firstAbove(logger, 0.1),
              firstAbove(logger, 0.9), firstAbove(adsb, 0.1), firstAbove(adsb, 0.9));
  EXPECT_LE(firstAbove(logger, 0.9), 5.0);
  EXPECT_GE(firstAbove(logger, 0.1), -4.0);
  EXPECT_GE(firstAbove(adsb, 0.9), 7.0);
  EXPECT_LE(firstAbove(adsb, 0.1), -6.0) << "ADS-B's window banks well before the turn";
  // Both bank at the turn's angle once in it.
  EXPECT_NEAR(logger.fixes[120].pose.roll_deg, bank_deg, 0.5);
  EXPECT_NEAR(adsb.fixes[120].pose.roll_deg, bank_deg, 0.5);
}

}  // namespace
}  // namespace sky::flight
