// libFuzzer target: the weather stream's frame decoder and message decoder
// (FlatBuffers verifier + range checks) on arbitrary bytes, fed in two parts
// to exercise reassembly. What decodes must be in range: a CameraReport (the
// one message a renderer sends besides Subscribe) is checked field by field,
// and re-encoding any decoded report must decode to the same values.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <variant>

#include "sky/stream/framing.hpp"
#include "sky/stream/messages.hpp"

namespace {

void check(const sky::Result<sky::stream::Message>& m) {
  if (!m) return;
  const auto* r = std::get_if<sky::stream::CameraReport>(&*m);
  if (!r) return;
  auto in = [](double v, double lo, double hi) { return std::isfinite(v) && v >= lo && v <= hi; };
  if (r->channel.size() > sky::stream::kMaxChannelBytes || !in(r->lat_deg, -90, 90) || !in(r->lon_deg, -180, 180) ||
      !in(r->alt_m, -1000, 1e6) || !in(r->heading_deg, 0, 360) || !in(r->pitch_deg, -90, 90) ||
      !in(r->roll_deg, -180, 180) || !std::isfinite(r->weatherClock_s))
    std::abort();
  for (char c : r->channel)
    if (static_cast<unsigned char>(c) < 0x20 || c == 0x7f) std::abort();
  auto again = sky::stream::decodeMessage(sky::stream::encodeMessage(*r));
  if (!again) std::abort();
  const auto& r2 = std::get<sky::stream::CameraReport>(*again);
  if (r2.channel != r->channel || r2.lat_deg != r->lat_deg || r2.lon_deg != r->lon_deg || r2.alt_m != r->alt_m ||
      r2.heading_deg != r->heading_deg || r2.frame != r->frame || r2.weatherVersion != r->weatherVersion)
    std::abort();
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  // Raw payload straight into the message decoder.
  check(sky::stream::decodeMessage(std::span(data, size)));
  // The same bytes as a stream of frames, split at a point chosen by the input.
  sky::stream::FrameDecoder decoder;
  const std::size_t split = size > 0 ? data[0] % (size + 1) : 0;
  decoder.append(std::span(data, split));
  for (int part = 0; part < 2; ++part) {
    while (true) {
      auto frame = decoder.next();
      if (!frame || !*frame) break;
      check(sky::stream::decodeMessage(**frame));
    }
    if (part == 0) decoder.append(std::span(data + split, size - split));
  }
  return 0;
}
