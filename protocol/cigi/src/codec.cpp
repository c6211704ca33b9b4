// CIGI 3.3 codec: field-by-field packing in the sender's byte order, and a
// datagram walker that checks sizes, ids and ranges before use.
#include "sky/cigi/codec.hpp"

#include <bit>
#include <cmath>
#include <cstring>
#include <string>

namespace sky::cigi {

namespace {

constexpr std::uint16_t kByteSwapMagic = 0x8000;

// Writes scalars in a chosen byte order into a fixed-size packet buffer.
class PacketBuilder {
 public:
  PacketBuilder(std::vector<std::uint8_t>& out, ByteOrder order, std::uint8_t id, std::uint8_t size)
      : out_(out), base_(out.size()), order_(order) {
    out_.resize(base_ + size, 0);
    out_[base_] = id;
    out_[base_ + 1] = size;
  }
  void u8(std::size_t off, std::uint8_t v) { out_[base_ + off] = v; }
  void u16(std::size_t off, std::uint16_t v) { put(off, &v, 2); }
  void u32(std::size_t off, std::uint32_t v) { put(off, &v, 4); }
  void f32(std::size_t off, float v) { put(off, &v, 4); }
  void f64(std::size_t off, double v) { put(off, &v, 8); }

 private:
  void put(std::size_t off, const void* v, std::size_t n) {
    std::uint8_t tmp[8];
    std::memcpy(tmp, v, n);
    const bool hostLittle = std::endian::native == std::endian::little;
    const bool wantLittle = order_ == ByteOrder::Little;
    for (std::size_t i = 0; i < n; ++i)
      out_[base_ + off + i] = hostLittle == wantLittle ? tmp[i] : tmp[n - 1 - i];
  }
  std::vector<std::uint8_t>& out_;
  std::size_t base_;
  ByteOrder order_;
};

// Reads scalars of one packet; the walker has checked the packet fits.
class PacketReader {
 public:
  PacketReader(const std::uint8_t* p, ByteOrder order) : p_(p), order_(order) {}
  std::uint8_t u8(std::size_t off) const { return p_[off]; }
  std::uint16_t u16(std::size_t off) const { return get<std::uint16_t>(off); }
  std::uint32_t u32(std::size_t off) const { return get<std::uint32_t>(off); }
  float f32(std::size_t off) const { return get<float>(off); }
  double f64(std::size_t off) const { return get<double>(off); }

