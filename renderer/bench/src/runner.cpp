// The bench run (see runner.hpp): renders, times, compares, and writes each
// scene's images and contact sheet.
#include "sky/bench/runner.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <ctime>
#include <fstream>
#include <limits>
#include <sstream>
#include <thread>

#include "sky/bench/contact_sheet.hpp"
#include "sky/bench/cpu_time.hpp"
#include "sky/bench/display.hpp"
#include "sky/bench/driver_pin.hpp"
#include "sky/bench/renderer_probe.hpp"
#include "sky/render/cpu_reference.hpp"

namespace sky::bench {

namespace {

// `reference` takes 65 s a frame on overcast-below at 640x360 on lavapipe (2
// cores), past the renderer's default of a minute; the bench waits for it.
render::GpuOptions benchGpu() {
  render::GpuOptions gpu;
  gpu.frameTimeout = std::chrono::minutes(30);
  return gpu;
}

using Clock = std::chrono::steady_clock;

double msBetween(Clock::time_point a, Clock::time_point b) {
  return std::chrono::duration<double, std::milli>(b - a).count();
}

struct Rendered {
  render::Image image;
  FrameTiming timing;
};

Result<Rendered> timedRender(render::CloudRenderer& renderer, const render::FrameInputs& inputs) {
  const CpuSnapshot before = sampleCpu();
  const auto t0 = Clock::now();
  auto image = renderer.render(inputs);
  const auto t1 = Clock::now();
  const CpuSnapshot after = sampleCpu();
  if (!image) return tl::unexpected(image.error());
  Rendered out{std::move(*image), {}};
  out.timing.wall_ms = msBetween(t0, t1);
  const CpuUse use = cpuBetween(before, after);
  out.timing.cpu_ms = use.cpu_ms;
  out.timing.maxThread_ms = use.maxThread_ms;
  const RendererCounters counters = rendererCounters(renderer, out.image);
  out.timing.gpu_ms = counters.gpuCloud_ms;
  out.timing.lookups = counters.densityLookups;
  out.timing.passes_ms = counters.passes_ms;
  return out;
}

// The reference's frames of one scene at one resolution.
struct ReferenceFrames {
  std::vector<std::vector<float>> linear;
  std::vector<Srgb8Image> srgb;
  double medianWall_ms = 0;
  // A still's path-traced truth (--truth path), when asked.
  std::optional<TruthImage> truth;
  Srgb8Image truthSrgb;
};

// What a case keeps for the temporal error and the contact sheet.
struct KeptFrames {
  std::vector<Srgb8Image> srgb;
};

std::string fixed(double v, int digits) {
  if (!std::isfinite(v)) return v > 0 ? "inf" : "nan";
  std::ostringstream s;
  s.setf(std::ios::fixed);
  s.precision(digits);
  s << v;
  return s.str();
}

// A rendered image's linear rgba at the output size (a configuration with a
// render scale is resized bilinearly, display.hpp).
std::vector<float> atOutputSize(const render::Image& image, const Resolution& res) {
  if (image.width == res.width && image.height == res.height) return image.rgba;
  return resizeBilinear({image.width, image.height, image.rgba}, res.width, res.height);
}

std::string sizeName(std::uint32_t w, std::uint32_t h) { return std::to_string(w) + "x" + std::to_string(h); }

Result<CaseResult> runCase(const LoadedScene& ls, const Configuration& config, const Resolution& res,
                           const RunOptions& options, ReferenceFrames& reference, KeptFrames& kept,
                           std::string& deviceName) {
  const Scene& scene = ls.scene;
  const bool isReference = config.name == kReferenceName;
  CaseResult cr;
  cr.scene = scene.name;
  cr.configuration = config.name;
  cr.path = scene.isPath();
  cr.width = res.width;
  cr.height = res.height;
  const render::RenderSettings settings = settingsFor(config, res.width, res.height, scene.verticalFov_deg);
  cr.renderWidth = settings.width;
  cr.renderHeight = settings.height;

  const auto c0 = Clock::now();
  auto renderer = render::CloudRenderer::create(settings, benchGpu());
  if (!renderer) return tl::unexpected(renderer.error());
  cr.create_ms = msBetween(c0, Clock::now());
  deviceName = (*renderer)->deviceName();
  keepVulkanDriversLoaded();
  // A configuration that reuses history starts with it full (the first view
  // held still, as a simulator sits before it moves), so a still scene shows
  // the converged image and its steady per-frame cost.
  const std::uint32_t warmup =
      options.historyWarmup ? std::max(options.warmup, render::historyWarmupFrames(settings.temporal)) : options.warmup;
  for (std::uint32_t i = 0; i < warmup; ++i)
    if (auto warm = (*renderer)->render(frameInputs(ls, 0)); !warm) return tl::unexpected(warm.error());

  const std::uint32_t frames = cr.path ? scene.frames : 1;
  const std::uint32_t repeats = std::max(1u, cr.path ? options.pathRepeats : options.repeats);
  std::vector<float> firstStill;
  double mseSum = 0, rmseSum = 0, ssimSum = 0;
  cr.worst.psnr_dB = std::numeric_limits<double>::infinity();
  cr.worst.rmseLinear = 0;
  // A long case (a path's reference at a large size takes minutes, an hour
  // on a loaded machine) says how far it is, at most every kProgressEvery_ms.
  constexpr double kProgressEvery_ms = 30000;
  const auto caseStart = Clock::now();
  auto lastProgress = caseStart;
  for (std::uint32_t rep = 0; rep < repeats; ++rep)
    for (std::uint32_t f = 0; f < frames; ++f) {
      auto rendered = timedRender(**renderer, frameInputs(ls, f));
      if (!rendered) return tl::unexpected(rendered.error());
      cr.frames.push_back(rendered->timing);
      if (const std::uint32_t done = rep * frames + f + 1, total = repeats * frames;
          options.log && done < total && msBetween(lastProgress, Clock::now()) >= kProgressEvery_ms) {
        lastProgress = Clock::now();
        const double perFrame_s = msBetween(caseStart, lastProgress) / 1000.0 / done;
        char line[160];
        std::snprintf(line, sizeof line, "%s-%s %s: frame %u of %u, %.1f s a frame, about %.0f s left",
                      scene.name.c_str(), sizeName(res.width, res.height).c_str(), config.name.c_str(), done, total,
                      perFrame_s, perFrame_s * (total - done));
        options.log(line);
      }
      if (rep > 0) {
        const auto& px = rendered->image.rgba;
        if (!cr.path && (px.size() != firstStill.size() ||
                         std::memcmp(px.data(), firstStill.data(), px.size() * sizeof(float)) != 0))
          cr.repeatable = false;
        continue;
      }
      cr.nonFinitePixels += render::computeStats(rendered->image).nonFinite;
      std::vector<float> linear = atOutputSize(rendered->image, res);
      if (!cr.path) firstStill = rendered->image.rgba;
      Srgb8Image srgb = toSrgb8({res.width, res.height, linear});
      if (isReference) {
        reference.linear.push_back(linear);
        reference.srgb.push_back(srgb);
      }
      auto rmse = rmseLinear({res.width, res.height, linear}, {res.width, res.height, reference.linear[f]});
      auto r8 = rmse8(srgb, reference.srgb[f]);
      auto p = psnr(srgb, reference.srgb[f]);
      auto s = ssim(srgb, reference.srgb[f]);
      if (!rmse || !r8 || !p || !s) return fail(ErrorCode::InvalidArgument, scene.name + ": cannot compare images");
      if (reference.truth && !cr.path) {
        const std::vector<float>& truth = reference.truth->image.rgba;
        auto tr = rmseLinear({res.width, res.height, linear}, {res.width, res.height, truth});
        auto tp = psnr(srgb, reference.truthSrgb);
        auto ts = ssim(srgb, reference.truthSrgb);
        if (!tr || !tp || !ts) return fail(ErrorCode::InvalidArgument, scene.name + ": cannot compare with the truth");
        cr.truthError = ErrorSummary{*tr, *tp, *ts};
        cr.truthSamples = reference.truth->samples;
        cr.truthRelativeError = reference.truth->meanRelativeError;
        const TruthDistance d = truthDistance(linear, *reference.truth);
        cr.truthRmse = d.rmse;
        cr.truthMeanRatio = d.meanRatio;
      }
      rmseSum += *rmse;
      mseSum += *r8 * *r8;
      ssimSum += *s;
      cr.worst.rmseLinear = std::max(cr.worst.rmseLinear, *rmse);
      cr.worst.psnr_dB = std::min(cr.worst.psnr_dB, *p);
      if (f == 0 || *s < cr.worst.ssim) cr.worstFrame = f;
      cr.worst.ssim = std::min(cr.worst.ssim, *s);
      kept.srgb.push_back(std::move(srgb));
    }
  cr.error.rmseLinear = rmseSum / frames;
  cr.error.ssim = ssimSum / frames;
  const double mse = mseSum / frames;  // PSNR of the MSE pooled over the path's frames
  cr.error.psnr_dB = mse == 0 ? std::numeric_limits<double>::infinity() : 10 * std::log10(255.0 * 255.0 / mse);
  if (!cr.path) cr.worst = cr.error;
  if (cr.path) {
    // temporalBaseline: a configuration without history is its own baseline;
    // one with history is compared with the same configuration drawing every
    // pixel of every frame (metrics.hpp, ghosting).
    std::vector<Srgb8Image> historyFree;
    if (config.reusesHistory()) {
      render::RenderSettings whole = settings;
      whole.temporal = {};
      auto plain = render::CloudRenderer::create(whole, benchGpu());
      if (!plain) return tl::unexpected(plain.error());
      for (std::uint32_t f = 0; f < frames; ++f) {
        auto image = (*plain)->render(frameInputs(ls, f));
        if (!image) return tl::unexpected(image.error());
        historyFree.push_back(toSrgb8({res.width, res.height, atOutputSize(*image, res)}));
      }
    }
    const std::span<const Srgb8Image> baseline =
        config.reusesHistory() ? std::span<const Srgb8Image>(historyFree) : std::span<const Srgb8Image>(kept.srgb);
    auto te = temporalError(kept.srgb, reference.srgb, baseline);
    if (!te) return tl::unexpected(te.error());
    cr.temporal = std::move(*te);
  }

  std::vector<double> wall, cpu, busiest, gpu;
  double lookups = 0, gpuTotal_ms = 0;
  bool allLookups = true;
  for (const FrameTiming& t : cr.frames) {
    wall.push_back(t.wall_ms);
    cpu.push_back(t.cpu_ms);
    busiest.push_back(t.maxThread_ms);
    if (t.gpu_ms) gpu.push_back(*t.gpu_ms), gpuTotal_ms += *t.gpu_ms;
    if (t.lookups) lookups += double(*t.lookups);
    allLookups = allLookups && t.lookups.has_value();
  }
  cr.wall_ms = spreadOf(wall);
  cr.cpu_ms = spreadOf(cpu);
  cr.maxThread_ms = spreadOf(busiest);
  if (gpu.size() == cr.frames.size()) cr.gpu_ms = spreadOf(gpu);
  std::map<std::string, std::vector<double>> passes;
  for (const FrameTiming& t : cr.frames)
    for (const auto& [pass, ms] : t.passes_ms) passes[pass].push_back(ms);
  for (const auto& [pass, times] : passes) cr.passMedian_ms[pass] = spreadOf(times).median;
  if (cr.gpu_ms && allLookups && gpuTotal_ms > 0) cr.lookupsPerSecond = lookups / (gpuTotal_ms * 1e-3);
  if (isReference) reference.medianWall_ms = cr.wall_ms.median;
  return cr;
}

// Writes each configuration's displayed frame and the scene's contact sheet:
// one row per configuration (its frame, the reference, the error heat map).
// A path's row shows the configuration's worst frame (lowest SSIM) beside
// the reference's same frame: a path's errors come and go, and its last
// frame may be one of its best.
Result<std::string> writeSceneImages(const std::string& stem, const std::vector<CaseResult>& cases,
                                     const std::vector<KeptFrames>& kept, const RunOptions& options,
                                     const ReferenceFrames* truthOf) {
  const std::filesystem::path dir = options.outDir / "contact";
  std::error_code ec;
  std::filesystem::create_directories(dir / "frames", ec);
  if (ec) return fail(ErrorCode::Io, (dir / "frames").string() + ": " + ec.message());
  std::vector<Srgb8Image> heat(cases.size());
  std::vector<std::vector<SheetCell>> rows;
  for (std::size_t i = 0; i < cases.size(); ++i) {
    const std::size_t shown = !cases[i].path ? 0 : i == 0 ? kept[i].srgb.size() - 1 : std::min(cases[i].worstFrame, kept[i].srgb.size() - 1);
    const Srgb8Image& img = kept[i].srgb[shown];
    const Srgb8Image& ref = kept.front().srgb[shown];
    if (auto ok = writePng(img, (dir / "frames" / (stem + "-" + cases[i].configuration + ".png")).string()); !ok)
      return tl::unexpected(ok.error());
    const std::string timeLabel = cases[i].configuration + " " + fixed(cases[i].wall_ms.median, 1) + " MS" +
                                  (cases[i].path && i > 0 ? " FRAME " + std::to_string(shown) : "");
    if (i == 0) {
      rows.push_back({{&img, timeLabel}});
      continue;
    }
    auto map = errorHeatMap(img, ref);
    auto shownSsim = ssim(img, ref);
    auto shownPsnr = psnr(img, ref);
    if (!map || !shownSsim || !shownPsnr) return fail(ErrorCode::InvalidArgument, stem + ": cannot compare images");
    heat[i] = std::move(*map);
    // The metrics of the frame shown (a path's worst), not of the whole path.
    rows.push_back({{&img, timeLabel},
                    {&ref, "REFERENCE"},
                    {&heat[i], "SSIM " + fixed(*shownSsim, 3) + " PSNR " + fixed(*shownPsnr, 1)}});
  }
  if (const ReferenceFrames* r = truthOf; r != nullptr && r->truth) {
    if (auto ok = writePng(r->truthSrgb, (dir / "frames" / (stem + "-truth.png")).string()); !ok)
      return tl::unexpected(ok.error());
    std::vector<Srgb8Image> truthHeat(cases.size());
    std::vector<std::vector<SheetCell>> truthRows;
    const std::string truthLabel = "PATH-TRACED " + std::to_string(r->truth->samples) + " SPP";
    for (std::size_t i = 0; i < cases.size(); ++i) {
      const Srgb8Image& img = kept[i].srgb[0];
      auto map = errorHeatMap(img, r->truthSrgb);
      auto s = ssim(img, r->truthSrgb);
      auto p = psnr(img, r->truthSrgb);
      if (!map || !s || !p) return fail(ErrorCode::InvalidArgument, stem + ": cannot compare with the truth");
      truthHeat[i] = std::move(*map);
      truthRows.push_back({{&img, cases[i].configuration},
                           {&r->truthSrgb, truthLabel},
                           {&truthHeat[i], "SSIM " + fixed(*s, 3) + " PSNR " + fixed(*p, 1)}});
    }
    const std::string truthTitle = stem + " AGAINST THE PATH-TRACED TRUTH - ERROR 0 TO " +
                                   fixed(kHeatMapFullScale, 0) + " LEVELS, BLACK TO WHITE";
    if (auto ok = writePng(contactSheet(truthTitle, truthRows), (dir / (stem + "-truth.png")).string()); !ok)
      return tl::unexpected(ok.error());
  }
  const std::string title = stem + (cases.front().path ? " (EACH ROW AT ITS WORST FRAME)" : "") + " - ERROR 0 TO " +
                            fixed(kHeatMapFullScale, 0) + " LEVELS, BLACK TO WHITE";
  const std::string file = "contact/" + stem + ".png";
  if (auto ok = writePng(contactSheet(title, rows), (options.outDir / file).string()); !ok)
    return tl::unexpected(ok.error());
  return file;
}

// The CPU reference with each part of the light model switched off in
// turn, against the truth: what each part brings.
Result<std::vector<ModelVariantResult>> modelVariants(const LoadedScene& ls, const Configuration& reference,
                                                      const Resolution& res, const TruthImage& truth,
                                                      const Srgb8Image& truthSrgb, const std::vector<double>& octaveWeights,
                                                      const std::vector<std::pair<std::string, render::ModelSwitches>>& models,
                                                      bool parts,
                                                      const std::function<void(const std::string&)>& log) {
  const render::RenderSettings settings = settingsFor(reference, res.width, res.height, ls.scene.verticalFov_deg);
  auto cpu = render::CpuReference::create(settings);
  if (!cpu) return tl::unexpected(cpu.error());
  struct Variant {
    std::string name;
    render::ModelSwitches model;
  };
  std::vector<Variant> variants{
      {"model", {}}, {"no octaves", {}}, {"no ambient", {}}, {"no scattered sun", {}}, {"HG phase", {}}};
  variants[1].model.octaves = false;
  variants[2].model.ambient = false;
  variants[3].model.scatteredSun = false;
  variants[4].model.miePhase = false;
  if (!parts) variants.resize(1);
  for (const double b : octaveWeights) {
    std::ostringstream name;
    name << "octaves b=" << b;
    Variant v{name.str(), {}};
    v.model.octaveContribution = b;
    variants.push_back(v);
  }
  for (const auto& [name, model] : models) variants.push_back({name, model});
  std::vector<ModelVariantResult> out;
  for (const Variant& v : variants) {
    cpu->setModel(v.model);
    auto image = cpu->render(frameInputs(ls, 0));
    if (!image) return tl::unexpected(image.error());
    const Srgb8Image srgb = toSrgb8({res.width, res.height, image->rgba});
    auto r = rmseLinear({res.width, res.height, image->rgba}, {res.width, res.height, truth.image.rgba});
    auto p = psnr(srgb, truthSrgb);
    auto s = ssim(srgb, truthSrgb);
    if (!r || !p || !s) return fail(ErrorCode::InvalidArgument, "cannot compare with the truth");
    ModelVariantResult m;
    m.scene = ls.scene.name;
    m.variant = v.name;
    m.width = res.width;
    m.height = res.height;
    m.error = ErrorSummary{*r, *p, *s};
    const TruthDistance d = truthDistance(image->rgba, truth);
    m.meanRatio = d.meanRatio;
    m.rmse = d.rmse;
    if (log)
      log(ls.scene.name + "-" + sizeName(res.width, res.height) + " CPU " + v.name + " against the truth: RMSE " +
          fixed(m.rmse, 4) + " (the truth's noise taken out), SSIM " + fixed(*s, 4) + ", mean " + fixed(m.meanRatio, 3) + "x the truth's");
    out.push_back(std::move(m));
  }
  return out;
}

std::string readFirstLine(const char* path) {
  std::ifstream in(path);
  std::string line;
  std::getline(in, line);
  return line;
}

}  // namespace

Spread spreadOf(std::vector<double> values) {
  Spread s;
  s.samples = values.size();
  if (values.empty()) return s;
  std::sort(values.begin(), values.end());
  auto rank = [&](double q) { return values[std::min(values.size() - 1, std::size_t(q * double(values.size())))]; };
  const std::size_t n = values.size();
  s.median = n % 2 ? values[n / 2] : 0.5 * (values[n / 2 - 1] + values[n / 2]);
  s.min = values.front();
  s.max = values.back();
  s.p10 = rank(0.1);
  s.p90 = rank(0.9);
  return s;
}

std::string loadAverage() {
  std::istringstream in(readFirstLine("/proc/loadavg"));
  std::string a, b, c;
  in >> a >> b >> c;
  return a + " " + b + " " + c;
}

MachineInfo describeMachine() {
  MachineInfo m;
  std::ifstream cpuinfo("/proc/cpuinfo");
  for (std::string line; std::getline(cpuinfo, line);)
    if (line.rfind("model name", 0) == 0) {
      m.cpu = line.substr(line.find(':') + 2);
      break;
    }
  m.cores = std::thread::hardware_concurrency();
  const char* lp = std::getenv("LP_NUM_THREADS");
  m.lpNumThreads = lp ? lp : "(unset: lavapipe uses one thread per CPU)";
  m.loadAverageStart = loadAverage();
  const std::time_t now = std::time(nullptr);
  char buf[32];
  std::strftime(buf, sizeof buf, "%Y-%m-%dT%H:%M:%SZ", std::gmtime(&now));
  m.started = buf;
  return m;
}

Result<BenchReport> runBench(const std::vector<LoadedScene>& scenes, const RunOptions& options) {
  BenchReport report;
  report.machine = describeMachine();
  report.timingSource = rendererCountersSource();
  report.warmup = options.warmup;
  report.repeats = options.repeats;
  report.pathRepeats = options.pathRepeats;
  auto log = [&](const std::string& line) {
    if (options.log) options.log(line);
  };
  if (options.configurations.empty() || options.configurations.front().name != kReferenceName)
    return fail(ErrorCode::InvalidArgument, "the first configuration must be reference");
  for (const Resolution& res : options.resolutions)
    for (const LoadedScene& ls : scenes) {
      const std::string stem = ls.scene.name + "-" + sizeName(res.width, res.height);
      ReferenceFrames reference;
      if (options.truth.samplesPerPixel > 0 && !ls.scene.isPath()) {
        TruthOptions truthOptions = options.truth;
        if (truthOptions.stateDir.empty()) truthOptions.stateDir = (options.outDir / "truth").string();
        auto truth = pathTruth(ls, options.configurations.front(), res.width, res.height, truthOptions, log);
        if (!truth) return fail(truth.error().code, stem + " truth: " + truth.error().detail);
        reference.truthSrgb = toSrgb8({res.width, res.height, truth->image.rgba});
        auto variants = modelVariants(ls, options.configurations.front(), res, *truth, reference.truthSrgb,
                                      options.truth.octaveWeights, options.truth.models, options.truth.parts, log);
        if (!variants) return fail(variants.error().code, stem + " model variants: " + variants.error().detail);
        for (ModelVariantResult& v : *variants) report.modelVariants.push_back(std::move(v));
        reference.truth = std::move(*truth);
      }
      std::vector<CaseResult> cases;
      std::vector<KeptFrames> kept;
      for (const Configuration& config : options.configurations) {
        KeptFrames frames;
        auto cr = runCase(ls, config, res, options, reference, frames, report.machine.device);
        if (!cr) return fail(cr.error().code, stem + " " + config.name + ": " + cr.error().detail);
        log(stem + " " + config.name + ": " + fixed(cr->wall_ms.median, 2) + " ms median (" +
            fixed(cr->wall_ms.min, 2) + "-" + fixed(cr->wall_ms.max, 2) + ", " + std::to_string(cr->wall_ms.samples) +
            " frames), SSIM " + fixed(cr->error.ssim, 4) + ", PSNR " + fixed(cr->error.psnr_dB, 2) + " dB" +
            (cr->nonFinitePixels ? ", " + std::to_string(cr->nonFinitePixels) + " NON-FINITE PIXELS" : ""));
        cases.push_back(std::move(*cr));
        kept.push_back(std::move(frames));
      }
      auto sheet = writeSceneImages(stem, cases, kept, options, &reference);
      if (!sheet) return tl::unexpected(sheet.error());
      for (CaseResult& c : cases) {
        c.contactSheet = *sheet;
        report.cases.push_back(std::move(c));
      }
    }
  report.machine.loadAverageEnd = loadAverage();
  return report;
}

}  // namespace sky::bench
