// See renderer_probe.hpp. GPU time from the renderer's per-pass timestamps
// (CloudRenderer::lastPassTimes); lookup counts are not exposed yet.
#include "sky/bench/renderer_probe.hpp"

namespace sky::bench {

RendererCounters rendererCounters(const render::CloudRenderer& renderer, const render::Image& /*image*/) {
  RendererCounters c;
  for (const auto& pass : renderer.lastPassTimes())
    if (pass.pass == "sun-map" || pass.pass == "air-table" || pass.pass == "clouds" || pass.pass == "reproject" ||
        pass.pass == "upscale") {
      c.gpuCloud_ms = c.gpuCloud_ms.value_or(0.0) + pass.gpu_ms;
      c.passes_ms[pass.pass] += pass.gpu_ms;
    }
  return c;
}

const char* rendererCountersSource() {
  return "wall = fence wall time around CloudRenderer::render (upload, dispatch, wait, readback); GPU = Vulkan "
         "timestamps around the sun map, the air table, the cloud pass, its reprojection and its upscale "
         "(CloudRenderer::lastPassTimes); lookup counts not exposed yet";
}

}  // namespace sky::bench
