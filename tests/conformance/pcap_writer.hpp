// Writes UDP datagrams into a classic pcap file (LINKTYPE_RAW, IPv4 on
// 127.0.0.1), so tshark can decode what our encoder produced.
#pragma once

#include <cstdint>
#include <cstdio>
#include <string>
#include <vector>

namespace sky::test {

class PcapWriter {
 public:
  explicit PcapWriter(const std::string& path) : f_(std::fopen(path.c_str(), "wb")) {
    // Global header: magic, v2.4, UTC offset 0, accuracy 0, snaplen, LINKTYPE_RAW (101).
    put32(0xa1b2c3d4);
    put16(2);
    put16(4);
    put32(0);
    put32(0);
    put32(65535);
    put32(101);
  }
  ~PcapWriter() {
    if (f_) std::fclose(f_);
  }
  bool ok() const { return f_ != nullptr; }

  void add(const std::vector<std::uint8_t>& payload, std::uint16_t srcPort, std::uint16_t dstPort) {
    std::vector<std::uint8_t> p;
    const std::size_t total = 20 + 8 + payload.size();
    // IPv4 header, no options, UDP, 127.0.0.1 -> 127.0.0.1.
    const std::uint8_t ip[20] = {0x45, 0, static_cast<std::uint8_t>(total >> 8), static_cast<std::uint8_t>(total),
                                 0, 0, 0x40, 0, 64, 17, 0, 0, 127, 0, 0, 1, 127, 0, 0, 1};
    p.assign(ip, ip + 20);
    std::uint32_t sum = 0;
    for (int i = 0; i < 20; i += 2) sum += (p[i] << 8) | p[i + 1];
    while (sum >> 16) sum = (sum & 0xffff) + (sum >> 16);
    p[10] = static_cast<std::uint8_t>(~sum >> 8);
    p[11] = static_cast<std::uint8_t>(~sum);
    const std::size_t udpLen = 8 + payload.size();
    // UDP header; checksum 0 = not computed (allowed for IPv4).
    const std::uint8_t udp[8] = {static_cast<std::uint8_t>(srcPort >> 8), static_cast<std::uint8_t>(srcPort),
                                 static_cast<std::uint8_t>(dstPort >> 8), static_cast<std::uint8_t>(dstPort),
                                 static_cast<std::uint8_t>(udpLen >> 8), static_cast<std::uint8_t>(udpLen), 0, 0};
    p.insert(p.end(), udp, udp + 8);
    p.insert(p.end(), payload.begin(), payload.end());
    put32(seconds_++);
    put32(0);
    put32(static_cast<std::uint32_t>(p.size()));
    put32(static_cast<std::uint32_t>(p.size()));
    std::fwrite(p.data(), 1, p.size(), f_);
  }

 private:
  void put16(std::uint16_t v) { std::fwrite(&v, 2, 1, f_); }
  void put32(std::uint32_t v) { std::fwrite(&v, 4, 1, f_); }
  std::FILE* f_;
  std::uint32_t seconds_ = 1;
};

}  // namespace sky::test
