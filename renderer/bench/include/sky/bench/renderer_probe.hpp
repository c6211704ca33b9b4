// What the renderer measures about its own frame, read through its public
// API. The one place the bench asks the renderer for GPU time and lookup
// counts: GPU time comes from its per-pass timestamps; lookup counts are not
// in the public API (cloud_renderer.hpp) yet, so they stay absent.
#pragma once

#include <cstdint>
#include <map>
#include <optional>
#include <string>

#include "sky/render/cloud_renderer.hpp"

namespace sky::bench {

struct RendererCounters {
  // GPU time of the cloud passes of the last frame, ms (timestamps written
  // around the passes: lavapipe.md, "Timestamps").
  std::optional<double> gpuCloud_ms;
  // The same per pass ("sun-map", "air-table", "clouds", "reproject", "upscale").
  std::map<std::string, double> passes_ms;
  // Density lookups (3D noise texture fetches) of the last frame's cloud pass.
  std::optional<std::uint64_t> densityLookups;
};

// Counters of the frame `image` was just rendered by `renderer`.
RendererCounters rendererCounters(const render::CloudRenderer& renderer, const render::Image& image);

// One line saying where the numbers come from, for logs and reports.
const char* rendererCountersSource();

}  // namespace sky::bench
