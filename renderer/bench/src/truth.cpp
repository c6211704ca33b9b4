#include "sky/bench/truth.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <cstdlib>
#include <sstream>
#include <string_view>

#include "sky/render/path_tracer.hpp"

namespace sky::bench {

namespace {

using Clock = std::chrono::steady_clock;

std::string fixed(double v, int digits) {
  std::ostringstream s;
  s.setf(std::ios::fixed);
  s.precision(digits);
  s << v;
  return s.str();
}

// What the sums are of: a resumed state must be of the same frame.
std::string stateKey(const LoadedScene& scene, std::uint32_t w, std::uint32_t h, const TruthOptions& o,
                     const render::RenderSettings& s) {
  std::ostringstream k;
  k.precision(17);
  k << scene.scene.name << ' ' << w << 'x' << h << " events " << o.maxEvents << " seed " << s.noiseSeed << " fov "
    << s.verticalFov_deg << " air " << s.march.airSteps << " shadow " << int(s.march.sunShadow.method);
  return k.str();
}

}  // namespace

Result<render::ModelSwitches> parseModelSpec(std::string_view spec) {
  render::ModelSwitches m;
  if (spec.empty()) return fail(ErrorCode::InvalidArgument, "empty model spec (e.g. b=0.35:sd=0.5)");
  std::size_t start = 0;
  while (start <= spec.size()) {
    const std::size_t end = std::min(spec.find(':', start), spec.size());
    const std::string_view part = spec.substr(start, end - start);
    const std::size_t eq = part.find('=');
    const std::string_view key = part.substr(0, eq);
    const std::string value(eq == std::string_view::npos ? std::string_view{} : part.substr(eq + 1));
    char* stop = nullptr;
    const double v = value.empty() ? -1.0 : std::strtod(value.c_str(), &stop);
    const bool number = !value.empty() && stop == value.c_str() + value.size() && std::isfinite(v);
    if (key == "b" && number && v >= 0 && v <= 1) {
      if (m.octaveContribution) return fail(ErrorCode::InvalidArgument, "model spec '" + std::string(spec) + "': b twice");
      m.octaveContribution = v;
    } else if (key == "sd" && number && v >= 0 && v <= 2) {
      if (m.sunDiffuseGain) return fail(ErrorCode::InvalidArgument, "model spec '" + std::string(spec) + "': sd twice");
      m.sunDiffuseGain = v;
    } else if (key == "a" && number && v > 0 && v <= 1) {
      if (m.octaveExtinction) return fail(ErrorCode::InvalidArgument, "model spec '" + std::string(spec) + "': a twice");
      m.octaveExtinction = v;
    } else if (key == "c" && number && v >= 0 && v <= 1) {
      if (m.octaveEccentricity)
        return fail(ErrorCode::InvalidArgument, "model spec '" + std::string(spec) + "': c twice");
      m.octaveEccentricity = v;
    } else {
      return fail(ErrorCode::InvalidArgument, "model spec '" + std::string(spec) + "': '" + std::string(part) +
                                                  "' is not b=<0-1>, a=<(0,1]>, c=<0-1> or sd=<0-2>");
    }
    start = end + 1;
  }
  return m;
}

TruthDistance truthDistance(const std::vector<float>& rgba, const TruthImage& truth) {
  const std::size_t n = std::min(rgba.size(), truth.image.rgba.size()) / 4;
  double squares = 0, noise = 0, a = 0, t = 0;
  for (std::size_t i = 0; i < n; ++i) {
    const double ya = (rgba[i * 4] + rgba[i * 4 + 1] + rgba[i * 4 + 2]) / 3.0;
    const double yt = (truth.image.rgba[i * 4] + truth.image.rgba[i * 4 + 1] + truth.image.rgba[i * 4 + 2]) / 3.0;
    squares += (ya - yt) * (ya - yt);
    noise += i < truth.error.size() ? double(truth.error[i]) * truth.error[i] : 0.0;
    a += ya;
    t += yt;
  }
  TruthDistance d;
  if (n == 0) return d;
  d.rmse = std::sqrt(std::max(0.0, (squares - noise) / double(n)));
  d.meanRatio = t > 0 ? a / t : 0.0;
  return d;
}

Result<TruthImage> pathTruth(const LoadedScene& scene, const Configuration& reference, std::uint32_t width,
                             std::uint32_t height, const TruthOptions& options,
                             const std::function<void(const std::string&)>& log) {
  const render::RenderSettings settings = settingsFor(reference, width, height, scene.scene.verticalFov_deg);
  auto tracer = render::PathTracer::create(settings);
  if (!tracer) return tl::unexpected(tracer.error());
  const std::string key = stateKey(scene, width, height, options, settings);
  const std::string stem = scene.scene.name + "-" + std::to_string(width) + "x" + std::to_string(height);
  std::filesystem::path statePath;
  render::PathTraceState state;
  if (!options.stateDir.empty()) {
    std::error_code ec;
    std::filesystem::create_directories(options.stateDir, ec);
    if (ec) return fail(ErrorCode::Io, options.stateDir + ": " + ec.message());
    statePath = std::filesystem::path(options.stateDir) / (stem + ".state");
    if (std::filesystem::exists(statePath)) {
      auto loaded = render::PathTraceState::load(statePath.string(), key);
      if (!loaded) return tl::unexpected(loaded.error());
      state = std::move(*loaded);
      if (log) log(stem + " truth: resumed at " + std::to_string(state.samples) + " samples per pixel");
    }
  }
  state.key = key;  // a fresh state is of this frame; a loaded one was checked to be
  const render::FrameInputs inputs = frameInputs(scene, 0);
  const auto start = Clock::now();
  TruthImage out;
  // Passes of 1, 3, 12, 48, ... samples: 1, 4, 16, 64 in all, each pass
  // halving the noise of the last.
  while (state.samples < options.samplesPerPixel) {
    const std::uint64_t target = std::min<std::uint64_t>(options.samplesPerPixel, std::max<std::uint64_t>(1, state.samples * 4));
    render::PathTraceOptions po;
    po.samplesPerPixel = std::uint32_t(target - state.samples);
    po.threads = options.threads;
    po.maxEvents = options.maxEvents;
    const auto passStart = Clock::now();
    po.progress = [&](std::uint32_t rows, std::uint32_t all) {
      if (!log || (rows % std::max(1u, all / 4) != 0 && rows != all)) return;
      const double spent = std::chrono::duration<double>(Clock::now() - passStart).count();
      const double rate = rows / std::max(spent, 1e-9);
      log(stem + " truth: pass to " + std::to_string(target) + " spp, rows " + std::to_string(rows) + "/" +
          std::to_string(all) + ", " + fixed(rate * 60.0, 1) + " rows/min, " + fixed((all - rows) / rate, 0) +
          " s left in the pass");
    };
    if (auto ok = tracer->render(inputs, po, state); !ok) return tl::unexpected(ok.error());
    if (!statePath.empty())
      if (auto ok = state.save(statePath.string()); !ok) return tl::unexpected(ok.error());
  }
  out.seconds = std::chrono::duration<double>(Clock::now() - start).count();
  out.image = state.mean();
  out.error = state.standardError();
  out.samples = state.samples;
  out.violations = state.violations;
  double rel = 0.0;
  const std::size_t n = std::size_t(width) * height;
  for (std::size_t i = 0; i < n; ++i) {
    const double m = (out.image.rgba[i * 4] + out.image.rgba[i * 4 + 1] + out.image.rgba[i * 4 + 2]) / 3.0;
    rel += out.error[i] / std::max(m, 1e-3);
  }
  out.meanRelativeError = n > 0 ? rel / double(n) : 0.0;
  if (log)
    log(stem + " truth: " + std::to_string(out.samples) + " samples per pixel, mean relative standard error " +
        fixed(100.0 * out.meanRelativeError, 2) + " %, " + std::to_string(out.violations) +
        " majorant violations, " + fixed(out.seconds, 1) + " s");
  return out;
}

}  // namespace sky::bench
