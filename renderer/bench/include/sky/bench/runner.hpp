// The bench run: every chosen scene x configuration x resolution rendered on
// the real renderer, timed after warm-up, compared with `reference` at the
// same resolution; each scene's contact sheet is written as it completes.
#pragma once

#include <cstdint>
#include <filesystem>
#include <functional>
#include <string>
#include <vector>

#include "sky/bench/configurations.hpp"
#include "sky/bench/results.hpp"
#include "sky/bench/suite_loader.hpp"
#include "sky/bench/truth.hpp"
#include "sky/core/result.hpp"

namespace sky::bench {

struct Resolution {
  std::uint32_t width = 320, height = 180;
};

struct RunOptions {
  std::vector<Resolution> resolutions{{320, 180}};
  std::vector<Configuration> configurations;  // reference first (selectConfigurations)
  // Untimed frames before timing each case: a pipeline's first dispatch
  // compiles its shader variant (10-70 ms extra on lavapipe, lavapipe.md).
  std::uint32_t warmup = 2;
  // A configuration that reuses history first fills it (historyWarmupFrames,
  // hundreds of frames with accumulation); off only for checks that the
  // bench runs, whose stills then show an unconverged image.
  bool historyWarmup = true;
  std::uint32_t repeats = 5;      // timed renders of each still
  std::uint32_t pathRepeats = 1;  // timed runs of each whole camera path
  std::filesystem::path outDir;   // contact sheets go to outDir/contact/
  // --truth path: each still also measured against its path-traced frame
  // (samplesPerPixel 0: not); the sums resume from outDir/truth/.
  TruthOptions truth;
  std::function<void(const std::string&)> log;  // progress lines; may be empty
};

// Runs the bench. Errors: the renderer's (Unsupported without a Vulkan
// device), Io for output files; a frame with non-finite pixels is not an
// error (it is counted in the results).
Result<BenchReport> runBench(const std::vector<LoadedScene>& scenes, const RunOptions& options);

// Facts about this machine for the report (everything but the device).
MachineInfo describeMachine();
std::string loadAverage();

}  // namespace sky::bench
