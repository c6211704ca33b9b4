// What the operator console sees of one weather-stream subscriber (GET
// /api/renderers and the WebSocket's "renderers" message): its connection,
// the area it subscribed to and the camera it reported last.
#pragma once

#include <chrono>
#include <cstdint>
#include <optional>
#include <string>

#include "sky/stream/messages.hpp"

namespace sky::server {

struct RendererInfo {
  std::uint64_t id = 0;  // the stream session's id, unique over the server's run
  std::string peer;      // "ip:port"
  std::optional<weather::SphericalCap> area;  // none before its first Subscribe
  std::optional<stream::CameraReport> report; // none from a renderer that sends no CameraReport
  double lastReportAge_s = 0;  // wall seconds since `report` arrived (with a report)
};

}  // namespace sky::server
