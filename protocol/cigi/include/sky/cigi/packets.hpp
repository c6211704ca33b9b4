// CIGI 3.3 packets as typed values (layouts: ../shared/reference/cigi.md).
// Units are in the field names; angles in degrees as on the wire. Ranges in
// the comments are what the decoder accepts (CCL bound checks where the ICD
// states none).
#pragma once

#include <cstdint>

#include "sky/weather/model.hpp"

namespace sky::cigi {

inline constexpr std::uint8_t kMajorVersion = 3;
inline constexpr std::uint8_t kMinorVersion = 3;

enum class ByteOrder { Big, Little };

enum class IgMode : std::uint8_t { ResetStandby = 0, Operate = 1, Debug = 2, OfflineMaintenance = 3 };
enum class EntityState : std::uint8_t { Inactive = 0, Active = 1, Destroyed = 2 };
enum class RegionState : std::uint8_t { Inactive = 0, Active = 1, Destroyed = 2 };
enum class WeatherScope : std::uint8_t { Global = 0, Regional = 1, Entity = 2 };

// Weather Control layer ids: 0-9 are standard; 10-255 are IG-defined and
// carried as LayerId{n} (an enum class holds any value of its underlying type).
enum class LayerId : std::uint8_t {
  GroundFog = 0, CloudLayer1 = 1, CloudLayer2 = 2, CloudLayer3 = 3, Rain = 4,
  Snow = 5, Sleet = 6, Hail = 7, Sand = 8, Dust = 9,
};

// Request Type bits of Environmental Conditions Request.
enum RequestTypeBits : std::uint8_t {
  kRequestMaritime = 1, kRequestTerrestrial = 2, kRequestWeather = 4, kRequestAerosol = 8,
};

// IG Control, id 1, 24 bytes: first packet of every host->IG datagram.
struct IgControl {
  static constexpr std::uint8_t kId = 1, kSize = 24;
  std::int8_t databaseNumber = 0;
  IgMode mode = IgMode::Operate;  // Offline Maintenance is invalid from a host
  bool timestampValid = false;
  bool extrapolationEnable = false;
  std::uint32_t hostFrame = 0;
  std::uint32_t timestamp_10us = 0;
  std::uint32_t lastIgFrame = 0;
  bool operator==(const IgControl&) const = default;
};

// Entity Control, id 2, 48 bytes. Entity 0 is the ownship.
struct EntityControl {
  static constexpr std::uint8_t kId = 2, kSize = 48;
  std::uint16_t entityId = 0;
  EntityState state = EntityState::Active;
  bool attached = false;
  bool collisionDetection = false;
  bool inheritAlpha = false;
  std::uint8_t groundClamp = 0;      // 0 none, 1 non-conformal, 2 conformal
  std::uint8_t animationFlags = 0;   // byte 5 bits 0-3 (direction, loop, state)
  bool linearExtrapolation = false;  // byte 5 bit 4 (3.3)
  std::uint8_t alpha = 255;
  std::uint16_t entityType = 0;
  std::uint16_t parentId = 0;
  float roll_deg = 0;   // [-180, 180]
  float pitch_deg = 0;  // [-90, 90]
  float yaw_deg = 0;    // [0, 360], true heading
  double lat_deg = 0;   // [-90, 90] when detached (else m along parent x)
  double lon_deg = 0;   // [-180, 180] when detached
  double alt_m = 0;     // MSL
  bool operator==(const EntityControl&) const = default;
};

// Celestial Sphere Control, id 9, 16 bytes. Hour/minute are UTC.
struct CelestialSphereControl {
  static constexpr std::uint8_t kId = 9, kSize = 16;
  std::uint8_t hour = 12;    // [0, 23]
  std::uint8_t minute = 0;   // [0, 59]
  bool ephemerisEnable = false, sunEnable = true, moonEnable = true, starEnable = true;
  bool dateTimeValid = false;
  std::uint32_t dateMmddyyyy = 1012000;  // month*10^6 + day*10^4 + year
  float starIntensity_pct = 100;         // [0, 100]
  bool operator==(const CelestialSphereControl&) const = default;
};

// Atmosphere Control, id 10, 32 bytes: the global atmosphere.
struct AtmosphereControl {
  static constexpr std::uint8_t kId = 10, kSize = 32;
  bool atmosphericModelEnable = false;
  std::uint8_t humidity_pct = 30;  // [0, 100]
  float airTemperature_c = 15;
  float visibility_m = 64373.76f;  // >= 0
  float horizontalWind_mps = 0;    // >= 0
  float verticalWind_mps = 0;
  float windDirection_deg = 0;     // from, [0, 360]
  float pressure_hpa = 1013.25f;   // >= 0
  bool operator==(const AtmosphereControl&) const = default;
};

// Environmental Region Control, id 11, 48 bytes: a rounded rectangle of
// regional weather with a transition perimeter.
struct EnvironmentalRegionControl {
  static constexpr std::uint8_t kId = 11, kSize = 48;
  std::uint16_t regionId = 0;
  RegionState state = RegionState::Active;
  bool mergeWeather = false, mergeAerosol = false, mergeMaritime = false, mergeTerrestrial = false;
  double lat_deg = 0;  // [-90, 90]
  double lon_deg = 0;  // [-180, 180]
  float sizeX_m = 0, sizeY_m = 0;  // >= 0
  float cornerRadius_m = 0;        // >= 0
  float rotation_deg = 0;          // [-180, 180]
  float transitionPerimeter_m = 0; // >= 0
  bool operator==(const EnvironmentalRegionControl&) const = default;
};

// Weather Control, id 12, 56 bytes: a layer, a region's layer, or an entity's weather.
struct WeatherControl {
  static constexpr std::uint8_t kId = 12, kSize = 56;
  std::uint16_t entityOrRegionId = 0;
  LayerId layerId = LayerId::CloudLayer1;
  std::uint8_t humidity_pct = 0;  // [0, 100]
  bool weatherEnable = true, scudEnable = false, randomWindsEnable = false, randomLightningEnable = false;
  weather::CloudType cloudType = weather::CloudType::None;  // 11 is our fog; 12-15 rejected (IG-defined, we have none)
  WeatherScope scope = WeatherScope::Global;
  std::uint8_t severity = 0;  // [0, 5]
  float airTemperature_c = 15;
  float visibility_m = 0;          // >= 0
  float scudFrequency_pct = 0;     // [0, 100]
  float coverage_pct = 0;          // [0, 100]
  float baseElevation_m = 0;       // MSL
  float thickness_m = 0;           // >= 0
  float transitionBand_m = 0;      // >= 0
  float horizontalWind_mps = 0;    // >= 0
  float verticalWind_mps = 0;
  float windDirection_deg = 0;     // from, [-180, 360]
  float pressure_hpa = 1013.25f;   // >= 0
  float aerosol_gpm3 = 0;          // >= 0
  bool operator==(const WeatherControl&) const = default;
};

// View Control, id 16, 32 bytes: eyepoint offset and rotation relative to an entity.
struct ViewControl {
  static constexpr std::uint8_t kId = 16, kSize = 32;
  std::uint16_t viewId = 0;
  std::uint8_t groupId = 0;
  bool xEnable = false, yEnable = false, zEnable = false;
  bool rollEnable = false, pitchEnable = false, yawEnable = false;
  std::uint16_t entityId = 0;
  float x_m = 0, y_m = 0, z_m = 0;  // body axes: forward, right, down
  float roll_deg = 0;   // [-180, 180]
  float pitch_deg = 0;  // [-90, 90]
  float yaw_deg = 0;    // [-360, 360]
  bool operator==(const ViewControl&) const = default;
};

// View Definition, id 21, 32 bytes: the frustum of a view.
struct ViewDefinition {
  static constexpr std::uint8_t kId = 21, kSize = 32;
  std::uint16_t viewId = 0;
  std::uint8_t groupId = 0;
  bool nearEnable = false, farEnable = false, leftEnable = false, rightEnable = false;
  bool topEnable = false, bottomEnable = false;
  std::uint8_t mirrorMode = 0;        // [0, 3]
  std::uint8_t pixelReplication = 0;  // [0, 7]
  bool orthographic = false;
  bool reorder = false;
  std::uint8_t viewType = 0;          // [0, 7]
  float near_m = 0.5f, far_m = 100000;  // 0 < near < far
  float left_deg = -30, right_deg = 30, top_deg = 20, bottom_deg = -20;  // half-angles, (-90, 90)
  bool operator==(const ViewDefinition&) const = default;
};

// Component Control, id 4, 32 bytes (CIGI 3.3: 2 component id, 4 instance
// id, 6 bits 0-5 component class, 7 component state, 8-31 six 32-bit data
// words), of Skyshell's camera exposure component: class View, component
// id kComponentId. The host fixes the EV100 of the channels' cameras, or
// gives it back to their meter (docs/cigi-conformance.md). Any other
// Component Control is not decoded (skipped by its size, counted).
enum class ExposureMode : std::uint8_t { Auto = 0, Fixed = 1 };
struct CameraExposureControl {
  static constexpr std::uint8_t kId = 4, kSize = 32;
  static constexpr std::uint8_t kComponentClass = 1;    // View: the instance id is a view id
  static constexpr std::uint16_t kComponentId = 100;    // IG-defined; Skyshell's camera exposure
  static constexpr std::uint16_t kAllViews = 0xFFFF;    // instance id: every view (every channel)
  std::uint16_t viewId = kAllViews;         // the instance id
  ExposureMode mode = ExposureMode::Auto;   // the component state: 0 auto (the meter), 1 fixed
  float ev100 = 0;            // data word 1 (8-11): fixed: [-10, 30]; auto: finite, not used
  float compensation_ev = 0;  // data word 2 (12-15): [-10, 10], added in both modes
  // Data words 3-6 (16-31) are reserved: 0.
  bool operator==(const CameraExposureControl&) const = default;
};

// Environmental Conditions Request, id 28, 32 bytes.
struct EnvironmentalConditionsRequest {
  static constexpr std::uint8_t kId = 28, kSize = 32;
  std::uint8_t requestType = kRequestWeather;  // RequestTypeBits, [1, 15]
  std::uint8_t requestId = 0;
  double lat_deg = 0;  // [-90, 90]
  double lon_deg = 0;  // [-180, 180]
  double alt_m = 0;    // MSL
  bool operator==(const EnvironmentalConditionsRequest&) const = default;
};

// Start of Frame, id 101, 24 bytes: first packet of every IG->host datagram.
struct StartOfFrame {
  static constexpr std::uint8_t kId = 101, kSize = 24;
  std::int8_t databaseNumber = 0;
  std::uint8_t igStatus = 0;
  IgMode mode = IgMode::Operate;
  bool timestampValid = false;
  bool earthReferenceModelHostDefined = false;  // false = WGS84
  std::uint32_t igFrame = 0;
  std::uint32_t timestamp_10us = 0;
  std::uint32_t lastHostFrame = 0;
  bool operator==(const StartOfFrame&) const = default;
};

// Weather Conditions Response, id 109, 32 bytes.
struct WeatherConditionsResponse {
  static constexpr std::uint8_t kId = 109, kSize = 32;
  std::uint8_t requestId = 0;
  std::uint8_t humidity_pct = 0;
  float airTemperature_c = 15;
  float visibility_m = 0;
  float horizontalWind_mps = 0;
  float verticalWind_mps = 0;
  float windDirection_deg = 0;  // from
  float pressure_hpa = 1013.25f;
  bool operator==(const WeatherConditionsResponse&) const = default;
};

// Aerosol Concentration Response, id 110, 8 bytes.
struct AerosolConcentrationResponse {
  static constexpr std::uint8_t kId = 110, kSize = 8;
  std::uint8_t requestId = 0;
  LayerId layerId = LayerId::GroundFog;
  float concentration_gpm3 = 0;
  bool operator==(const AerosolConcentrationResponse&) const = default;
};

}  // namespace sky::cigi
