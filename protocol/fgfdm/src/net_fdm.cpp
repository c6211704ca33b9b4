// FGNetFDM v24 codec: a big-endian cursor walks the struct in declaration
// order; the offsets asserted below are those of the reference table.
#include "sky/fgfdm/net_fdm.hpp"

#include <cmath>
#include <cstdio>
#include <cstring>
#include <string>

namespace sky::fgfdm {

namespace {

// Reads (or writes) big-endian scalars in struct order.
class Cursor {
 public:
  explicit Cursor(std::uint8_t* p) : p_(p) {}
  std::size_t offset() const { return off_; }

  template <class T>
  void io(T& v, bool write) {
    static_assert(sizeof(T) == 4 || sizeof(T) == 8);
    std::uint8_t tmp[sizeof(T)];
    if (write) {
      std::memcpy(tmp, &v, sizeof(T));
      for (std::size_t i = 0; i < sizeof(T); ++i) p_[off_ + i] = tmp[sizeof(T) - 1 - i];
    } else {
      for (std::size_t i = 0; i < sizeof(T); ++i) tmp[i] = p_[off_ + sizeof(T) - 1 - i];
      std::memcpy(&v, tmp, sizeof(T));
    }
    off_ += sizeof(T);
  }
  template <class T, std::size_t N>
  void io(std::array<T, N>& a, bool write) {
    for (auto& v : a) io(v, write);
  }