 private:
  template <class T>
  T get(std::size_t off) const {
    std::uint8_t tmp[sizeof(T)];
    const bool hostLittle = std::endian::native == std::endian::little;
    const bool isLittle = order_ == ByteOrder::Little;
    for (std::size_t i = 0; i < sizeof(T); ++i)
      tmp[i] = hostLittle == isLittle ? p_[off + i] : p_[off + sizeof(T) - 1 - i];
    T v;
    std::memcpy(&v, tmp, sizeof(T));
    return v;
  }
  const std::uint8_t* p_;
  ByteOrder order_;
};

std::string where(std::size_t index, std::size_t offset, const char* packet) {
  return std::string("packet ") + std::to_string(index) + " (" + packet + ") at byte " +
         std::to_string(offset) + ": ";
}

Result<void> rangeCheck(std::size_t index, std::size_t offset, const char* packet,
                        const char* field, double v, double lo, double hi) {
  if (std::isfinite(v) && v >= lo && v <= hi) return {};
  return fail(ErrorCode::InvalidArgument, where(index, offset, packet) + field + " " +
                                              std::to_string(v) + " outside [" +
                                              std::to_string(lo) + ", " + std::to_string(hi) + "]");
}

IgControl readIgControl(const PacketReader& r) {
  IgControl p;
  p.databaseNumber = static_cast<std::int8_t>(r.u8(3));
  const std::uint8_t flags = r.u8(4);
  p.mode = static_cast<IgMode>(flags & 0x03);
  p.timestampValid = flags & 0x04;
  p.extrapolationEnable = flags & 0x08;
  p.hostFrame = r.u32(8);
  p.timestamp_10us = r.u32(12);
  p.lastIgFrame = r.u32(16);
  return p;
}

StartOfFrame readStartOfFrame(const PacketReader& r) {
  StartOfFrame p;
  p.databaseNumber = static_cast<std::int8_t>(r.u8(3));
  p.igStatus = r.u8(4);
  const std::uint8_t flags = r.u8(5);
  p.mode = static_cast<IgMode>(flags & 0x03);
  p.timestampValid = flags & 0x04;
  p.earthReferenceModelHostDefined = flags & 0x08;
  p.igFrame = r.u32(8);
  p.timestamp_10us = r.u32(12);
  p.lastHostFrame = r.u32(16);
  return p;
}

Result<EntityControl> readEntityControl(const PacketReader& r, std::size_t index, std::size_t offset) {
  EntityControl p;
  p.entityId = r.u16(2);
  const std::uint8_t b4 = r.u8(4);
  const std::uint8_t state = b4 & 0x03;
  if (state > 2)
    return fail(ErrorCode::InvalidArgument,
                where(index, offset, "Entity Control") + "entity state 3 is undefined");
  p.state = static_cast<EntityState>(state);
  p.attached = b4 & 0x04;
  p.collisionDetection = b4 & 0x08;
  p.inheritAlpha = b4 & 0x10;
  p.groundClamp = (b4 >> 5) & 0x03;
  const std::uint8_t b5 = r.u8(5);
  p.animationFlags = b5 & 0x0F;
  p.linearExtrapolation = b5 & 0x10;
  p.alpha = r.u8(6);
  p.entityType = r.u16(8);
  p.parentId = r.u16(10);
  p.roll_deg = r.f32(12);
  p.pitch_deg = r.f32(16);
  p.yaw_deg = r.f32(20);
  p.lat_deg = r.f64(24);
  p.lon_deg = r.f64(32);
  p.alt_m = r.f64(40);
  const char* name = "Entity Control";
  Result<void> ok;
  if (!(ok = rangeCheck(index, offset, name, "roll", p.roll_deg, -180, 180)) ||
      !(ok = rangeCheck(index, offset, name, "pitch", p.pitch_deg, -90, 90)) ||
      !(ok = rangeCheck(index, offset, name, "yaw", p.yaw_deg, -360, 360)))
    return tl::unexpected(ok.error());
  if (!p.attached) {
    if (!(ok = rangeCheck(index, offset, name, "latitude", p.lat_deg, -90, 90)) ||
        !(ok = rangeCheck(index, offset, name, "longitude", p.lon_deg, -180, 180)) ||
        !(ok = rangeCheck(index, offset, name, "altitude", p.alt_m, -12000, 1.0e7)))
      return tl::unexpected(ok.error());
  } else if (!std::isfinite(p.lat_deg) || !std::isfinite(p.lon_deg) || !std::isfinite(p.alt_m)) {
    return fail(ErrorCode::InvalidArgument,
                where(index, offset, name) + "attached offset is not finite");
  }
  return p;
}

}  // namespace

DatagramWriter& DatagramWriter::add(const IgControl& p) {
  PacketBuilder b(bytes_, order_, IgControl::kId, IgControl::kSize);
  b.u8(2, kMajorVersion);
  b.u8(3, static_cast<std::uint8_t>(p.databaseNumber));
  b.u8(4, static_cast<std::uint8_t>((static_cast<std::uint8_t>(p.mode) & 0x03) |
                                    (p.timestampValid ? 0x04 : 0) |
                                    (p.extrapolationEnable ? 0x08 : 0) | (kMinorVersion << 4)));
  b.u16(6, kByteSwapMagic);
  b.u32(8, p.hostFrame);
  b.u32(12, p.timestamp_10us);
  b.u32(16, p.lastIgFrame);
  return *this;
}

DatagramWriter& DatagramWriter::add(const EntityControl& p) {
  PacketBuilder b(bytes_, order_, EntityControl::kId, EntityControl::kSize);
  b.u16(2, p.entityId);
  b.u8(4, static_cast<std::uint8_t>((static_cast<std::uint8_t>(p.state) & 0x03) |
                                    (p.attached ? 0x04 : 0) | (p.collisionDetection ? 0x08 : 0) |
                                    (p.inheritAlpha ? 0x10 : 0) | ((p.groundClamp & 0x03) << 5)));
  b.u8(5, static_cast<std::uint8_t>((p.animationFlags & 0x0F) | (p.linearExtrapolation ? 0x10 : 0)));
  b.u8(6, p.alpha);
  b.u16(8, p.entityType);
  b.u16(10, p.parentId);
  b.f32(12, p.roll_deg);
  b.f32(16, p.pitch_deg);
  b.f32(20, p.yaw_deg);
  b.f64(24, p.lat_deg);
  b.f64(32, p.lon_deg);
  b.f64(40, p.alt_m);
  return *this;
}

DatagramWriter& DatagramWriter::add(const StartOfFrame& p) {
  PacketBuilder b(bytes_, order_, StartOfFrame::kId, StartOfFrame::kSize);
  b.u8(2, kMajorVersion);
  b.u8(3, static_cast<std::uint8_t>(p.databaseNumber));
  b.u8(4, p.igStatus);
  b.u8(5, static_cast<std::uint8_t>((static_cast<std::uint8_t>(p.mode) & 0x03) |
                                    (p.timestampValid ? 0x04 : 0) |
                                    (p.earthReferenceModelHostDefined ? 0x08 : 0) |
                                    (kMinorVersion << 4)));
  b.u16(6, kByteSwapMagic);
  b.u32(8, p.igFrame);
  b.u32(12, p.timestamp_10us);
  b.u32(16, p.lastHostFrame);
  return *this;
}

Result<Datagram> decodeDatagram(std::span<const std::uint8_t> bytes) {
  if (bytes.size() < 24)
    return fail(ErrorCode::Malformed, "datagram of " + std::to_string(bytes.size()) +
                                          " bytes is shorter than a 24-byte IG Control / Start of Frame");
  const std::uint8_t firstId = bytes[0];
  if (firstId != IgControl::kId && firstId != StartOfFrame::kId)
    return fail(ErrorCode::Malformed, "packet 0 at byte 0: id " + std::to_string(firstId) +
                                          " but a datagram must start with IG Control (1) or Start of Frame (101)");
  if (bytes[1] != 24)
    return fail(ErrorCode::Malformed, "packet 0 at byte 1: size " + std::to_string(bytes[1]) +
                                          ", CIGI 3.3 IG Control / Start of Frame are 24 bytes");
  if (bytes[2] != kMajorVersion)
    return fail(ErrorCode::Unsupported, "packet 0 at byte 2: major version " +
                                            std::to_string(bytes[2]) + ", we speak 3");
  Datagram out;
  if (bytes[6] == 0x80 && bytes[7] == 0x00) {
    out.order = ByteOrder::Big;
  } else if (bytes[6] == 0x00 && bytes[7] == 0x80) {
    out.order = ByteOrder::Little;
  } else {
    return fail(ErrorCode::Malformed, "packet 0 at byte 6: byte-swap magic " +
                                          std::to_string(bytes[6]) + "," + std::to_string(bytes[7]) +
                                          " is neither 80 00 nor 00 80");
  }

  std::size_t offset = 0;
  for (std::size_t index = 0; offset < bytes.size(); ++index) {
    if (bytes.size() - offset < 2)
      return fail(ErrorCode::Malformed, "packet " + std::to_string(index) + " at byte " +
                                            std::to_string(offset) + ": 1 byte left, no room for id and size");
    const std::uint8_t id = bytes[offset];
    const std::uint8_t size = bytes[offset + 1];
    if (size < 2)
      return fail(ErrorCode::Malformed, "packet " + std::to_string(index) + " at byte " +
                                            std::to_string(offset + 1) + ": size " +
                                            std::to_string(size) + " is below the 2-byte header");
    if (size > bytes.size() - offset)
      return fail(ErrorCode::Malformed, "packet " + std::to_string(index) + " (id " +
                                            std::to_string(id) + ") at byte " + std::to_string(offset) +
                                            ": size " + std::to_string(size) + " runs past the " +
                                            std::to_string(bytes.size()) + "-byte datagram");
    const PacketReader r(bytes.data() + offset, out.order);
    auto sizeMust = [&](std::uint8_t want, const char* name) -> Result<void> {
      if (size == want) return {};
      return fail(ErrorCode::Malformed, where(index, offset + 1, name) + "size " +
                                            std::to_string(size) + ", must be " + std::to_string(want));
    };
    if (index > 0 && (id == IgControl::kId || id == StartOfFrame::kId))
      return fail(ErrorCode::Malformed, where(index, offset, id == 1 ? "IG Control" : "Start of Frame") +
                                            "only the first packet may be IG Control / Start of Frame");
    switch (id) {
      case IgControl::kId: {
        if (auto ok = sizeMust(IgControl::kSize, "IG Control"); !ok) return tl::unexpected(ok.error());
        IgControl p = readIgControl(r);
        if (p.mode == IgMode::OfflineMaintenance)
          return fail(ErrorCode::InvalidArgument,
                      where(index, offset + 4, "IG Control") + "IG mode 3 is not valid from a host");
        out.packets.emplace_back(p);
        break;
      }
      case StartOfFrame::kId: {
        if (auto ok = sizeMust(StartOfFrame::kSize, "Start of Frame"); !ok) return tl::unexpected(ok.error());
        out.packets.emplace_back(readStartOfFrame(r));
        break;
      }
      case EntityControl::kId: {
        if (auto ok = sizeMust(EntityControl::kSize, "Entity Control"); !ok) return tl::unexpected(ok.error());
        auto p = readEntityControl(r, index, offset);
        if (!p) return tl::unexpected(p.error());
        out.packets.emplace_back(*p);
        break;
      }
      default:
        ++out.skippedPackets;
        break;
    }
    offset += size;
  }
  return out;
}

}  // namespace sky::cigi
