// What a headless replay leaves besides the frames: a contact sheet (a grid of
// thumbnails across the flight), an MP4 made by ffmpeg from the PNGs, and the
// numbers for the report.
#pragma once

#include <cstddef>
#include <string>
#include <vector>

#include "sky/core/result.hpp"
#include "sky/render/cloud_renderer.hpp"

namespace sky::app {

// Builds a contact sheet of `columns` × `rows` cells from thumbnails added in
// order (linear radiance, box-filtered), with a dark gap between cells.
class ContactSheet {
 public:
  ContactSheet(std::size_t columns, std::size_t rows, std::uint32_t cellWidth, std::uint32_t sourceWidth,
               std::uint32_t sourceHeight);
  // The frame indices (of `frameCount`) to pick: evenly spaced, first and last included.
  static std::vector<std::size_t> pick(std::size_t frameCount, std::size_t cells);
  // The frame's radiance is scaled by `exposure` (its PNG's display
  // exposure: writePng), so a sheet written at exposure 1 shows each
  // thumbnail as its frame's PNG does.
  void add(const render::Image& frame, double exposure = 1.0);
  const render::Image& image() const { return sheet_; }

 private:
  std::size_t columns_, rows_, added_ = 0;
  std::uint32_t cellW_, cellH_;
  render::Image sheet_;
};

// Runs ffmpeg (found on PATH) to encode directory/frame_%06d.png at `fps`
// into `mp4Path` (H.264, yuv420p, even size). Io when ffmpeg is missing or fails.
Result<void> encodeVideo(const std::string& framesDirectory, double fps, const std::string& mp4Path);

struct Percentiles {
  double p50 = 0, p90 = 0, p99 = 0, mean = 0, max = 0;
};
// Nearest-rank percentiles; all zero for no samples.
Percentiles percentiles(std::vector<double> samples);

}  // namespace sky::app
