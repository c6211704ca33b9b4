// CIGI 3.3 datagram encoding and decoding, both byte orders. A datagram is a
// sequence of packets; the first is IG Control (host->IG) or Start of Frame
// (IG->host) and carries the byte-swap magic that tells the sender's order.
#pragma once

#include <cstddef>
#include <cstdint>
#include <span>
#include <variant>
#include <vector>

#include "sky/cigi/packets.hpp"
#include "sky/core/result.hpp"

namespace sky::cigi {

using Packet = std::variant<IgControl, EntityControl, CelestialSphereControl, AtmosphereControl,
                            EnvironmentalRegionControl, WeatherControl, ViewControl, ViewDefinition,
                            EnvironmentalConditionsRequest, StartOfFrame, WeatherConditionsResponse,
                            AerosolConcentrationResponse, CameraExposureControl>;

// Appends packets to a datagram under construction, in one byte order. The
// caller puts IG Control (or Start of Frame) first.
class DatagramWriter {
 public:
  explicit DatagramWriter(ByteOrder order = ByteOrder::Big) : order_(order) {}
  DatagramWriter& add(const Packet& packet);
  const std::vector<std::uint8_t>& bytes() const { return bytes_; }

 private:
  ByteOrder order_;
  std::vector<std::uint8_t> bytes_;
};

enum class Direction { HostToIg, IgToHost };

struct Datagram {
  ByteOrder order = ByteOrder::Big;
  Direction direction = Direction::HostToIg;
  std::vector<Packet> packets;     // the packets we decode, in datagram order
  // Ids of the well-sized packets we do not decode (Component Control of
  // components other than ours, Rate Control, user-defined 201-255, ...), in
  // datagram order: skipped by their size byte.
  std::vector<std::uint8_t> skippedIds;
};

// Decodes a whole datagram, or rejects it with the packet index, byte offset
// and reason: a wrong first packet, a size byte that is wrong for its id or
// runs past the datagram, a packet of the other direction, or a field out of
// range. Never reads outside `bytes`.
Result<Datagram> decodeDatagram(std::span<const std::uint8_t> bytes);

// Packet name for logs ("Weather Control").
const char* packetName(const Packet& packet);
// The CIGI 3.3 name of a packet id (cigi.md §1.6), decoded or not
// ("Component Control"); "user-defined" for 201-255, "unassigned" otherwise.
const char* packetIdName(std::uint8_t id);
// The id of a decoded packet.
std::uint8_t packetId(const Packet& packet);

}  // namespace sky::cigi
