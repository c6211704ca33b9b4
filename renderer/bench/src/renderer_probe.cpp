// See renderer_probe.hpp. Today's renderer exposes no per-frame counters.
#include "sky/bench/renderer_probe.hpp"

namespace sky::bench {

RendererCounters rendererCounters(const render::CloudRenderer& /*renderer*/, const render::Image& /*image*/) {
  return {};
}

const char* rendererCountersSource() {
  return "wall = fence wall time around CloudRenderer::render (upload, dispatch, wait, readback): the renderer does "
         "not expose GPU timestamps yet";
}

}  // namespace sky::bench
