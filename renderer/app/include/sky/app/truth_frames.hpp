// skyshell-render --replay --truth path: a flight's frames drawn by the CPU
// path tracer of the same medium (sky/render/path_tracer.hpp) instead of the
// GPU, each with its sample count and per-pixel standard error in its
// record (frames.jsonl "truth", the EXR's truth.standard_error). Slow by
// design: seconds a frame at 32x18, minutes at 160x90.
#pragma once

#include <cstdint>
#include <functional>
#include <optional>
#include <string>

#include "sky/app/frame_writer.hpp"
#include "sky/core/result.hpp"
#include "sky/render/cloud_renderer.hpp"
#include "sky/render/path_tracer.hpp"

namespace sky::app {

// --spp's range. At least 2: a pixel's standard error is estimated from the
// spread of its samples, which one sample does not have. At most 65536: a
// 160x90 cumulus frame at 64 takes 41 s to 12 min on this machine
// (docs/ground-truth.md), so 65536 is days a frame; more is a typo.
inline constexpr std::uint32_t kMinTruthSpp = 2, kMaxTruthSpp = 65536;
// Without --spp: 16, a quarter of the bench's 64 (half its noise's
// precision) for a quarter of its time, since a replay has many frames.
inline constexpr std::uint32_t kDefaultTruthSpp = 16;
// --truth-threads' largest value (0: every hardware thread).
inline constexpr std::uint32_t kMaxTruthThreads = 1024;

struct TruthSettings {
  std::uint32_t samplesPerPixel = kDefaultTruthSpp;  // [kMinTruthSpp, kMaxTruthSpp]
  std::uint32_t threads = 0;                         // 0: every hardware thread
};

// --truth's mode ("path", the only one) and --spp's text (nullopt: not
// given, the default) into settings. InvalidArgument, saying which option
// and why, for another mode, an --spp that is not a whole number in range
// (an empty one too), or threads over kMaxTruthThreads.
Result<TruthSettings> parseTruthSettings(const std::string& mode, const std::optional<std::string>& spp,
                                         std::uint32_t threads);

class TruthFrames {
 public:
  // The path tracer of `settings` (resolution, field of view, noise seed,
  // the march of the view ray's air). Errors: PathTracer::create's.
  static Result<TruthFrames> create(const render::RenderSettings& settings, const TruthSettings& truth);

  // Path-traces the frame `in` with its frame index as the seed (so the
  // frames' noise is independent and a re-run gives the same sums), and
  // fills record's render_ms, cpu_ms, stats, lighting and truth. Errors:
  // PathTracer::render's.
  Result<render::Image> render(const render::FrameInputs& in, FrameRecord& record) const;

  // Called from one thread as a frame's rows finish: rows done, rows in all.
  void setProgress(std::function<void(std::uint32_t, std::uint32_t)> progress) { progress_ = std::move(progress); }

  const render::RenderSettings& settings() const { return tracer_.settings(); }
  const TruthSettings& truth() const { return truth_; }
  // The threads a frame is traced on (the hardware's when 0 was asked).
  std::uint32_t threads() const;
  // What report.json names as the device: "CPU path tracer, N threads".
  std::string deviceName() const;

 private:
  TruthFrames(render::PathTracer tracer, const TruthSettings& truth) : tracer_(std::move(tracer)), truth_(truth) {}
  render::PathTracer tracer_;
  TruthSettings truth_;
  std::function<void(std::uint32_t, std::uint32_t)> progress_;
};

}  // namespace sky::app
