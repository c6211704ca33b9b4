// CIGI 3.3 packets as typed values (layouts: ../shared/reference/cigi.md).
// Units are in the field names; angles in degrees as on the wire.
#pragma once

#include <cstdint>

namespace sky::cigi {

inline constexpr std::uint8_t kMajorVersion = 3;
inline constexpr std::uint8_t kMinorVersion = 3;

enum class ByteOrder { Big, Little };

enum class IgMode : std::uint8_t { ResetStandby = 0, Operate = 1, Debug = 2, OfflineMaintenance = 3 };

enum class EntityState : std::uint8_t { Inactive = 0, Active = 1, Destroyed = 2 };

// IG Control, id 1, 24 bytes: first packet of every host->IG datagram.
struct IgControl {
  static constexpr std::uint8_t kId = 1;
  static constexpr std::uint8_t kSize = 24;
  std::int8_t databaseNumber = 0;
  IgMode mode = IgMode::Operate;  // Offline Maintenance is invalid from a host
  bool timestampValid = false;
  bool extrapolationEnable = false;
  std::uint32_t hostFrame = 0;
  std::uint32_t timestamp_10us = 0;
  std::uint32_t lastIgFrame = 0;
};

// Entity Control, id 2, 48 bytes. Entity 0 is the ownship.
struct EntityControl {
  static constexpr std::uint8_t kId = 2;
  static constexpr std::uint8_t kSize = 48;
  std::uint16_t entityId = 0;
  EntityState state = EntityState::Active;
  bool attached = false;
  bool collisionDetection = false;
  bool inheritAlpha = false;
  std::uint8_t groundClamp = 0;       // 0 none, 1 non-conformal, 2 conformal
  std::uint8_t animationFlags = 0;    // byte 5 bits 0-3 (direction, loop, state)
  bool linearExtrapolation = false;   // byte 5 bit 4 (3.3)
  std::uint8_t alpha = 255;
  std::uint16_t entityType = 0;
  std::uint16_t parentId = 0;
  float roll_deg = 0;   // [-180, 180]
  float pitch_deg = 0;  // [-90, 90]
  float yaw_deg = 0;    // [0, 360], true heading
  double lat_deg = 0;   // [-90, 90] when detached
  double lon_deg = 0;   // [-180, 180] when detached
  double alt_m = 0;     // MSL
};

// Start of Frame, id 101, 24 bytes: first packet of every IG->host datagram.
struct StartOfFrame {
  static constexpr std::uint8_t kId = 101;
  static constexpr std::uint8_t kSize = 24;
  std::int8_t databaseNumber = 0;
  std::uint8_t igStatus = 0;
  IgMode mode = IgMode::Operate;
  bool timestampValid = false;
  bool earthReferenceModelHostDefined = false;  // false = WGS84
  std::uint32_t igFrame = 0;
  std::uint32_t timestamp_10us = 0;
  std::uint32_t lastHostFrame = 0;
};

}  // namespace sky::cigi