 private:
  std::uint8_t* p_;
  std::size_t off_ = 0;
};

// Walks every field; the same code reads and writes, so the two cannot drift.
// Returns the offset reached, checked against the struct size.
std::size_t walk(NetFdm& f, std::uint8_t* bytes, bool write) {
  Cursor c(bytes);
  std::uint32_t padding = 0;
  c.io(f.version, write);
  c.io(padding, write);
  c.io(f.lon_rad, write);
  c.io(f.lat_rad, write);
  c.io(f.alt_m, write);
  c.io(f.agl_m, write);
  c.io(f.phi_rad, write);
  c.io(f.theta_rad, write);
  c.io(f.psi_rad, write);
  c.io(f.alpha_rad, write);
  c.io(f.beta_rad, write);
  c.io(f.phidot_rps, write);
  c.io(f.thetadot_rps, write);
  c.io(f.psidot_rps, write);
  c.io(f.vcas_kt, write);  // offset 68
  c.io(f.climbRate_fps, write);
  c.io(f.vNorth_fps, write);
  c.io(f.vEast_fps, write);
  c.io(f.vDown_fps, write);
  c.io(f.vWindBodyNorth_fps, write);
  c.io(f.vWindBodyEast_fps, write);
  c.io(f.vWindBodyDown_fps, write);
  c.io(f.aXPilot_fps2, write);
  c.io(f.aYPilot_fps2, write);
  c.io(f.aZPilot_fps2, write);
  c.io(f.stallWarning, write);
  c.io(f.slip_deg, write);
  c.io(f.numEngines, write);  // offset 120
  c.io(f.engState, write);
  c.io(f.rpm, write);  // offset 140
  c.io(f.fuelFlow_gph, write);
  c.io(f.fuelPx_psi, write);
  c.io(f.egt_degf, write);
  c.io(f.cht_degf, write);
  c.io(f.mpOsi, write);
  c.io(f.tit, write);
  c.io(f.oilTemp_degf, write);
  c.io(f.oilPx_psi, write);
  c.io(f.numTanks, write);  // offset 284
  c.io(f.fuelQuantity_gal, write);
  c.io(f.numWheels, write);  // offset 304
  c.io(f.wow, write);
  c.io(f.gearPos, write);
  c.io(f.gearSteer, write);
  c.io(f.gearCompression, write);
  c.io(f.curTime_unix, write);  // offset 356
  c.io(f.warp_s, write);
  c.io(f.visibility_m, write);
  c.io(f.elevator, write);  // offset 368
  c.io(f.elevatorTrimTab, write);
  c.io(f.leftFlap, write);
  c.io(f.rightFlap, write);
  c.io(f.leftAileron, write);
  c.io(f.rightAileron, write);
  c.io(f.rudder, write);
  c.io(f.noseWheel, write);
  c.io(f.speedbrake, write);
  c.io(f.spoilers, write);
  return c.offset();
}

constexpr double kPi = 3.14159265358979323846;
// Small slack over pi for the wire's float rounding of angles.
constexpr double kAngleSlack_rad = 1e-3;
constexpr double kMetresPerFoot = 0.3048;  // international foot, exact
constexpr double kMetresPerSecondPerKnot = 1852.0 / 3600.0;
// Fastest a FlightGear vehicle can move inside the altitude range we take
// (< 1e7 m): escape velocity at the surface is 11.2 km/s, so 12 km/s bounds
// even the Space Shuttle; anything faster is a broken sender, not a flight.
constexpr double kMaxSpeed_mps = 12000.0;
constexpr double kMaxSpeed_fps = kMaxSpeed_mps / kMetresPerFoot;
constexpr double kMaxSpeed_kt = kMaxSpeed_mps / kMetresPerSecondPerKnot;
// Body rates: 100 rad/s is ten times the fastest aerobatic roll (~7 rad/s,
// 420 deg/s) and more than any tumbling flight model produces.
constexpr double kMaxRate_rps = 100.0;
// Accelerations felt by the pilot: 1000 ft/s^2 is ~31 g, past any airframe
// and past a crash that FlightGear keeps flying through.
constexpr double kMaxAcceleration_fps2 = 1000.0;

// One range check of a decoded field: the field's wire name, unit, value and
// closed bounds. A non-finite value is always out of range.
struct Bound {
  const char* field;
  const char* unit;
  double value, lo, hi;
};

std::string number(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%g", v);
  return buf;
}

}  // namespace

Result<NetFdm> decodeNetFdm(std::span<const std::uint8_t> bytes) {
  if (bytes.size() != kPacketBytes)
    return fail(ErrorCode::Malformed, "FGNetFDM: datagram of " + std::to_string(bytes.size()) +
                                          " bytes, version 24 is " + std::to_string(kPacketBytes));
  std::array<std::uint8_t, kPacketBytes> copy;
  std::memcpy(copy.data(), bytes.data(), kPacketBytes);
  NetFdm f;
  const std::size_t end = walk(f, copy.data(), false);
  if (end != kPacketBytes) return fail(ErrorCode::Malformed, "FGNetFDM: layout walked " + std::to_string(end) + " bytes");
  if (f.version != kVersion)
    return fail(ErrorCode::Unsupported, "FGNetFDM: field 'version' is " + std::to_string(f.version) +
                                            ", we decode version 24 only");
  constexpr double kHalfPi = kPi / 2 + kAngleSlack_rad, kTwoPi = 2 * kPi + kAngleSlack_rad;
  // The fields a renderer reads or could read: position, attitude, rates,
  // velocities, accelerations, time and visibility. The rest (engines, gear,
  // controls) is carried as it comes.
  const Bound bounds[] = {
      {"latitude", "rad", f.lat_rad, -kHalfPi, kHalfPi},
      {"longitude", "rad", f.lon_rad, -kTwoPi, kTwoPi},
      {"altitude", "m", f.alt_m, -12000, 1.0e7},
      {"agl", "m", f.agl_m, -1.0e7, 1.0e7},
      {"phi", "rad", f.phi_rad, -kTwoPi, kTwoPi},
      {"theta", "rad", f.theta_rad, -kHalfPi, kHalfPi},
      {"psi", "rad", f.psi_rad, -kTwoPi, kTwoPi},
      {"alpha", "rad", f.alpha_rad, -kTwoPi, kTwoPi},
      {"beta", "rad", f.beta_rad, -kTwoPi, kTwoPi},
      {"phidot", "rad/s", f.phidot_rps, -kMaxRate_rps, kMaxRate_rps},
      {"thetadot", "rad/s", f.thetadot_rps, -kMaxRate_rps, kMaxRate_rps},
      {"psidot", "rad/s", f.psidot_rps, -kMaxRate_rps, kMaxRate_rps},
      {"vcas", "kt", f.vcas_kt, -kMaxSpeed_kt, kMaxSpeed_kt},
      {"climb_rate", "ft/s", f.climbRate_fps, -kMaxSpeed_fps, kMaxSpeed_fps},
      {"v_north", "ft/s", f.vNorth_fps, -kMaxSpeed_fps, kMaxSpeed_fps},
      {"v_east", "ft/s", f.vEast_fps, -kMaxSpeed_fps, kMaxSpeed_fps},
      {"v_down", "ft/s", f.vDown_fps, -kMaxSpeed_fps, kMaxSpeed_fps},
      {"v_body_u", "ft/s", f.vWindBodyNorth_fps, -kMaxSpeed_fps, kMaxSpeed_fps},
      {"v_body_v", "ft/s", f.vWindBodyEast_fps, -kMaxSpeed_fps, kMaxSpeed_fps},
      {"v_body_w", "ft/s", f.vWindBodyDown_fps, -kMaxSpeed_fps, kMaxSpeed_fps},
      {"A_X_pilot", "ft/s^2", f.aXPilot_fps2, -kMaxAcceleration_fps2, kMaxAcceleration_fps2},
      {"A_Y_pilot", "ft/s^2", f.aYPilot_fps2, -kMaxAcceleration_fps2, kMaxAcceleration_fps2},
      {"A_Z_pilot", "ft/s^2", f.aZPilot_fps2, -kMaxAcceleration_fps2, kMaxAcceleration_fps2},
      {"visibility", "m", f.visibility_m, 0, 1.0e9},
  };
  for (const Bound& b : bounds)
    if (!(std::isfinite(b.value) && b.value >= b.lo && b.value <= b.hi))
      return fail(ErrorCode::InvalidArgument, std::string("FGNetFDM: field '") + b.field + "' " + number(b.value) +
                                                  " " + b.unit + " outside [" + number(b.lo) + ", " +
                                                  number(b.hi) + "]");
  if (f.numEngines > kMaxEngines)
    return fail(ErrorCode::InvalidArgument, "FGNetFDM: field 'num_engines' " + std::to_string(f.numEngines) + " above 4");
  if (f.numTanks > kMaxTanks)
    return fail(ErrorCode::InvalidArgument, "FGNetFDM: field 'num_tanks' " + std::to_string(f.numTanks) + " above 4");
  if (f.numWheels > kMaxWheels)
    return fail(ErrorCode::InvalidArgument, "FGNetFDM: field 'num_wheels' " + std::to_string(f.numWheels) + " above 3");
  return f;
}
std::array<std::uint8_t, kPacketBytes> encodeNetFdm(const NetFdm& fdm) {
  std::array<std::uint8_t, kPacketBytes> out{};
  NetFdm copy = fdm;
  walk(copy, out.data(), true);
  return out;
}

}  // namespace sky::fgfdm
