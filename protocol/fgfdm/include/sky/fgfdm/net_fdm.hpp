// FlightGear's --native-fdm UDP stream (struct FGNetFDM, version 24, 408
// bytes, network byte order; layout: ../shared/reference/cigi.md §11), so a
// desktop FlightGear can drive a renderer channel without CIGI.
#pragma once

#include <array>
#include <cstdint>
#include <span>

#include "sky/core/result.hpp"

namespace sky::fgfdm {

inline constexpr std::uint32_t kVersion = 24;
inline constexpr std::size_t kPacketBytes = 408;
inline constexpr std::size_t kMaxEngines = 4, kMaxTanks = 4, kMaxWheels = 3;

// Every field of FGNetFDM v24, in its wire units (angles in radians).
struct NetFdm {
  std::uint32_t version = kVersion;
  double lon_rad = 0, lat_rad = 0;  // geodetic
  double alt_m = 0;                 // MSL
  float agl_m = 0;
  float phi_rad = 0, theta_rad = 0, psi_rad = 0;  // roll, pitch, true heading
  float alpha_rad = 0, beta_rad = 0;
  float phidot_rps = 0, thetadot_rps = 0, psidot_rps = 0;
  float vcas_kt = 0;
  float climbRate_fps = 0;
  float vNorth_fps = 0, vEast_fps = 0, vDown_fps = 0;
  float vWindBodyNorth_fps = 0, vWindBodyEast_fps = 0, vWindBodyDown_fps = 0;
  float aXPilot_fps2 = 0, aYPilot_fps2 = 0, aZPilot_fps2 = 0;
  float stallWarning = 0, slip_deg = 0;
  std::uint32_t numEngines = 0;
  std::array<std::uint32_t, kMaxEngines> engState{};
  std::array<float, kMaxEngines> rpm{}, fuelFlow_gph{}, fuelPx_psi{}, egt_degf{}, cht_degf{}, mpOsi{}, tit{},
      oilTemp_degf{}, oilPx_psi{};
  std::uint32_t numTanks = 0;
  std::array<float, kMaxTanks> fuelQuantity_gal{};
  std::uint32_t numWheels = 0;
  std::array<std::uint32_t, kMaxWheels> wow{};
  std::array<float, kMaxWheels> gearPos{}, gearSteer{}, gearCompression{};
  std::uint32_t curTime_unix = 0;  // simulated time (the warp included), unix s
  std::int32_t warp_s = 0;         // how far the user moved the simulated time from real time, s
  float visibility_m = 0;
  float elevator = 0, elevatorTrimTab = 0, leftFlap = 0, rightFlap = 0, leftAileron = 0, rightAileron = 0,
        rudder = 0, noseWheel = 0, speedbrake = 0, spoilers = 0;
};

// Decodes one datagram. Rejects, with the field named: other sizes
// (Malformed) and versions (Unsupported); non-finite or absurd position,
// attitude, body rates, velocities (above 12 km/s), accelerations or
// visibility, and engine/tank/wheel counts above FlightGear's array sizes
// (InvalidArgument). cur_time is FlightGear's simulated time (SimGear's
// SGTime adds the warp into it; warp only says by how much it was moved),
// so any value of either is taken.
Result<NetFdm> decodeNetFdm(std::span<const std::uint8_t> bytes);

// Encodes (for tests and for tools that stand in for FlightGear).
std::array<std::uint8_t, kPacketBytes> encodeNetFdm(const NetFdm& fdm);

}  // namespace sky::fgfdm
