// CPU reference: the same cloud model as the GPU pass (shaders/include/
// cloud_core.glsl compiled as C++), evaluated in double precision with
// emulated texture filtering, for image tests and numerical checks.
#pragma once

#include "sky/render/cloud_renderer.hpp"

namespace sky::render {

// Renders the frame on the CPU. Same contract and errors as
// CloudRenderer::render (no Device errors). Slow: meant for small images.
Result<Image> renderCpuReference(const RenderSettings& settings, const FrameInputs& inputs);

}  // namespace sky::render
