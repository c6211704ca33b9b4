// The Vulkan side of the density-lookup micro-benchmark (lookup_bench.cpp): a
// device, a 128^3 volume texture, the lookup_march.comp pipeline, and timed
// dispatches (GPU timestamps around the dispatch, fence wall time around the
// submit). Standalone on purpose: it measures the machine, not the renderer,
// so it shares no code with renderer/core.
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "sky/core/result.hpp"

namespace sky::bench {

inline constexpr std::uint32_t kVolumeSize = 128;  // texels per edge, as the renderer's shape noise

enum class VolumeFormat { Rgba8, R8 };
enum class VolumeFilter { Linear, Nearest };

struct LookupDispatch {
  std::uint32_t width = 320, height = 180;
  std::uint32_t steps = 128;        // lookups per pixel
  double stepTexels = 0.5;          // step length along the ray, texels: < 1 is a coherent march
  double verticalFov_deg = 60;
};

struct LookupTiming {
  double gpu_ms = 0;   // timestamps around the dispatch
  double wall_ms = 0;  // submit to fence signalled
  double cpu_ms = 0;   // process CPU time over the submit
};

class LookupGpu {
 public:
  // Creates the device (SKY_VULKAN_DEVICE=<substring> chooses by name) and a
  // volume of this format filled with `texels` (kVolumeSize^3 values, one per
  // texel; RGBA8 repeats it in every channel), sampled with repeat addressing.
  // Errors: Unsupported without a Vulkan 1.2 compute device with timestamps,
  // Io when the SPIR-V is missing, Device for other Vulkan failures.
  static Result<std::unique_ptr<LookupGpu>> create(VolumeFormat format, VolumeFilter filter,
                                                   const std::vector<std::uint8_t>& texels,
                                                   const std::string& spirvPath);

  // One dispatch of the march; `sums` (optional) receives each pixel's sum of lookups.
  Result<LookupTiming> run(const LookupDispatch& dispatch, std::vector<float>* sums = nullptr);

  std::string deviceName() const;

  ~LookupGpu();
  LookupGpu(const LookupGpu&) = delete;
  LookupGpu& operator=(const LookupGpu&) = delete;

 private:
  struct Impl;
  explicit LookupGpu(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
};

}  // namespace sky::bench
