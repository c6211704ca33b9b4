// The weather stream's messages as C++ values, and their FlatBuffers encoding.
// decodeMessage runs the FlatBuffers verifier and then checks every field's
// range, so a caller only ever sees values inside the documented ranges.
#pragma once

#include <cstdint>
#include <span>
#include <string>
#include <variant>
#include <vector>

#include "sky/core/result.hpp"
#include "sky/weather/model.hpp"
#include "sky/weather/tiling.hpp"

namespace sky::stream {

// Major version of the stream: bumped on any incompatible schema change. A
// server answers a Subscribe of another version with an Error and closes.
inline constexpr std::uint16_t kProtocolVersion = 2;

// Bytes one coverage tile takes on the wire (FlatBuffers struct Tile),
// for budgeting tiles against kMaxFrameBytes.
inline constexpr std::size_t kTileWireBytes = 16;

struct Hello {
  std::uint16_t protocolVersion = kProtocolVersion;
  std::string serverId;
  double weatherClock_s = 0;
  double clockRate = 1;  // weather seconds per wall second, [0, 3600]
};

struct Subscribe {
  std::uint16_t protocolVersion = kProtocolVersion;
  weather::SphericalCap area;
  double altMin_m = -500;  // altitude band of interest, MSL
  double altMax_m = 20000;
  int tileLevel = 8;  // S2 level, [0, 20]
};

struct Heartbeat {
  double weatherClock_s = 0;
};

struct StreamError {
  std::uint16_t code = 0;
  std::string detail;
};

using Message = std::variant<Hello, Subscribe, weather::WeatherSnapshot, Heartbeat, StreamError,
                             weather::WeatherDelta>;

std::vector<std::uint8_t> encodeMessage(const Message& message);

// Verifies and range-checks one frame's payload: finite numbers, fractions in
// [0, 1], latitudes, longitudes and altitudes in range, every tile a valid S2
// cell of the stated level, every Snapshot tile of a layer the Snapshot has,
// layer ids unique. A Hello or Subscribe of another protocol version is an
// Unsupported error that says both versions.
Result<Message> decodeMessage(std::span<const std::uint8_t> payload);

// Name of the message kind, for logs ("Hello", "Snapshot", ...).
const char* kindName(const Message& message);

}  // namespace sky::stream
