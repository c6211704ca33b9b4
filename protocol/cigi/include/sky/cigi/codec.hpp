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

using Packet = std::variant<IgControl, EntityControl, StartOfFrame>;

// Appends packets to a datagram under construction, in one byte order.
class DatagramWriter {
 public:
  explicit DatagramWriter(ByteOrder order = ByteOrder::Big) : order_(order) {}
  DatagramWriter& add(const IgControl& p);
  DatagramWriter& add(const EntityControl& p);
  DatagramWriter& add(const StartOfFrame& p);
  const std::vector<std::uint8_t>& bytes() const { return bytes_; }

 private:
  ByteOrder order_;
  std::vector<std::uint8_t> bytes_;
};

struct Datagram {
  ByteOrder order = ByteOrder::Big;
  std::vector<Packet> packets;  // the packets we decode, in datagram order
  std::size_t skippedPackets = 0;  // valid-sized packets of ids we do not decode
};

// Decodes a whole datagram, or rejects it with the packet index, byte offset
// and reason. Never reads outside `bytes`.
Result<Datagram> decodeDatagram(std::span<const std::uint8_t> bytes);

}  // namespace sky::cigi
