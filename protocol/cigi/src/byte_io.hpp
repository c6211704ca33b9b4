// Private to the CIGI codec: scalar access in a chosen byte order inside one
// packet, and the range checks that name packet, byte offset and field.
#pragma once

#include <bit>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <optional>
#include <string>
#include <vector>

#include "sky/cigi/packets.hpp"
#include "sky/core/result.hpp"

namespace sky::cigi::detail {

inline bool needsSwap(ByteOrder order) {
  return (std::endian::native == std::endian::little) != (order == ByteOrder::Little);
}

// Writes one fixed-size packet at the end of `out`; reserved bytes stay 0.
class PacketBuilder {
 public:
  PacketBuilder(std::vector<std::uint8_t>& out, ByteOrder order, std::uint8_t id, std::uint8_t size)
      : out_(out), base_(out.size()), swap_(needsSwap(order)) {
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
    for (std::size_t i = 0; i < n; ++i) out_[base_ + off + i] = swap_ ? tmp[n - 1 - i] : tmp[i];
  }
  std::vector<std::uint8_t>& out_;
  std::size_t base_;
  bool swap_;
};

// Reads one packet whose size the walker has checked, and collects the first
// range violation with its packet index, absolute byte offset and field name.
class PacketReader {
 public:
  PacketReader(const std::uint8_t* p, ByteOrder order, std::size_t index, std::size_t offset, const char* name)
      : p_(p), swap_(needsSwap(order)), index_(index), offset_(offset), name_(name) {}

  std::uint8_t u8(std::size_t off) const { return p_[off]; }
  std::uint16_t u16(std::size_t off) const { return get<std::uint16_t>(off); }
  std::uint32_t u32(std::size_t off) const { return get<std::uint32_t>(off); }
  float f32(std::size_t off) const { return get<float>(off); }
  double f64(std::size_t off) const { return get<double>(off); }

  // Records a violation unless lo <= v <= hi and v is finite.
  void range(std::size_t off, const char* field, double v, double lo, double hi) {
    if (error_ || (std::isfinite(v) && v >= lo && v <= hi)) return;
    error_ = where(off) + field + " " + number(v) + " outside [" + number(lo) + ", " + number(hi) + "]";
  }
  void finite(std::size_t off, const char* field, double v) {
    if (!error_ && !std::isfinite(v)) error_ = where(off) + field + " is not finite";
  }
  void invalid(std::size_t off, const std::string& what) {
    if (!error_) error_ = where(off) + what;
  }

  template <class T>
  Result<T> result(T value) const {
    if (error_) return fail(ErrorCode::InvalidArgument, *error_);
    return value;
  }

  std::string where(std::size_t off) const {
    return "packet " + std::to_string(index_) + " (" + name_ + ") at byte " + std::to_string(offset_ + off) + ": ";
  }

 private:
  static std::string number(double v) {
    char buf[32];
    std::snprintf(buf, sizeof buf, "%g", v);
    return buf;
  }
  template <class T>
  T get(std::size_t off) const {
    std::uint8_t tmp[sizeof(T)];
    for (std::size_t i = 0; i < sizeof(T); ++i) tmp[i] = swap_ ? p_[off + sizeof(T) - 1 - i] : p_[off + i];
    T v;
    std::memcpy(&v, tmp, sizeof(T));
    return v;
  }
  const std::uint8_t* p_;
  bool swap_;
  std::size_t index_, offset_;
  const char* name_;
  std::optional<std::string> error_;
};

inline std::uint8_t bit(bool b, int shift) { return static_cast<std::uint8_t>(b ? 1u << shift : 0u); }
inline bool isSet(std::uint8_t byte, int shift) { return (byte >> shift) & 1u; }

}  // namespace sky::cigi::detail
