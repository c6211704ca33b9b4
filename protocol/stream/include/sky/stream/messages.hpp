// The weather stream's messages as C++ values, and their FlatBuffers encoding.
// decodeMessage runs the FlatBuffers verifier and then checks every field's
// range, so a caller only ever sees values inside the documented ranges.
#pragma once

#include <cstddef>
#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <variant>
#include <vector>

#include "sky/core/result.hpp"
#include "sky/weather/lightning.hpp"
#include "sky/weather/model.hpp"
#include "sky/weather/tiling.hpp"

namespace sky::stream {

// Major version of the stream: bumped on any incompatible schema change. A
// server answers a Subscribe of another version with an Error and closes.
inline constexpr std::uint16_t kProtocolVersion = 2;

// Bytes one coverage tile takes on the wire (FlatBuffers struct Tile),
// for budgeting tiles against kMaxFrameBytes.
inline constexpr std::size_t kTileWireBytes = 16;
// The same for a WindTile and an AirTile.
inline constexpr std::size_t kWindTileWireBytes = 16;
inline constexpr std::size_t kAirTileWireBytes = 16;

// Caps on one Snapshot or Delta, checked before anything is decoded, so a
// crafted frame costs O(n log n) in its counts and no more. Layers: a server
// sends at most weather::kMaxScenarioLayers (32) distinct layers; 256 leaves
// room for a newer server and is still nothing to sort. Tiles: as many as fit
// in the largest frame (kMaxFrameBytes / kTileWireBytes = 262144).
inline constexpr std::size_t kMaxMessageLayers = 256;
inline constexpr std::size_t kMaxMessageTiles = (4u << 20) / kTileWireBytes;
static_assert(kMaxMessageTiles == weather::kMaxSnapshotTiles, "a snapshot holds what one frame carries");

// Bits of Hello::features: what a server takes beyond the base protocol of
// its major version. A server from before the field sends 0.
inline constexpr std::uint32_t kFeatureCameraReports = 1u << 0;  // takes CameraReport
inline constexpr std::uint32_t kFeatureAreas = 1u << 1;          // takes Subscribe.areaIndex > 0
inline constexpr std::uint32_t kFeatureHostClock = 1u << 2;      // takes HostClock proposals
inline constexpr std::uint32_t kFeatureTileDrift = 1u << 3;      // sets Layer.tiles_drift (else: all drift)
inline constexpr std::uint32_t kFeatureLightningRequests = 1u << 4;  // answers LightningRequest

// Areas of interest one connection may hold (Subscribe::areaIndex): a
// renderer asks for its detailed area around the camera (0) and a wider one
// at coarser tiles (1) for the weather map's coarse ring.
inline constexpr std::uint8_t kMaxAreas = 2;

struct Hello {
  std::uint16_t protocolVersion = kProtocolVersion;
  std::string serverId;
  double weatherClock_s = 0;
  double clockRate = 1;  // weather seconds per wall second, [0, 3600]
  std::uint32_t features = 0;  // kFeature* bits
};

struct Subscribe {
  std::uint16_t protocolVersion = kProtocolVersion;
  weather::SphericalCap area;
  double altMin_m = -500;  // altitude band of interest, MSL
  double altMax_m = 20000;
  int tileLevel = 8;  // S2 level, [0, 20]
  std::uint8_t areaIndex = 0;  // [0, kMaxAreas); replaces only the area of this index
};

struct Heartbeat {
  double weatherClock_s = 0;
};

struct StreamError {
  std::uint16_t code = 0;
  std::string detail;
};

// Longest CameraReport::channel, bytes: a display name ("left", "cockpit-2
// center"), bounded so a report stays a few hundred bytes.
inline constexpr std::size_t kMaxChannelBytes = 64;

// Renderer to server: the camera a channel renders from, for the console.
struct CameraReport {
  std::string channel;        // UTF-8, no control characters, <= kMaxChannelBytes
  double lat_deg = 0;         // geodetic, [-90, 90]
  double lon_deg = 0;         // [-180, 180]
  double alt_m = 0;           // the pose's height (WGS84 ellipsoid), [-1000, 1e6] (as Subscribe's band)
  double heading_deg = 0;     // true, [0, 360]
  double pitch_deg = 0;       // nose up +, [-90, 90]
  double roll_deg = 0;        // right wing down +, [-180, 180]
  std::uint64_t frame = 0;    // the renderer's frame index
  std::uint64_t weatherVersion = 0;  // snapshots and deltas the renderer has applied
  double weatherClock_s = 0;  // weather clock of that frame, finite
};

// Server to renderer: lightning flashes (sky/weather/lightning.hpp), each
// sent once. At most kMaxMessageFlashes a message.
inline constexpr std::size_t kMaxMessageFlashes = 1024;
struct Lightning {
  double weatherClock_s = 0;
  std::vector<weather::LightningFlash> flashes;
  // The answer to a LightningRequest: its toSeconds; unset for flashes drawn
  // as the server's clock ran or asked for by the operator.
  std::optional<double> answersTo_s;
};

// Renderer to server: the flashes of the server's lightning process in the
// weather-clock interval (from_s, to_s] over this session's areas (see the
// schema). At most kMaxLightningRequestSpan_s long.
inline constexpr double kMaxLightningRequestSpan_s = 600;
struct LightningRequest {
  double from_s = 0;  // finite, |from_s| <= 1e12
  double to_s = 0;    // from_s < to_s <= from_s + kMaxLightningRequestSpan_s
};

// Both ways: the weather clock of one CIGI host's frames, as weather clock =
// offset_s + rate x host time (sky/weather/host_clock_lock.hpp). A renderer
// proposes its estimate; the server answers with the offset it holds for the
// host, the same for every channel of it.
struct HostClock {
  std::string host;     // UTF-8, no control characters, 1..kMaxChannelBytes bytes
  double offset_s = 0;  // finite, |offset_s| <= 1e12
  double rate = 1;      // (0, 3600]
};

// A message of a kind this build does not know (a newer peer of the same
// major version sent it): decoded so the receiver can ignore it. Encoding one
// writes an empty table of that kind (for tests of that rule).
struct UnknownKind {
  std::uint8_t bodyType = 0;  // the union type byte, not one of ours
};

using Message = std::variant<Hello, Subscribe, weather::WeatherSnapshot, Heartbeat, StreamError,
                             weather::WeatherDelta, CameraReport, Lightning, HostClock, LightningRequest, UnknownKind>;

std::vector<std::uint8_t> encodeMessage(const Message& message);

// Verifies and range-checks one frame's payload: finite numbers, fractions in
// [0, 1], latitudes, longitudes and altitudes in range, every tile a valid S2
// cell of the stated level, every Snapshot tile of a layer the Snapshot has,
// layer ids unique, at most kMaxMessageLayers layers (and removed ids) and
// kMaxMessageTiles tiles (TooLarge otherwise), a CameraReport's pose in range and its channel valid
// UTF-8. A Hello or Subscribe of another protocol version is an Unsupported
// error that says both versions. A body of a kind we do not know is an
// UnknownKind (to ignore), not an error; a missing body is Malformed.
Result<Message> decodeMessage(std::span<const std::uint8_t> payload);

// Name of the message kind, for logs ("Hello", "Snapshot", ...).
const char* kindName(const Message& message);

}  // namespace sky::stream
