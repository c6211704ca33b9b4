// Length-prefixed frames on a byte stream (TCP): a 4-byte big-endian payload
// length, then the payload. Payloads are capped (kMaxFrameBytes for what a
// server sends, kMaxSubscriberFrameBytes for what a subscriber sends); a
// larger announced length is a protocol error (the connection must be dropped).
#pragma once

#include <cstddef>
#include <cstdint>
#include <optional>
#include <span>
#include <vector>

#include "sky/core/result.hpp"

namespace sky::stream {

inline constexpr std::size_t kFrameHeaderBytes = 4;
// Cap on one frame: a snapshot of ~20k tiles (24 bytes each) fits with room.
inline constexpr std::size_t kMaxFrameBytes = 4u << 20;
// Cap on one frame a subscriber sends (the server's read side). A subscriber
// sends only Subscribe (~100 bytes), CameraReport (~150 bytes plus a channel
// name of at most 64), Heartbeat and Error: 4 KiB leaves room for fields a
// newer client adds, while a peer announcing a snapshot-sized frame is refused
// from its 4-byte header, before the server buffers any of it.
inline constexpr std::size_t kMaxSubscriberFrameBytes = 4096;

std::vector<std::uint8_t> encodeFrame(std::span<const std::uint8_t> payload);

// Incremental decoder: feed it whatever bytes arrived, take whole frames out.
class FrameDecoder {
 public:
  // maxFrameBytes: the largest payload this side accepts (kMaxFrameBytes on
  // a renderer, which must take snapshots; kMaxSubscriberFrameBytes on a server).
  explicit FrameDecoder(std::size_t maxFrameBytes = kMaxFrameBytes) : maxFrameBytes_(maxFrameBytes) {}

  void append(std::span<const std::uint8_t> bytes);

  // The next complete payload; nullopt when more bytes are needed; an error
  // (TooLarge) when the stream announced an oversized frame. After an error
  // the decoder stays failed.
  Result<std::optional<std::vector<std::uint8_t>>> next();

  std::size_t bufferedBytes() const { return buffer_.size() - consumed_; }

 private:
  std::vector<std::uint8_t> buffer_;
  std::size_t consumed_ = 0;
  std::size_t maxFrameBytes_;
  bool failed_ = false;
};

}  // namespace sky::stream
