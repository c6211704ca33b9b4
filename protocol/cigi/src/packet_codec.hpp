// Private to the CIGI codec: one Codec<T> per packet type, with the packet's
// name, its field-by-field writer and its reader with range checks.
#pragma once

#include "byte_io.hpp"

namespace sky::cigi::detail {

template <class T>
struct Codec;

#define SKY_CIGI_CODEC(Type, Name)                     \
  template <>                                          \
  struct Codec<Type> {                                 \
    static constexpr const char* kName = Name;         \
    static void write(PacketBuilder& b, const Type& p); \
    static Result<Type> read(PacketReader& r);         \
  };

SKY_CIGI_CODEC(IgControl, "IG Control")
SKY_CIGI_CODEC(EntityControl, "Entity Control")
SKY_CIGI_CODEC(CelestialSphereControl, "Celestial Sphere Control")
SKY_CIGI_CODEC(AtmosphereControl, "Atmosphere Control")
SKY_CIGI_CODEC(EnvironmentalRegionControl, "Environmental Region Control")
SKY_CIGI_CODEC(WeatherControl, "Weather Control")
SKY_CIGI_CODEC(ViewControl, "View Control")
SKY_CIGI_CODEC(ViewDefinition, "View Definition")
SKY_CIGI_CODEC(EnvironmentalConditionsRequest, "Environmental Conditions Request")
SKY_CIGI_CODEC(StartOfFrame, "Start of Frame")
SKY_CIGI_CODEC(WeatherConditionsResponse, "Weather Conditions Response")
SKY_CIGI_CODEC(AerosolConcentrationResponse, "Aerosol Concentration Response")
SKY_CIGI_CODEC(CameraExposureControl, "Component Control (camera exposure)")

#undef SKY_CIGI_CODEC

// Whether a Component Control (id 4) of `size` bytes at `packet` is of our
// camera exposure component (its class and component id; size >= 8 to hold
// them). Component Control carries many components in one id: only ours is
// decoded, the others are skipped like any packet a channel does not use.
bool claimsCameraExposure(const std::uint8_t* packet, std::size_t size, ByteOrder order);

}  // namespace sky::cigi::detail
