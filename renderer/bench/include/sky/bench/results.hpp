// What one bench run measured: per scene, configuration and resolution the
// frame times (wall, GPU when the renderer reports it, CPU) and the error
// against `reference`; and the report files made from it (JSON, markdown,
// plots). Written by runner.hpp, turned into files by report.hpp.
#pragma once

#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "sky/bench/metrics.hpp"

namespace sky::bench {

// Median and spread of a sample (nearest-rank percentiles).
struct Spread {
  std::size_t samples = 0;
  double median = 0, min = 0, max = 0, p10 = 0, p90 = 0;
};
Spread spreadOf(std::vector<double> values);

struct FrameTiming {
  double wall_ms = 0;             // steady clock around CloudRenderer::render
  std::optional<double> gpu_ms;   // the renderer's GPU timestamps around its cloud passes, when it reports them
  double cpu_ms = 0;              // process CPU time during the frame
  double maxThread_ms = 0;        // the busiest thread's CPU time during the frame
  std::optional<std::uint64_t> lookups;  // density lookups of the frame, when the renderer counts them
  std::map<std::string, double> passes_ms;  // GPU time per pass (renderer_probe.hpp), when it reports them
};

// Error of a configuration's frame(s) against reference at the same output size.
struct ErrorSummary {
  double rmseLinear = 0;  // linear rgb radiance
  double psnr_dB = 0;     // 8-bit sRGB; +infinity when identical
  double ssim = 1;        // Wang et al. 2004 on sRGB luma
};

struct CaseResult {
  std::string scene, configuration;
  bool path = false;
  std::uint32_t width = 0, height = 0;              // output (and reference) size
  std::uint32_t renderWidth = 0, renderHeight = 0;  // what the renderer drew
  double create_ms = 0;                             // CloudRenderer::create
  std::vector<FrameTiming> frames;                  // every timed frame (repeats x path frames)
  Spread wall_ms, cpu_ms, maxThread_ms;
  std::optional<Spread> gpu_ms;
  std::map<std::string, double> passMedian_ms;  // each pass's median GPU time over the frames
  std::optional<double> lookupsPerSecond;  // lookups / GPU time, when both exist
  ErrorSummary error;  // a still: its image; a path: the mean over its frames
  ErrorSummary worst;  // a path: the worst frame (largest RMSE, lowest PSNR, lowest SSIM); a still: = error
  std::size_t worstFrame = 0;  // a path: the frame of the lowest SSIM (the contact sheet shows it); a still: 0
  std::optional<TemporalError> temporal;  // paths only
  // A still with --truth path: its image against the path-traced truth
  // (truth.hpp), and the truth's own noise: its samples per pixel and mean
  // relative standard error.
  std::optional<ErrorSummary> truthError;
  double truthRmse = 0;       // of the rgb mean, the truth's noise taken out (truth.hpp, truthDistance)
  double truthMeanRatio = 0;  // the image's mean over the truth's
  std::uint64_t truthSamples = 0;
  double truthRelativeError = 0;
  std::size_t nonFinitePixels = 0;        // over every kept frame
  bool repeatable = true;                 // every repeat of a still gave the same image, bit for bit
  std::string contactSheet;               // file of the scene's contact sheet, relative to the output folder
};

struct MachineInfo {
  std::string device;       // Vulkan device name
  std::string cpu;          // /proc/cpuinfo model name
  unsigned cores = 0;       // online CPUs
  std::string lpNumThreads; // LP_NUM_THREADS as the run saw it
  std::string loadAverageStart, loadAverageEnd;  // /proc/loadavg (1, 5, 15 min)
  std::string started;      // UTC, ISO 8601
};

// A still's model with one part switched off (render::ModelSwitches),
// drawn by the CPU reference and measured against the path-traced truth.
struct ModelVariantResult {
  std::string scene, variant;  // variant: "model", "no octaves", "no ambient", "HG phase"
  std::uint32_t width = 0, height = 0;
  ErrorSummary error;
  double meanRatio = 0;  // the variant's mean luminance over the truth's
  double rmse = 0;       // of the rgb mean, the truth's noise taken out (truthDistance)
};

struct BenchReport {
  MachineInfo machine;
  std::string timingSource;  // where wall/GPU times come from (renderer_probe.hpp)
  std::uint32_t warmup = 0, repeats = 0, pathRepeats = 0;
  std::vector<CaseResult> cases;
  std::vector<ModelVariantResult> modelVariants;  // --truth path only
};

}  // namespace sky::bench
