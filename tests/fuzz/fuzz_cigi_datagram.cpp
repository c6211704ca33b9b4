// libFuzzer target: the CIGI 3.3 datagram reader must reject or decode any
// bytes without reading outside them; a decoded datagram re-encodes to a
// datagram that decodes to the same packets.
#include <cstddef>
#include <cstdint>
#include <cstdlib>

#include "sky/cigi/codec.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  auto d = sky::cigi::decodeDatagram(std::span(data, size));
  if (!d) return 0;
  sky::cigi::DatagramWriter w(d->order);
  for (const auto& p : d->packets) w.add(p);
  auto again = sky::cigi::decodeDatagram(w.bytes());
  if (!again || again->packets != d->packets) std::abort();
  return 0;
}
