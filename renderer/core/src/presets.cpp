// Quality presets (see presets.hpp).
#include "sky/render/presets.hpp"

namespace sky::render {

namespace {

MarchSettings march(std::uint32_t primarySteps, std::uint32_t lightSteps, double minTransmittance,
                    std::uint32_t emptyStride) {
  MarchSettings m;
  m.primarySteps = primarySteps;
  m.lightSteps = lightSteps;
  m.minTransmittance = minTransmittance;
  m.emptyStride = emptyStride;
  return m;
}

}  // namespace

const std::vector<Preset>& presets() {
  static const std::vector<Preset> all = {
      {"reference", "ground truth: 256 primary steps, 8 light steps, no early exit, every sample", march(256, 8, 0, 1)},
      {"high", "the default: 48 primary steps, 4 light steps, exit at 1 %, every sample", MarchSettings{}},
      {"medium", "32 primary steps, 3 light steps, exit at 2 %, empty stride 2", march(32, 3, 0.02, 2)},
      {"low", "24 primary steps, 2 light steps, exit at 3 %, empty stride 2", march(24, 2, 0.03, 2)},
      {"realtime", "16 primary steps, 1 light step, exit at 5 %, empty stride 3", march(16, 1, 0.05, 3)},
  };
  return all;
}

Result<Preset> findPreset(const std::string& name) {
  std::string valid;
  for (const Preset& p : presets()) {
    if (p.name == name) return p;
    valid += (valid.empty() ? "" : ", ") + p.name;
  }
  return fail(ErrorCode::InvalidArgument, "unknown preset '" + name + "' (valid: " + valid + ")");
}

}  // namespace sky::render
