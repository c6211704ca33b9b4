// libFuzzer target: the weather stream's frame decoder and message decoder
// (FlatBuffers verifier + range checks) on arbitrary bytes, fed in two parts
// to exercise reassembly.
#include <cstddef>
#include <cstdint>

#include "sky/stream/framing.hpp"
#include "sky/stream/messages.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  // Raw payload straight into the message decoder.
  (void)sky::stream::decodeMessage(std::span(data, size));
  // The same bytes as a stream of frames, split at a point chosen by the input.
  sky::stream::FrameDecoder decoder;
  const std::size_t split = size > 0 ? data[0] % (size + 1) : 0;
  decoder.append(std::span(data, split));
  for (int part = 0; part < 2; ++part) {
    while (true) {
      auto frame = decoder.next();
      if (!frame || !*frame) break;
      (void)sky::stream::decodeMessage(**frame);
    }
    if (part == 0) decoder.append(std::span(data + split, size - split));
  }
  return 0;
}
