// FGNetFDM v24 codec: a big-endian cursor walks the struct in declaration
// order; the offsets asserted below are those of the reference table.
#include "sky/fgfdm/net_fdm.hpp"

#include <cmath>
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

Result<void> check(bool ok, const std::string& what) {
  if (ok) return {};
  return fail(ErrorCode::InvalidArgument, "FGNetFDM: " + what);
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
  constexpr double kPi = 3.14159265358979323846;
  // Small slack over pi for the wire's float rounding of angles.
  constexpr double kAngleSlack_rad = 1e-3;
  Result<void> r;
  if (!(r = check(std::isfinite(f.lat_rad) && std::abs(f.lat_rad) <= kPi / 2 + kAngleSlack_rad,
                  "field 'latitude' " + std::to_string(f.lat_rad) + " rad outside [-pi/2, pi/2]")) ||
      !(r = check(std::isfinite(f.lon_rad) && std::abs(f.lon_rad) <= 2 * kPi + kAngleSlack_rad,
                  "field 'longitude' " + std::to_string(f.lon_rad) + " rad outside [-2pi, 2pi]")) ||
      !(r = check(std::isfinite(f.alt_m) && f.alt_m > -12000 && f.alt_m < 1.0e7,
                  "field 'altitude' " + std::to_string(f.alt_m) + " m outside (-12000, 1e7)")) ||
      !(r = check(std::isfinite(f.phi_rad) && std::abs(f.phi_rad) <= 2 * kPi + kAngleSlack_rad, "field 'phi' out of range")) ||
      !(r = check(std::isfinite(f.theta_rad) && std::abs(f.theta_rad) <= kPi / 2 + kAngleSlack_rad, "field 'theta' out of range")) ||
      !(r = check(std::isfinite(f.psi_rad) && std::abs(f.psi_rad) <= 2 * kPi + kAngleSlack_rad, "field 'psi' out of range")) ||
      !(r = check(f.numEngines <= kMaxEngines, "field 'num_engines' " + std::to_string(f.numEngines) + " above 4")) ||
      !(r = check(f.numTanks <= kMaxTanks, "field 'num_tanks' " + std::to_string(f.numTanks) + " above 4")) ||
      !(r = check(f.numWheels <= kMaxWheels, "field 'num_wheels' " + std::to_string(f.numWheels) + " above 3")))
    return tl::unexpected(r.error());
  return f;
}

std::array<std::uint8_t, kPacketBytes> encodeNetFdm(const NetFdm& fdm) {
  std::array<std::uint8_t, kPacketBytes> out{};
  NetFdm copy = fdm;
  walk(copy, out.data(), true);
  return out;
}

}  // namespace sky::fgfdm
