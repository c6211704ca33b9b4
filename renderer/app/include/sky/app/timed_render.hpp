// One frame through the renderer with what the metadata says about it: wall
// time, process CPU time (lavapipe runs the GPU work on CPU threads, so wall
// time alone doubles when another process takes a core), GPU time per pass,
// and the sun and moon the frame was lit by.
#pragma once

#include "sky/app/frame_writer.hpp"
#include "sky/render/cloud_renderer.hpp"

namespace sky::app {

// Renders `in` and, on success, fills record's render_ms, cpu_ms, gpu, stats
// and sun, moon and haze fields.
Result<render::Image> timedRender(render::CloudRenderer& renderer, const render::FrameInputs& in, FrameRecord& record);

// Fills record's sun, moon and haze fields with what the frame `in` is lit
// by (the renderer's choice: the ephemeris when it has a date, else its angles).
void recordLighting(const render::FrameInputs& in, FrameRecord& record);

// CPU time of the whole process (every thread), ms.
double processCpu_ms();

// Logs the Vulkan validation messages collected since the last call (errors
// as errors, the rest as warnings) on stderr; nothing without validation.
void logValidationMessages(render::CloudRenderer& renderer);

}  // namespace sky::app
