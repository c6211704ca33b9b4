// Datagrams a renderer's input dropped, counted by reason. Written by the io
// thread, read by the render loop and the exit summary: atomic counters.
#pragma once

#include <array>
#include <atomic>
#include <cstddef>
#include <cstdint>
#include <string>

#include "sky/core/result.hpp"

namespace sky::app {

enum class DropReason : std::size_t {
  Malformed,      // does not parse: its size, a CIGI size byte of 0 or 1 or past the datagram's end
  Unsupported,    // another protocol version
  OutOfRange,     // a field non-finite or outside its range
  NotFromHost,    // CIGI: an IG's datagram (Start of Frame first), not a host's
  ForeignSender,  // CIGI: from a sender other than the host the port is bound to
  Unusable,       // FlightGear, ForeFlight: a pose the smoother cannot take
  Count_,
};

inline const char* toString(DropReason r) {
  constexpr std::array<const char*, static_cast<std::size_t>(DropReason::Count_)> kNames = {
      "malformed", "unsupported version", "out of range", "not from a host", "foreign sender", "unusable pose"};
  return kNames[static_cast<std::size_t>(r)];
}

// The reason a decoder's error stands for.
inline DropReason dropReasonOf(ErrorCode code) {
  switch (code) {
    case ErrorCode::Unsupported: return DropReason::Unsupported;
    case ErrorCode::InvalidArgument: return DropReason::OutOfRange;
    default: return DropReason::Malformed;
  }
}

// The kind of a drop that is logged once: its reason and the decoder's
// detail without the values ("packet 1 (Entity Control) at byte 48: latitude
// nan outside [-90, 90]" and "... latitude 1e+30 ..." are one kind), so a
// sender varying its values cannot flood the log. A key, never shown.
inline std::string dropKind(DropReason reason, const std::string& detail) {
  std::string kind = std::string(toString(reason)) + ": ";
  for (std::size_t i = 0; i < detail.size() && kind.size() < 120; ++i) {
    const char c = detail[i];
    if ((c >= '0' && c <= '9') || c == '.' || c == '+' || c == '-') continue;
    if (detail.compare(i, 3, "nan") == 0 || detail.compare(i, 3, "inf") == 0) {
      i += 2;
      continue;
    }
    // The exponent mark of a number ("1e+30", digits and sign already gone).
    if (c == 'e' && i > 0 && detail[i - 1] >= '0' && detail[i - 1] <= '9') continue;
    kind += c;
  }
  return kind;
}

class DropCounts {
 public:
  void add(DropReason r) { counts_[static_cast<std::size_t>(r)].fetch_add(1, std::memory_order_relaxed); }
  std::uint64_t of(DropReason r) const { return counts_[static_cast<std::size_t>(r)].load(std::memory_order_relaxed); }
  std::uint64_t total() const {
    std::uint64_t n = 0;
    for (const auto& c : counts_) n += c.load(std::memory_order_relaxed);
    return n;
  }
  // "malformed 3, out of range 1" (reasons with a count only); "none" when empty.
  std::string summary() const {
    std::string out;
    for (std::size_t i = 0; i < counts_.size(); ++i) {
      const std::uint64_t n = counts_[i].load(std::memory_order_relaxed);
      if (n == 0) continue;
      if (!out.empty()) out += ", ";
      out += std::string(toString(static_cast<DropReason>(i))) + " " + std::to_string(n);
    }
    return out.empty() ? "none" : out;
  }

 private:
  std::array<std::atomic<std::uint64_t>, static_cast<std::size_t>(DropReason::Count_)> counts_{};
};

// Packets a host sent that a channel accepts and does not use (Component
// Control, Rate Control, articulated parts, entities other than the
// ownship, user-defined packets, ...), counted by packet id: never an error.
class IgnoredPackets {
 public:
  void add(std::uint8_t id) { counts_[id].fetch_add(1, std::memory_order_relaxed); }
  std::uint64_t of(std::uint8_t id) const { return counts_[id].load(std::memory_order_relaxed); }
  std::uint64_t total() const {
    std::uint64_t n = 0;
    for (const auto& c : counts_) n += c.load(std::memory_order_relaxed);
    return n;
  }

 private:
  std::array<std::atomic<std::uint64_t>, 256> counts_{};
};

}  // namespace sky::app
