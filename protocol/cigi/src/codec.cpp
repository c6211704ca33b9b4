// CIGI 3.3 datagram walker and writer. Per-packet layouts live in
// packet_codec.cpp; this file checks the datagram's structure.
#include "sky/cigi/codec.hpp"

#include <array>
#include <string>

#include "packet_codec.hpp"

namespace sky::cigi {

using detail::Codec;
using detail::PacketBuilder;
using detail::PacketReader;

namespace {

// One row per packet id we decode: its size, direction and reader.
struct PacketKind {
  std::uint8_t id;
  std::uint8_t size;
  Direction direction;
  const char* name;
  Result<Packet> (*read)(PacketReader&);
  // For an id several packets share (Component Control): whether this
  // packet is the one we decode. Null: every packet of the id is.
  bool (*claims)(const std::uint8_t* packet, std::size_t size, ByteOrder order) = nullptr;
};

template <class T>
Result<Packet> readAs(PacketReader& r) {
  auto p = Codec<T>::read(r);
  if (!p) return tl::unexpected(p.error());
  return Packet(*p);
}

template <class T>
constexpr PacketKind kind(Direction d) {
  return {T::kId, T::kSize, d, Codec<T>::kName, &readAs<T>};
}

template <class T>
constexpr PacketKind claimedKind(Direction d, bool (*claims)(const std::uint8_t*, std::size_t, ByteOrder)) {
  return {T::kId, T::kSize, d, Codec<T>::kName, &readAs<T>, claims};
}

constexpr std::array kKinds = {
    kind<IgControl>(Direction::HostToIg),
    kind<EntityControl>(Direction::HostToIg),
    kind<CelestialSphereControl>(Direction::HostToIg),
    kind<AtmosphereControl>(Direction::HostToIg),
    kind<EnvironmentalRegionControl>(Direction::HostToIg),
    kind<WeatherControl>(Direction::HostToIg),
    kind<ViewControl>(Direction::HostToIg),
    kind<ViewDefinition>(Direction::HostToIg),
    kind<EnvironmentalConditionsRequest>(Direction::HostToIg),
    kind<StartOfFrame>(Direction::IgToHost),
    kind<WeatherConditionsResponse>(Direction::IgToHost),
    kind<AerosolConcentrationResponse>(Direction::IgToHost),
    claimedKind<CameraExposureControl>(Direction::HostToIg, &detail::claimsCameraExposure),
};

// The kind that decodes the packet at `packet` (its id and size byte
// checked), or null for one we skip.
const PacketKind* findKind(const std::uint8_t* packet, std::size_t size, ByteOrder order) {
  for (const auto& k : kKinds)
    if (k.id == packet[0] && (!k.claims || k.claims(packet, size, order))) return &k;
  return nullptr;
}

// CIGI 3 assigns 1-35 to host packets and 101-117 to IG packets; anything
// else in those ranges is a packet we do not decode but whose direction we know.
std::optional<Direction> directionOfId(std::uint8_t id) {
  if (id >= 1 && id <= 35) return Direction::HostToIg;
  if (id >= 101 && id <= 117) return Direction::IgToHost;
  return std::nullopt;
}

std::string at(std::size_t index, std::size_t offset) {
  return "packet " + std::to_string(index) + " at byte " + std::to_string(offset) + ": ";
}

}  // namespace

DatagramWriter& DatagramWriter::add(const Packet& packet) {
  std::visit(
      [this](const auto& p) {
        using T = std::decay_t<decltype(p)>;
        PacketBuilder b(bytes_, order_, T::kId, T::kSize);
        Codec<T>::write(b, p);
      },
      packet);
  return *this;
}

const char* packetName(const Packet& packet) {
  return std::visit([](const auto& p) { return Codec<std::decay_t<decltype(p)>>::kName; }, packet);
}

std::uint8_t packetId(const Packet& packet) {
  return std::visit([](const auto& p) { return std::decay_t<decltype(p)>::kId; }, packet);
}

const char* packetIdName(std::uint8_t id) {
  // CIGI 3.3 host->IG ids 1-35 and IG->host ids 101-117 (cigi.md §1.6).
  static constexpr std::array<const char*, 35> kHost = {
      "IG Control", "Entity Control", "Conformal Clamped Entity Control", "Component Control",
      "Short Component Control", "Articulated Part Control", "Short Articulated Part Control", "Rate Control",
      "Celestial Sphere Control", "Atmosphere Control", "Environmental Region Control", "Weather Control",
      "Maritime Surface Conditions Control", "Wave Control", "Terrestrial Surface Conditions Control",
      "View Control", "Sensor Control", "Motion Tracker Control", "Earth Reference Model Definition",
      "Trajectory Definition", "View Definition", "Collision Detection Segment Definition",
      "Collision Detection Volume Definition", "HAT/HOT Request", "LOS Segment Request", "LOS Vector Request",
      "Position Request", "Environmental Conditions Request", "Symbol Surface Definition",
      "Symbol Text Definition", "Symbol Circle Definition", "Symbol Line Definition", "Symbol Clone",
      "Symbol Control", "Short Symbol Control"};
  static constexpr std::array<const char*, 17> kIg = {
      "Start of Frame", "HAT/HOT Response", "HAT/HOT Extended Response", "LOS Response", "LOS Extended Response",
      "Sensor Response", "Sensor Extended Response", "Position Response", "Weather Conditions Response",
      "Aerosol Concentration Response", "Maritime Surface Conditions Response",
      "Terrestrial Surface Conditions Response", "Collision Detection Segment Notification",
      "Collision Detection Volume Notification", "Animation Stop Notification", "Event Notification",
      "Image Generator Message"};
  if (id >= 1 && id <= kHost.size()) return kHost[id - 1];
  if (id >= 101 && id < 101 + kIg.size()) return kIg[id - 101];
  if (id >= 201) return "user-defined";
  return "unassigned";
}

Result<Datagram> decodeDatagram(std::span<const std::uint8_t> bytes) {
  if (bytes.size() < 24)
    return fail(ErrorCode::Malformed, "datagram of " + std::to_string(bytes.size()) +
                                          " bytes is shorter than a 24-byte IG Control / Start of Frame");
  Datagram out;
  if (bytes[0] == IgControl::kId) {
    out.direction = Direction::HostToIg;
  } else if (bytes[0] == StartOfFrame::kId) {
    out.direction = Direction::IgToHost;
  } else {
    return fail(ErrorCode::Malformed, at(0, 0) + "id " + std::to_string(bytes[0]) +
                                          " but a datagram must start with IG Control (1) or Start of Frame (101)");
  }
  if (bytes[1] != 24)
    return fail(ErrorCode::Malformed, at(0, 1) + "size " + std::to_string(bytes[1]) +
                                          ", CIGI 3.3 IG Control / Start of Frame are 24 bytes");
  if (bytes[2] != kMajorVersion)
    return fail(ErrorCode::Unsupported, at(0, 2) + "major version " + std::to_string(bytes[2]) + ", we speak 3");
  if (bytes[6] == 0x80 && bytes[7] == 0x00) {
    out.order = ByteOrder::Big;
  } else if (bytes[6] == 0x00 && bytes[7] == 0x80) {
    out.order = ByteOrder::Little;
  } else {
    return fail(ErrorCode::Malformed, at(0, 6) + "byte-swap magic " + std::to_string(bytes[6]) + "," +
                                          std::to_string(bytes[7]) + " is neither 80 00 nor 00 80");
  }

  std::size_t offset = 0;
  for (std::size_t index = 0; offset < bytes.size(); ++index) {
    if (bytes.size() - offset < 2)
      return fail(ErrorCode::Malformed, at(index, offset) + "1 byte left, no room for id and size");
    const std::uint8_t id = bytes[offset];
    const std::uint8_t size = bytes[offset + 1];
    if (size < 2)
      return fail(ErrorCode::Malformed,
                  at(index, offset + 1) + "size " + std::to_string(size) + " is below the 2-byte header");
    if (size > bytes.size() - offset)
      return fail(ErrorCode::Malformed, at(index, offset) + "id " + std::to_string(id) + " size " +
                                            std::to_string(size) + " runs past the " +
                                            std::to_string(bytes.size()) + "-byte datagram");
    const PacketKind* k = findKind(bytes.data() + offset, size, out.order);
    if (index > 0 && (id == IgControl::kId || id == StartOfFrame::kId))
      return fail(ErrorCode::Malformed,
                  at(index, offset) + "only the first packet may be IG Control / Start of Frame");
    if (const auto d = directionOfId(id); d && *d != out.direction)
      return fail(ErrorCode::Malformed, at(index, offset) + "id " + std::to_string(id) +
                                            (out.direction == Direction::HostToIg
                                                 ? " is an IG-to-host packet inside a host datagram"
                                                 : " is a host-to-IG packet inside an IG datagram"));
    if (!k) {
      out.skippedIds.push_back(id);
      offset += size;
      continue;
    }
    if (size != k->size)
      return fail(ErrorCode::Malformed, "packet " + std::to_string(index) + " (" + k->name + ") at byte " +
                                            std::to_string(offset + 1) + ": size " + std::to_string(size) +
                                            ", must be " + std::to_string(k->size));
    PacketReader r(bytes.data() + offset, out.order, index, offset, k->name);
    auto packet = k->read(r);
    if (!packet) return tl::unexpected(packet.error());
    out.packets.push_back(std::move(*packet));
    offset += size;
  }
  return out;
}

}  // namespace sky::cigi
