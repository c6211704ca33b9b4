// Field-by-field layouts of the CIGI 3.3 packets we speak, with the ranges
// the decoder enforces (../shared/reference/cigi.md §3-§7).
#include "packet_codec.hpp"

#include <cstring>

#include "sky/cigi/celestial_time.hpp"

namespace sky::cigi::detail {

namespace {
constexpr std::uint16_t kByteSwapMagic = 0x8000;
constexpr std::uint8_t kMinorNibble = kMinorVersion << 4;
// Atmosphere Control and Weather Conditions Response carry the same block of
// fields at the same offsets (3: humidity, 4: temperature, 8: visibility,
// 12/16: horizontal/vertical wind, 20: direction, 24: pressure).
template <class T>
void writeAtmosphericBlock(PacketBuilder& b, const T& p) {
  b.u8(3, p.humidity_pct);
  b.f32(4, p.airTemperature_c);
  b.f32(8, p.visibility_m);
  b.f32(12, p.horizontalWind_mps);
  b.f32(16, p.verticalWind_mps);
  b.f32(20, p.windDirection_deg);
  b.f32(24, p.pressure_hpa);
}

template <class T>
void readAtmosphericBlock(PacketReader& r, T& p) {
  p.humidity_pct = r.u8(3);
  p.airTemperature_c = r.f32(4);
  p.visibility_m = r.f32(8);
  p.horizontalWind_mps = r.f32(12);
  p.verticalWind_mps = r.f32(16);
  p.windDirection_deg = r.f32(20);
  p.pressure_hpa = r.f32(24);
  r.range(3, "humidity", p.humidity_pct, 0, 100);
  r.range(4, "air temperature", p.airTemperature_c, -100, 100);
  r.range(8, "visibility", p.visibility_m, 0, 1.0e7);
  r.range(12, "horizontal wind", p.horizontalWind_mps, 0, 500);
  r.range(16, "vertical wind", p.verticalWind_mps, -500, 500);
  r.range(20, "wind direction", p.windDirection_deg, -180, 360);
  r.range(24, "barometric pressure", p.pressure_hpa, 0, 2000);
}

}  // namespace

// --- IG Control (1) ---------------------------------------------------------
void Codec<IgControl>::write(PacketBuilder& b, const IgControl& p) {
  b.u8(2, kMajorVersion);
  b.u8(3, static_cast<std::uint8_t>(p.databaseNumber));
  b.u8(4, static_cast<std::uint8_t>((static_cast<std::uint8_t>(p.mode) & 0x03) | bit(p.timestampValid, 2) |
                                    bit(p.extrapolationEnable, 3) | kMinorNibble));
  b.u16(6, kByteSwapMagic);
  b.u32(8, p.hostFrame);
  b.u32(12, p.timestamp_10us);
  b.u32(16, p.lastIgFrame);
}

Result<IgControl> Codec<IgControl>::read(PacketReader& r) {
  IgControl p;
  p.databaseNumber = static_cast<std::int8_t>(r.u8(3));
  const std::uint8_t flags = r.u8(4);
  p.mode = static_cast<IgMode>(flags & 0x03);
  if (p.mode == IgMode::OfflineMaintenance) r.invalid(4, "IG mode 3 is not valid from a host");
  p.timestampValid = isSet(flags, 2);
  p.extrapolationEnable = isSet(flags, 3);
  p.hostFrame = r.u32(8);
  p.timestamp_10us = r.u32(12);
  p.lastIgFrame = r.u32(16);
  return r.result(p);
}

// --- Entity Control (2) -----------------------------------------------------
void Codec<EntityControl>::write(PacketBuilder& b, const EntityControl& p) {
  b.u16(2, p.entityId);
  b.u8(4, static_cast<std::uint8_t>((static_cast<std::uint8_t>(p.state) & 0x03) | bit(p.attached, 2) |
                                    bit(p.collisionDetection, 3) | bit(p.inheritAlpha, 4) |
                                    ((p.groundClamp & 0x03) << 5)));
  b.u8(5, static_cast<std::uint8_t>((p.animationFlags & 0x0F) | bit(p.linearExtrapolation, 4)));
  b.u8(6, p.alpha);
  b.u16(8, p.entityType);
  b.u16(10, p.parentId);
  b.f32(12, p.roll_deg);
  b.f32(16, p.pitch_deg);
  b.f32(20, p.yaw_deg);
  b.f64(24, p.lat_deg);
  b.f64(32, p.lon_deg);
  b.f64(40, p.alt_m);
}

Result<EntityControl> Codec<EntityControl>::read(PacketReader& r) {
  EntityControl p;
  p.entityId = r.u16(2);
  const std::uint8_t b4 = r.u8(4);
  if ((b4 & 0x03) == 3) r.invalid(4, "entity state 3 is undefined");
  p.state = static_cast<EntityState>(b4 & 0x03);
  p.attached = isSet(b4, 2);
  p.collisionDetection = isSet(b4, 3);
  p.inheritAlpha = isSet(b4, 4);
  p.groundClamp = (b4 >> 5) & 0x03;
  if (p.groundClamp == 3) r.invalid(4, "ground/ocean clamp 3 is undefined");
  const std::uint8_t b5 = r.u8(5);
  p.animationFlags = b5 & 0x0F;
  p.linearExtrapolation = isSet(b5, 4);
  p.alpha = r.u8(6);
  p.entityType = r.u16(8);
  p.parentId = r.u16(10);
  p.roll_deg = r.f32(12);
  p.pitch_deg = r.f32(16);
  p.yaw_deg = r.f32(20);
  p.lat_deg = r.f64(24);
  p.lon_deg = r.f64(32);
  p.alt_m = r.f64(40);
  r.range(12, "roll", p.roll_deg, -180, 180);
  r.range(16, "pitch", p.pitch_deg, -90, 90);
  r.range(20, "yaw", p.yaw_deg, -360, 360);
  if (p.attached) {
    r.finite(24, "x offset", p.lat_deg);
    r.finite(32, "y offset", p.lon_deg);
    r.finite(40, "z offset", p.alt_m);
  } else {
    r.range(24, "latitude", p.lat_deg, -90, 90);
    r.range(32, "longitude", p.lon_deg, -180, 180);
    r.range(40, "altitude", p.alt_m, -12000, 1.0e7);
  }
  return r.result(p);
}

// --- Celestial Sphere Control (9) -------------------------------------------
void Codec<CelestialSphereControl>::write(PacketBuilder& b, const CelestialSphereControl& p) {
  b.u8(2, p.hour);
  b.u8(3, p.minute);
  b.u8(4, static_cast<std::uint8_t>(bit(p.ephemerisEnable, 0) | bit(p.sunEnable, 1) | bit(p.moonEnable, 2) |
                                    bit(p.starEnable, 3) | bit(p.dateTimeValid, 4)));
  b.u32(8, p.dateMmddyyyy);
  b.f32(12, p.starIntensity_pct);
}

Result<CelestialSphereControl> Codec<CelestialSphereControl>::read(PacketReader& r) {
  CelestialSphereControl p;
  p.hour = r.u8(2);
  p.minute = r.u8(3);
  const std::uint8_t f = r.u8(4);
  p.ephemerisEnable = isSet(f, 0);
  p.sunEnable = isSet(f, 1);
  p.moonEnable = isSet(f, 2);
  p.starEnable = isSet(f, 3);
  p.dateTimeValid = isSet(f, 4);
  p.dateMmddyyyy = r.u32(8);
  p.starIntensity_pct = r.f32(12);
  r.range(2, "hour", p.hour, 0, 23);
  r.range(3, "minute", p.minute, 0, 59);
  // A date the host says is valid must be a calendar date of a year the
  // ephemeris serves (30 February, month 13 and year 20250 are dropped).
  if (p.dateTimeValid && !celestialUtc(p))
    r.invalid(8, "date " + std::to_string(p.dateMmddyyyy) + " is not a MMDDYYYY date of years " +
                     std::to_string(kCelestialMinYear) + "-" + std::to_string(kCelestialMaxYear));
  r.range(12, "star intensity", p.starIntensity_pct, 0, 100);
  return r.result(p);
}

// --- Atmosphere Control (10) --------------------------------------------------
void Codec<AtmosphereControl>::write(PacketBuilder& b, const AtmosphereControl& p) {
  b.u8(2, bit(p.atmosphericModelEnable, 0));
  writeAtmosphericBlock(b, p);
}

Result<AtmosphereControl> Codec<AtmosphereControl>::read(PacketReader& r) {
  AtmosphereControl p;
  p.atmosphericModelEnable = isSet(r.u8(2), 0);
  readAtmosphericBlock(r, p);
  return r.result(p);
}

// --- Environmental Region Control (11) ---------------------------------------
void Codec<EnvironmentalRegionControl>::write(PacketBuilder& b, const EnvironmentalRegionControl& p) {
  b.u16(2, p.regionId);
  b.u8(4, static_cast<std::uint8_t>((static_cast<std::uint8_t>(p.state) & 0x03) | bit(p.mergeWeather, 2) |
                                    bit(p.mergeAerosol, 3) | bit(p.mergeMaritime, 4) | bit(p.mergeTerrestrial, 5)));
  b.f64(8, p.lat_deg);
  b.f64(16, p.lon_deg);
  b.f32(24, p.sizeX_m);
  b.f32(28, p.sizeY_m);
  b.f32(32, p.cornerRadius_m);
  b.f32(36, p.rotation_deg);
  b.f32(40, p.transitionPerimeter_m);
}

Result<EnvironmentalRegionControl> Codec<EnvironmentalRegionControl>::read(PacketReader& r) {
  EnvironmentalRegionControl p;
  p.regionId = r.u16(2);
  const std::uint8_t f = r.u8(4);
  if ((f & 0x03) == 3) r.invalid(4, "region state 3 is undefined");
  p.state = static_cast<RegionState>(f & 0x03);
  p.mergeWeather = isSet(f, 2);
  p.mergeAerosol = isSet(f, 3);
  p.mergeMaritime = isSet(f, 4);
  p.mergeTerrestrial = isSet(f, 5);
  p.lat_deg = r.f64(8);
  p.lon_deg = r.f64(16);
  p.sizeX_m = r.f32(24);
  p.sizeY_m = r.f32(28);
  p.cornerRadius_m = r.f32(32);
  p.rotation_deg = r.f32(36);
  p.transitionPerimeter_m = r.f32(40);
  r.range(8, "latitude", p.lat_deg, -90, 90);
  r.range(16, "longitude", p.lon_deg, -180, 180);
  r.range(24, "size x", p.sizeX_m, 0, 2.0e7);
  r.range(28, "size y", p.sizeY_m, 0, 2.0e7);
  r.range(32, "corner radius", p.cornerRadius_m, 0, 1.0e7);
  r.range(36, "rotation", p.rotation_deg, -180, 180);
  r.range(40, "transition perimeter", p.transitionPerimeter_m, 0, 1.0e7);
  return r.result(p);
}

// --- Weather Control (12) -----------------------------------------------------
void Codec<WeatherControl>::write(PacketBuilder& b, const WeatherControl& p) {
  b.u16(2, p.entityOrRegionId);
  b.u8(4, static_cast<std::uint8_t>(p.layerId));
  b.u8(5, p.humidity_pct);
  b.u8(6, static_cast<std::uint8_t>(bit(p.weatherEnable, 0) | bit(p.scudEnable, 1) | bit(p.randomWindsEnable, 2) |
                                    bit(p.randomLightningEnable, 3) |
                                    ((static_cast<std::uint8_t>(p.cloudType) & 0x0F) << 4)));
  b.u8(7, static_cast<std::uint8_t>((static_cast<std::uint8_t>(p.scope) & 0x03) | ((p.severity & 0x07) << 2)));
  b.f32(8, p.airTemperature_c);
  b.f32(12, p.visibility_m);
  b.f32(16, p.scudFrequency_pct);
  b.f32(20, p.coverage_pct);
  b.f32(24, p.baseElevation_m);
  b.f32(28, p.thickness_m);
  b.f32(32, p.transitionBand_m);
  b.f32(36, p.horizontalWind_mps);
  b.f32(40, p.verticalWind_mps);
  b.f32(44, p.windDirection_deg);
  b.f32(48, p.pressure_hpa);
  b.f32(52, p.aerosol_gpm3);
}

Result<WeatherControl> Codec<WeatherControl>::read(PacketReader& r) {
  WeatherControl p;
  p.entityOrRegionId = r.u16(2);
  p.layerId = static_cast<LayerId>(r.u8(4));
  p.humidity_pct = r.u8(5);
  const std::uint8_t f = r.u8(6);
  p.weatherEnable = isSet(f, 0);
  p.scudEnable = isSet(f, 1);
  p.randomWindsEnable = isSet(f, 2);
  p.randomLightningEnable = isSet(f, 3);
  const std::uint8_t type = f >> 4;
  // 12-15 are our precipitation types, which a host sets by layer id (4-7), not as a cloud type.
  if (type > static_cast<std::uint8_t>(weather::CloudType::Fog))
    r.invalid(6, "cloud type " + std::to_string(type) + " is IG-defined; we define 11 (fog)");
  p.cloudType = static_cast<weather::CloudType>(type);
  const std::uint8_t s = r.u8(7);
  if ((s & 0x03) == 3) r.invalid(7, "scope 3 is undefined");
  p.scope = static_cast<WeatherScope>(s & 0x03);
  p.severity = (s >> 2) & 0x07;
  p.airTemperature_c = r.f32(8);
  p.visibility_m = r.f32(12);
  p.scudFrequency_pct = r.f32(16);
  p.coverage_pct = r.f32(20);
  p.baseElevation_m = r.f32(24);
  p.thickness_m = r.f32(28);
  p.transitionBand_m = r.f32(32);
  p.horizontalWind_mps = r.f32(36);
  p.verticalWind_mps = r.f32(40);
  p.windDirection_deg = r.f32(44);
  p.pressure_hpa = r.f32(48);
  p.aerosol_gpm3 = r.f32(52);
  r.range(5, "humidity", p.humidity_pct, 0, 100);
  r.range(7, "severity", p.severity, 0, 5);
  r.range(8, "air temperature", p.airTemperature_c, -100, 100);
  r.range(12, "visibility", p.visibility_m, 0, 1.0e7);
  r.range(16, "scud frequency", p.scudFrequency_pct, 0, 100);
  r.range(20, "coverage", p.coverage_pct, 0, 100);
  r.range(24, "base elevation", p.baseElevation_m, -12000, 1.0e5);
  r.range(28, "thickness", p.thickness_m, 0, 1.0e5);
  r.range(32, "transition band", p.transitionBand_m, 0, 1.0e5);
  r.range(36, "horizontal wind", p.horizontalWind_mps, 0, 500);
  r.range(40, "vertical wind", p.verticalWind_mps, -500, 500);
  r.range(44, "wind direction", p.windDirection_deg, -180, 360);
  r.range(48, "barometric pressure", p.pressure_hpa, 0, 2000);
  r.range(52, "aerosol concentration", p.aerosol_gpm3, 0, 1.0e4);
  return r.result(p);
}

// --- View Control (16) --------------------------------------------------------
void Codec<ViewControl>::write(PacketBuilder& b, const ViewControl& p) {
  b.u16(2, p.viewId);
  b.u8(4, p.groupId);
  b.u8(5, static_cast<std::uint8_t>(bit(p.xEnable, 0) | bit(p.yEnable, 1) | bit(p.zEnable, 2) | bit(p.rollEnable, 3) |
                                    bit(p.pitchEnable, 4) | bit(p.yawEnable, 5)));
  b.u16(6, p.entityId);
  b.f32(8, p.x_m);
  b.f32(12, p.y_m);
  b.f32(16, p.z_m);
  b.f32(20, p.roll_deg);
  b.f32(24, p.pitch_deg);
  b.f32(28, p.yaw_deg);
}

Result<ViewControl> Codec<ViewControl>::read(PacketReader& r) {
  ViewControl p;
  p.viewId = r.u16(2);
  p.groupId = r.u8(4);
  const std::uint8_t f = r.u8(5);
  p.xEnable = isSet(f, 0);
  p.yEnable = isSet(f, 1);
  p.zEnable = isSet(f, 2);
  p.rollEnable = isSet(f, 3);
  p.pitchEnable = isSet(f, 4);
  p.yawEnable = isSet(f, 5);
  p.entityId = r.u16(6);
  p.x_m = r.f32(8);
  p.y_m = r.f32(12);
  p.z_m = r.f32(16);
  p.roll_deg = r.f32(20);
  p.pitch_deg = r.f32(24);
  p.yaw_deg = r.f32(28);
  r.range(8, "x offset", p.x_m, -1.0e6, 1.0e6);
  r.range(12, "y offset", p.y_m, -1.0e6, 1.0e6);
  r.range(16, "z offset", p.z_m, -1.0e6, 1.0e6);
  r.range(20, "roll", p.roll_deg, -180, 180);
  r.range(24, "pitch", p.pitch_deg, -90, 90);
  r.range(28, "yaw", p.yaw_deg, -360, 360);
  return r.result(p);
}

// --- View Definition (21) -----------------------------------------------------
void Codec<ViewDefinition>::write(PacketBuilder& b, const ViewDefinition& p) {
  b.u16(2, p.viewId);
  b.u8(4, p.groupId);
  b.u8(5, static_cast<std::uint8_t>(bit(p.nearEnable, 0) | bit(p.farEnable, 1) | bit(p.leftEnable, 2) |
                                    bit(p.rightEnable, 3) | bit(p.topEnable, 4) | bit(p.bottomEnable, 5) |
                                    ((p.mirrorMode & 0x03) << 6)));
  b.u8(6, static_cast<std::uint8_t>((p.pixelReplication & 0x07) | bit(p.orthographic, 3) | bit(p.reorder, 4) |
                                    ((p.viewType & 0x07) << 5)));
  b.f32(8, p.near_m);
  b.f32(12, p.far_m);
  b.f32(16, p.left_deg);
  b.f32(20, p.right_deg);
  b.f32(24, p.top_deg);
  b.f32(28, p.bottom_deg);
}

Result<ViewDefinition> Codec<ViewDefinition>::read(PacketReader& r) {
  ViewDefinition p;
  p.viewId = r.u16(2);
  p.groupId = r.u8(4);
  const std::uint8_t f = r.u8(5);
  p.nearEnable = isSet(f, 0);
  p.farEnable = isSet(f, 1);
  p.leftEnable = isSet(f, 2);
  p.rightEnable = isSet(f, 3);
  p.topEnable = isSet(f, 4);
  p.bottomEnable = isSet(f, 5);
  p.mirrorMode = f >> 6;
  const std::uint8_t g = r.u8(6);
  p.pixelReplication = g & 0x07;
  p.orthographic = isSet(g, 3);
  p.reorder = isSet(g, 4);
  p.viewType = g >> 5;
  p.near_m = r.f32(8);
  p.far_m = r.f32(12);
  p.left_deg = r.f32(16);
  p.right_deg = r.f32(20);
  p.top_deg = r.f32(24);
  p.bottom_deg = r.f32(28);
  r.range(8, "near", p.near_m, 0, 1.0e9);
  r.range(12, "far", p.far_m, 0, 1.0e9);
  if (p.nearEnable && p.farEnable && !(p.near_m < p.far_m)) r.invalid(8, "near plane is not in front of far plane");
  r.range(16, "left", p.left_deg, -89.9, 89.9);
  r.range(20, "right", p.right_deg, -89.9, 89.9);
  r.range(24, "top", p.top_deg, -89.9, 89.9);
  r.range(28, "bottom", p.bottom_deg, -89.9, 89.9);
  return r.result(p);
}

// --- Environmental Conditions Request (28) ------------------------------------
void Codec<EnvironmentalConditionsRequest>::write(PacketBuilder& b, const EnvironmentalConditionsRequest& p) {
  b.u8(2, p.requestType & 0x0F);
  b.u8(3, p.requestId);
  b.f64(8, p.lat_deg);
  b.f64(16, p.lon_deg);
  b.f64(24, p.alt_m);
}

Result<EnvironmentalConditionsRequest> Codec<EnvironmentalConditionsRequest>::read(PacketReader& r) {
  EnvironmentalConditionsRequest p;
  p.requestType = r.u8(2) & 0x0F;
  p.requestId = r.u8(3);
  p.lat_deg = r.f64(8);
  p.lon_deg = r.f64(16);
  p.alt_m = r.f64(24);
  if (p.requestType == 0) r.invalid(2, "request type 0 asks for nothing");
  r.range(8, "latitude", p.lat_deg, -90, 90);
  r.range(16, "longitude", p.lon_deg, -180, 180);
  r.range(24, "altitude", p.alt_m, -12000, 1.0e7);
  return r.result(p);
}

// --- Start of Frame (101) -----------------------------------------------------
void Codec<StartOfFrame>::write(PacketBuilder& b, const StartOfFrame& p) {
  b.u8(2, kMajorVersion);
  b.u8(3, static_cast<std::uint8_t>(p.databaseNumber));
  b.u8(4, p.igStatus);
  b.u8(5, static_cast<std::uint8_t>((static_cast<std::uint8_t>(p.mode) & 0x03) | bit(p.timestampValid, 2) |
                                    bit(p.earthReferenceModelHostDefined, 3) | kMinorNibble));
  b.u16(6, kByteSwapMagic);
  b.u32(8, p.igFrame);
  b.u32(12, p.timestamp_10us);
  b.u32(16, p.lastHostFrame);
}

Result<StartOfFrame> Codec<StartOfFrame>::read(PacketReader& r) {
  StartOfFrame p;
  p.databaseNumber = static_cast<std::int8_t>(r.u8(3));
  p.igStatus = r.u8(4);
  const std::uint8_t flags = r.u8(5);
  p.mode = static_cast<IgMode>(flags & 0x03);
  p.timestampValid = isSet(flags, 2);
  p.earthReferenceModelHostDefined = isSet(flags, 3);
  p.igFrame = r.u32(8);
  p.timestamp_10us = r.u32(12);
  p.lastHostFrame = r.u32(16);
  return r.result(p);
}

// --- Weather Conditions Response (109) ----------------------------------------
void Codec<WeatherConditionsResponse>::write(PacketBuilder& b, const WeatherConditionsResponse& p) {
  b.u8(2, p.requestId);
  writeAtmosphericBlock(b, p);
}

Result<WeatherConditionsResponse> Codec<WeatherConditionsResponse>::read(PacketReader& r) {
  WeatherConditionsResponse p;
  p.requestId = r.u8(2);
  readAtmosphericBlock(r, p);
  return r.result(p);
}

// --- Aerosol Concentration Response (110) -------------------------------------
void Codec<AerosolConcentrationResponse>::write(PacketBuilder& b, const AerosolConcentrationResponse& p) {
  b.u8(2, p.requestId);
  b.u8(3, static_cast<std::uint8_t>(p.layerId));
  b.f32(4, p.concentration_gpm3);
}

Result<AerosolConcentrationResponse> Codec<AerosolConcentrationResponse>::read(PacketReader& r) {
  AerosolConcentrationResponse p;
  p.requestId = r.u8(2);
  p.layerId = static_cast<LayerId>(r.u8(3));
  p.concentration_gpm3 = r.f32(4);
  r.range(4, "aerosol concentration", p.concentration_gpm3, 0, 1.0e4);
  return r.result(p);
}

// --- Component Control (4): the camera exposure component --------------------
// The walker hands over only packets of our class and component id
// (claimsCameraExposure); the rest of the packet is checked here.
void Codec<CameraExposureControl>::write(PacketBuilder& b, const CameraExposureControl& p) {
  b.u16(2, CameraExposureControl::kComponentId);
  b.u16(4, p.viewId);
  b.u8(6, CameraExposureControl::kComponentClass);
  b.u8(7, static_cast<std::uint8_t>(p.mode));
  b.f32(8, p.ev100);
  b.f32(12, p.compensation_ev);
}

Result<CameraExposureControl> Codec<CameraExposureControl>::read(PacketReader& r) {
  CameraExposureControl p;
  p.viewId = r.u16(4);
  if ((r.u8(6) & 0xC0) != 0) r.invalid(6, "reserved bits 6-7 of the component class byte are set");
  const std::uint8_t state = r.u8(7);
  if (state > static_cast<std::uint8_t>(ExposureMode::Fixed))
    r.invalid(7, "camera exposure state " + std::to_string(state) + " is neither 0 (auto) nor 1 (fixed)");
  p.mode = static_cast<ExposureMode>(state);
  p.ev100 = r.f32(8);
  p.compensation_ev = r.f32(12);
  if (p.mode == ExposureMode::Fixed)
    r.range(8, "EV100", p.ev100, -10, 30);
  else
    r.finite(8, "EV100", p.ev100);
  r.range(12, "exposure compensation", p.compensation_ev, -10, 10);
  for (std::size_t off = 16; off < CameraExposureControl::kSize; off += 4)
    if (r.u32(off) != 0) r.invalid(off, "reserved data word is not 0");
  return r.result(p);
}

bool claimsCameraExposure(const std::uint8_t* packet, std::size_t size, ByteOrder order) {
  if (size < 8) return false;
  // Two fields read directly: a PacketReader here (with its optional error
  // string never set) trips GCC 12's -Wmaybe-uninitialized in the sanitizer
  // build, which treats warnings as errors.
  std::uint16_t id = 0;
  std::memcpy(&id, packet + 2, sizeof id);
  if (needsSwap(order)) id = static_cast<std::uint16_t>((id >> 8) | (id << 8));
  return (packet[6] & 0x3F) == CameraExposureControl::kComponentClass && id == CameraExposureControl::kComponentId;
}

}  // namespace sky::cigi::detail
