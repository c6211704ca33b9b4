// Length-prefixed framing (see framing.hpp).
#include "sky/stream/framing.hpp"

#include <string>

namespace sky::stream {

std::vector<std::uint8_t> encodeFrame(std::span<const std::uint8_t> payload) {
  std::vector<std::uint8_t> out;
  out.reserve(kFrameHeaderBytes + payload.size());
  const auto n = static_cast<std::uint32_t>(payload.size());
  out.push_back(static_cast<std::uint8_t>(n >> 24));
  out.push_back(static_cast<std::uint8_t>(n >> 16));
  out.push_back(static_cast<std::uint8_t>(n >> 8));
  out.push_back(static_cast<std::uint8_t>(n));
  out.insert(out.end(), payload.begin(), payload.end());
  return out;
}

void FrameDecoder::append(std::span<const std::uint8_t> bytes) {
  if (failed_) return;
  // Drop what was consumed before growing, so the buffer stays bounded by one
  // frame plus what arrived since.
  if (consumed_ > 0 && consumed_ >= buffer_.size() / 2) {
    buffer_.erase(buffer_.begin(), buffer_.begin() + static_cast<std::ptrdiff_t>(consumed_));
    consumed_ = 0;
  }
  buffer_.insert(buffer_.end(), bytes.begin(), bytes.end());
}

Result<std::optional<std::vector<std::uint8_t>>> FrameDecoder::next() {
  if (failed_) return fail(ErrorCode::Malformed, "frame decoder already failed");
  const std::size_t available = buffer_.size() - consumed_;
  if (available < kFrameHeaderBytes) return std::optional<std::vector<std::uint8_t>>{};
  const std::uint8_t* h = buffer_.data() + consumed_;
  const std::size_t n = (std::size_t{h[0]} << 24) | (std::size_t{h[1]} << 16) |
                        (std::size_t{h[2]} << 8) | std::size_t{h[3]};
  if (n > maxFrameBytes_) {
    failed_ = true;
    return fail(ErrorCode::TooLarge, "frame announces " + std::to_string(n) +
                                         " bytes, cap is " + std::to_string(maxFrameBytes_));
  }
  if (available < kFrameHeaderBytes + n) return std::optional<std::vector<std::uint8_t>>{};
  std::vector<std::uint8_t> payload(h + kFrameHeaderBytes, h + kFrameHeaderBytes + n);
  consumed_ += kFrameHeaderBytes + n;
  return std::optional<std::vector<std::uint8_t>>(std::move(payload));
}

}  // namespace sky::stream
