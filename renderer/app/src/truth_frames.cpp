// Path-traced frames of a replay (see truth_frames.hpp).
#include "sky/app/truth_frames.hpp"

#include <algorithm>
#include <charconv>
#include <chrono>
#include <cmath>
#include <thread>

#include "sky/app/timed_render.hpp"

namespace sky::app {

namespace {

// The floor of a pixel's mean in the relative standard error, radiance
// units: the bench's (renderer/bench/src/truth.cpp), so the two report the
// same number; it keeps black pixels (the night's ground) from dividing by 0.
constexpr double kRelativeErrorFloor = 1e-3;

}  // namespace

Result<TruthSettings> parseTruthSettings(const std::string& mode, const std::optional<std::string>& sppText,
                                         std::uint32_t threads) {
  if (mode != "path")
    return fail(ErrorCode::InvalidArgument, "--truth '" + mode + "': the only ground truth is 'path' (the path tracer)");
  TruthSettings s;
  if (sppText) {
    const std::string& spp = *sppText;
    std::uint64_t n = 0;
    const auto [end, ec] = std::from_chars(spp.data(), spp.data() + spp.size(), n);
    if (ec != std::errc() || end != spp.data() + spp.size() || n < kMinTruthSpp || n > kMaxTruthSpp)
      return fail(ErrorCode::InvalidArgument,
                  "--spp '" + spp + "': the samples per pixel must be a whole number from " +
                      std::to_string(kMinTruthSpp) + " to " + std::to_string(kMaxTruthSpp) + " (" +
                      std::to_string(kMinTruthSpp) + " at least: a pixel's standard error needs two samples)");
    s.samplesPerPixel = static_cast<std::uint32_t>(n);
  }
  if (threads > kMaxTruthThreads)
    return fail(ErrorCode::InvalidArgument, "--truth-threads " + std::to_string(threads) + ": at most " +
                                                std::to_string(kMaxTruthThreads) + " (0: every hardware thread)");
  s.threads = threads;
  return s;
}

Result<TruthFrames> TruthFrames::create(const render::RenderSettings& settings, const TruthSettings& truth) {
  auto tracer = render::PathTracer::create(settings);
  if (!tracer) return tl::unexpected(tracer.error());
  return TruthFrames(std::move(*tracer), truth);
}

std::uint32_t TruthFrames::threads() const {
  return truth_.threads > 0 ? truth_.threads : std::max(1u, std::thread::hardware_concurrency());
}

std::string TruthFrames::deviceName() const {
  return "CPU path tracer, " + std::to_string(threads()) + " threads";
}

Result<render::Image> TruthFrames::render(const render::FrameInputs& in, FrameRecord& record) const {
  render::PathTraceOptions o;
  o.samplesPerPixel = truth_.samplesPerPixel;
  o.threads = threads();
  o.seed = in.frameIndex + 1;
  o.progress = progress_;
  render::PathTraceState state;
  const double cpu0 = processCpu_ms();
  const auto t0 = std::chrono::steady_clock::now();
  if (auto ok = tracer_.render(in, o, state); !ok) return tl::unexpected(ok.error());
  record.render_ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
  record.cpu_ms = processCpu_ms() - cpu0;
  render::Image image = state.mean();
  record.stats = render::computeStats(image);
  recordLighting(in, record);

  FrameRecord::Truth t;
  t.samplesPerPixel = static_cast<std::uint32_t>(state.samples);
  t.seed = o.seed;
  t.threads = o.threads;
  t.majorantViolations = state.violations;
  t.densityLookups = state.lookups;
  t.standardError = state.standardError();
  const std::size_t n = t.standardError.size();
  double sum = 0, squares = 0, relative = 0;
  for (std::size_t i = 0; i < n; ++i) {
    const double e = t.standardError[i];
    const double mean = (image.rgba[i * 4] + image.rgba[i * 4 + 1] + image.rgba[i * 4 + 2]) / 3.0;
    sum += e;
    squares += e * e;
    relative += e / std::max(mean, kRelativeErrorFloor);
    t.maxStandardError = std::max(t.maxStandardError, e);
  }
  if (n > 0) {
    t.meanStandardError = sum / double(n);
    // The pixels' noise is independent, so the image mean's variance is
    // the sum of theirs over n^2.
    t.imageMeanStandardError = std::sqrt(squares) / double(n);
    t.meanRelativeStandardError = relative / double(n);
  }
  record.truth = std::move(t);
  return image;
}

}  // namespace sky::app
