// Named quality presets: each a set of the cloud march's cost knobs
// (MarchSettings). `reference` is the ground truth the bench compares the
// others with; `high` is the default (RenderSettings' defaults). The table
// of values is in docs/rendering.md ("Quality presets").
#pragma once

#include <string>
#include <vector>

#include "sky/core/result.hpp"
#include "sky/render/cloud_renderer.hpp"

namespace sky::render {

struct Preset {
  std::string name;         // what --preset takes
  std::string description;  // what it changes against reference, one line
  MarchSettings march;
  TemporalSettings temporal;  // interleave 1: every pixel every frame
  ResolutionSettings resolution{};  // divisor 1: the clouds drawn at full size
};

// Every preset, `reference` first, then from most to least expensive.
const std::vector<Preset>& presets();

// The preset called name. Errors: InvalidArgument naming it and listing the
// valid names.
Result<Preset> findPreset(const std::string& name);

}  // namespace sky::render
