// Writes a headless channel's output: one PNG per frame (optionally the
// linear radiance and the transmittance as PFM), and one JSON line of metadata per frame in
// frames.jsonl (camera pose and its source, host frame, weather clock, image statistics).
#pragma once

#include <cstdint>
#include <fstream>
#include <string>

#include "sky/app/shared_state.hpp"
#include "sky/core/result.hpp"
#include "sky/render/cloud_renderer.hpp"

namespace sky::app {

struct FrameRecord {
  std::uint64_t frame = 0;
  HostPose host;
  std::string source = "cigi";  // where the camera came from: "cigi" or "fdm" (FlightGear)
  double weatherClock_s = 0;
  std::uint64_t weatherVersion = 0;
  std::size_t layerCount = 0;
  render::ImageStats stats;
  double render_ms = 0;
};

class FrameWriter {
 public:
  static Result<FrameWriter> open(const std::string& directory, bool writeFloat);
  Result<void> write(const render::Image& image, const FrameRecord& record);
  const std::string& directory() const { return directory_; }

 private:
  std::string directory_;
  bool writeFloat_ = false;
  std::ofstream metadata_;
};

// Portable float map (PFM, little-endian, bottom row first) of the linear
// radiance (colour, no tone mapping) or of the view-ray transmittance through
// the clouds (grey), for tests that check every value.
enum class PfmChannels { Radiance, Transmittance };
Result<void> writePfm(const render::Image& image, const std::string& path, PfmChannels channels);

}  // namespace sky::app
