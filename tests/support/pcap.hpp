// The UDP payloads of a classic pcap (little-endian, microsecond stamps,
// Ethernet link type, IPv4), with their capture times: how the tests replay
// the real FlightGear captures in tests/data/flightgear/. A file of another
// kind, or a truncated record, ends the list and fails the test.
#pragma once

#include <cstdint>
#include <cstring>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

#include <gtest/gtest.h>

namespace sky::test {

struct CapturedDatagram {
  double t_s = 0;  // capture time, s after the first packet
  std::vector<std::uint8_t> payload;
};

inline std::vector<CapturedDatagram> readPcap(const std::string& path) {
  std::ifstream f(path, std::ios::binary);
  const std::vector<std::uint8_t> d((std::istreambuf_iterator<char>(f)), std::istreambuf_iterator<char>());
  auto u32 = [&](std::size_t at) {
    std::uint32_t v;
    std::memcpy(&v, &d[at], 4);
    return v;
  };
  std::vector<CapturedDatagram> out;
  if (d.size() < 24 || u32(0) != 0xa1b2c3d4u || u32(20) != 1) {
    ADD_FAILURE() << path << ": not a little-endian microsecond Ethernet pcap";
    return out;
  }
  double first = -1;
  for (std::size_t at = 24; at + 16 <= d.size();) {
    const double t = u32(at) + u32(at + 4) * 1e-6;
    const std::size_t caplen = u32(at + 8);
    const std::size_t frame = at + 16;
    at = frame + caplen;
    if (at > d.size()) {
      ADD_FAILURE() << path << ": a truncated record";
      break;
    }
    const std::size_t ip = frame + 14;  // Ethernet II header
    if (caplen < 14 + 20 + 8 || d[frame + 12] != 0x08 || d[frame + 13] != 0x00 || d[ip + 9] != 17) continue;
    const std::size_t udp = ip + (d[ip] & 0x0f) * 4u;
    const std::size_t udpLen = (std::size_t{d[udp + 4]} << 8) | d[udp + 5];
    if (udp + udpLen > at || udpLen < 8) {
      ADD_FAILURE() << path << ": a UDP length past its record";
      break;
    }
    if (first < 0) first = t;
    out.push_back({t - first, std::vector<std::uint8_t>(d.begin() + udp + 8, d.begin() + udp + udpLen)});
  }
  return out;
}

}  // namespace sky::test
