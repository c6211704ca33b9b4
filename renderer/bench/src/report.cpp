// Report files of a bench run (see report.hpp).
#include "sky/bench/report.hpp"

#include <fcntl.h>
#include <spawn.h>
#include <sys/wait.h>

#include <cmath>
#include <fstream>
#include <map>
#include <set>
#include <sstream>

#include <nlohmann/json.hpp>

extern char** environ;

namespace sky::bench {

namespace {

using nlohmann::json;

json number(double v) { return std::isfinite(v) ? json(v) : json(nullptr); }
json number(const std::optional<double>& v) { return v ? number(*v) : json(nullptr); }

json spreadJson(const Spread& s) {
  return {{"samples", s.samples}, {"median", s.median}, {"min", s.min}, {"max", s.max}, {"p10", s.p10}, {"p90", s.p90}};
}

json errorJson(const ErrorSummary& e) {
  return {{"rmse_linear", number(e.rmseLinear)}, {"psnr_db", number(e.psnr_dB)}, {"ssim", number(e.ssim)}};
}

std::string key(const CaseResult& c) { return c.scene + "/" + std::to_string(c.width) + "x" + std::to_string(c.height); }

// Median wall ms of reference per scene and resolution.
std::map<std::string, double> referenceTimes(const BenchReport& report) {
  std::map<std::string, double> out;
  for (const CaseResult& c : report.cases)
    if (c.configuration == "reference") out[key(c)] = c.wall_ms.median;
  return out;
}

std::optional<double> speedup(const std::map<std::string, double>& refs, const CaseResult& c) {
  const auto it = refs.find(key(c));
  if (it == refs.end() || c.wall_ms.median <= 0) return std::nullopt;
  return it->second / c.wall_ms.median;
}

std::string fixed(double v, int digits) {
  if (!std::isfinite(v)) return v > 0 ? "∞" : "n/a";
  std::ostringstream s;
  s.setf(std::ios::fixed);
  s.precision(digits);
  s << v;
  return s.str();
}
std::string fixed(const std::optional<double>& v, int digits) { return v ? fixed(*v, digits) : "n/a"; }

Result<void> writeFile(const std::filesystem::path& path, const std::string& text) {
  std::ofstream out(path, std::ios::binary);
  out << text;
  out.close();
  if (!out) return fail(ErrorCode::Io, path.string() + ": cannot write");
  return {};
}

// Runs `gnuplot script` without a shell, its output appended to logFile.
Result<void> runGnuplot(const std::filesystem::path& script, const std::filesystem::path& logFile) {
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_addopen(&actions, 1, logFile.c_str(), O_WRONLY | O_CREAT | O_APPEND, 0644);
  posix_spawn_file_actions_adddup2(&actions, 1, 2);
  std::string prog = "gnuplot", arg = script.string();
  char* argv[] = {prog.data(), arg.data(), nullptr};
  pid_t pid = 0;
  const int rc = posix_spawnp(&pid, "gnuplot", &actions, nullptr, argv, environ);
  posix_spawn_file_actions_destroy(&actions);
  if (rc != 0) return fail(ErrorCode::Unsupported, "gnuplot not found on PATH (deploy/setup installs gnuplot-nox)");
  int status = 0;
  if (waitpid(pid, &status, 0) < 0 || !WIFEXITED(status))
    return fail(ErrorCode::Io, "gnuplot " + arg + " did not finish");
  if (WEXITSTATUS(status) == 127)
    return fail(ErrorCode::Unsupported, "gnuplot not found on PATH (deploy/setup installs gnuplot-nox)");
  if (WEXITSTATUS(status) != 0)
    return fail(ErrorCode::Io, "gnuplot " + arg + " failed (see " + logFile.string() + ")");
  return {};
}

}  // namespace

std::string reportJson(const BenchReport& report) {
  const auto refs = referenceTimes(report);
  json variants = json::array();
  for (const ModelVariantResult& v : report.modelVariants)
    variants.push_back({{"scene", v.scene},
                        {"variant", v.variant},
                        {"width", v.width},
                        {"height", v.height},
                        {"error", errorJson(v.error)},
                        {"mean_ratio", number(v.meanRatio)},
                        {"rmse_denoised", number(v.rmse)}});
  json cases = json::array();
  for (const CaseResult& c : report.cases) {
    json frames = json::array();
    for (const FrameTiming& f : c.frames)
      frames.push_back({{"wall_ms", f.wall_ms},
                        {"gpu_ms", number(f.gpu_ms)},
                        {"cpu_ms", f.cpu_ms},
                        {"max_thread_ms", f.maxThread_ms},
                        {"lookups", f.lookups ? json(*f.lookups) : json(nullptr)},
                        {"passes_ms", f.passes_ms}});
    json temporal = nullptr;
    if (c.temporal) {
      json ghosting = json::array();
      for (const auto& g : c.temporal->ghosting) ghosting.push_back(number(g));
      temporal = {{"mean_flicker", c.temporal->meanFlicker},
                  {"max_flicker", c.temporal->maxFlicker},
                  {"mean_ghosting", number(c.temporal->meanGhosting)},
                  {"max_ghosting", number(c.temporal->maxGhosting)},
                  {"flicker", c.temporal->flicker},
                  {"ghosting", ghosting}};
    }
    json truth = nullptr;
    if (c.truthError)
      truth = {{"error", errorJson(*c.truthError)},
               {"samples_per_pixel", c.truthSamples},
               {"rmse_denoised", number(c.truthRmse)},
               {"mean_ratio", number(c.truthMeanRatio)},
               {"mean_relative_standard_error", c.truthRelativeError}};
    cases.push_back({{"truth", truth},
                     {"scene", c.scene},
                     {"configuration", c.configuration},
                     {"path", c.path},
                     {"width", c.width},
                     {"height", c.height},
                     {"render_width", c.renderWidth},
                     {"render_height", c.renderHeight},
                     {"create_ms", c.create_ms},
                     {"wall_ms", spreadJson(c.wall_ms)},
                     {"gpu_ms", c.gpu_ms ? spreadJson(*c.gpu_ms) : json(nullptr)},
                     {"pass_median_ms", c.passMedian_ms},
                     {"cpu_ms", spreadJson(c.cpu_ms)},
                     {"max_thread_ms", spreadJson(c.maxThread_ms)},
                     {"cores", number(c.wall_ms.median > 0 ? c.cpu_ms.median / c.wall_ms.median : NAN)},
                     {"speedup_vs_reference", number(speedup(refs, c))},
                     {"lookups_per_s", number(c.lookupsPerSecond)},
                     {"error", errorJson(c.error)},
                     {"worst", errorJson(c.worst)},
                     {"worst_frame", c.worstFrame},
                     {"temporal", temporal},
                     {"non_finite_pixels", c.nonFinitePixels},
                     {"repeatable", c.repeatable},
                     {"contact_sheet", c.contactSheet},
                     {"frames", frames}});
  }
  const MachineInfo& m = report.machine;
  json out = {{"machine",
               {{"device", m.device},
                {"cpu", m.cpu},
                {"cores", m.cores},
                {"lp_num_threads", m.lpNumThreads},
                {"load_average_start", m.loadAverageStart},
                {"load_average_end", m.loadAverageEnd},
                {"started", m.started}}},
              {"timing_source", report.timingSource},
              {"warmup", report.warmup},
              {"repeats", report.repeats},
              {"path_repeats", report.pathRepeats},
              {"cases", cases},
              {"model_variants", variants}};
  return out.dump(2) + "\n";
}

std::string reportMarkdown(const BenchReport& report) {
  const auto refs = referenceTimes(report);
  const MachineInfo& m = report.machine;
  std::ostringstream md;
  md << "# skyshell-bench results\n\n"
     << "* started " << m.started << " on " << m.cpu << " (" << m.cores << " CPUs), device " << m.device
     << ", LP_NUM_THREADS " << m.lpNumThreads << "\n"
     << "* load average (1/5/15 min) " << m.loadAverageStart << " at the start, " << m.loadAverageEnd
     << " at the end\n"
     << "* " << report.timingSource << "\n"
     << "* " << report.warmup << " warm-up frames per case, then " << report.repeats << " timed renders of each still, "
     << report.pathRepeats << " timed run(s) of each camera path; error against `reference` at the same resolution "
     << "(paths: mean over frames; a path's contact sheet shows each configuration's worst frame (lowest SSIM) with that frame's SSIM and PSNR)\n\n";
  std::set<std::pair<std::uint32_t, std::uint32_t>> sizes;
  for (const CaseResult& c : report.cases) sizes.insert({c.width, c.height});
  for (const auto& [w, h] : sizes) {
    md << "## " << w << "x" << h << "\n\n"
       << "| scene | configuration | wall ms median [min, max] | GPU ms | cores | M lookups/s | speed-up | RMSE linear | "
          "PSNR dB | SSIM | flicker | ghosting | contact sheet |\n"
       << "|---|---|---|---|---|---|---|---|---|---|---|---|---|\n";
    for (const CaseResult& c : report.cases) {
      if (c.width != w || c.height != h) continue;
      md << "| " << c.scene << (c.path ? " (path)" : "") << " | " << c.configuration
         << (c.renderWidth != c.width ? " (" + std::to_string(c.renderWidth) + "x" + std::to_string(c.renderHeight) + ")"
                                      : "")
         << " | " << fixed(c.wall_ms.median, 2) << " [" << fixed(c.wall_ms.min, 2) << ", " << fixed(c.wall_ms.max, 2)
         << "] | " << (c.gpu_ms ? fixed(c.gpu_ms->median, 2) : "n/a") << " | "
         << fixed(c.wall_ms.median > 0 ? c.cpu_ms.median / c.wall_ms.median : NAN, 2) << " | "
         << (c.lookupsPerSecond ? fixed(*c.lookupsPerSecond * 1e-6, 1) : "n/a") << " | " << fixed(speedup(refs, c), 2) << "x | " << fixed(c.error.rmseLinear, 4) << " | " << fixed(c.error.psnr_dB, 2)
         << " | " << fixed(c.error.ssim, 4) << " | "
         << (c.temporal ? fixed(c.temporal->meanFlicker, 2) : "") << " | "
         << (c.temporal ? fixed(c.temporal->meanGhosting, 3) : "") << " | [sheet](" << c.contactSheet << ") |";
      if (c.nonFinitePixels) md << " **" << c.nonFinitePixels << " non-finite pixels**";
      if (!c.repeatable) md << " **repeats differ**";
      md << "\n";
    }
    md << "\n";
  }
  bool anyTruth = false;
  for (const CaseResult& c : report.cases) anyTruth = anyTruth || c.truthError.has_value();
  if (anyTruth) {
    md << "## Against the path-traced truth (`--truth path`)\n\n"
       << "Each still against its frame path-traced with every order of scattering (renderer/core/src/path_tracer.cpp); "
          "the truth's own noise is its mean relative standard error per pixel. `reference` here is the model's "
          "own error; the other rows add what each preset loses. RMSE of the rgb mean: with the truth's noise taken "
          "out (sqrt(max(0, mean squared difference - mean squared standard error))); the RMSE, PSNR and SSIM after "
          "it include the truth's noise.\n\n"
       << "| scene | size | configuration | RMSE of the rgb mean | mean / truth's | RMSE linear | PSNR dB | SSIM | vs reference: RMSE | truth spp | truth noise | sheet |\n"
       << "|---|---|---|---|---|---|---|---|---|---|---|---|\n";
    for (const CaseResult& c : report.cases) {
      if (!c.truthError) continue;
      md << "| " << c.scene << " | " << c.width << "x" << c.height << " | " << c.configuration << " | "
         << fixed(c.truthRmse, 4) << " | " << fixed(c.truthMeanRatio, 3) << " | " << fixed(c.truthError->rmseLinear, 4) << " | " << fixed(c.truthError->psnr_dB, 2) << " | "
         << fixed(c.truthError->ssim, 4) << " | " << fixed(c.error.rmseLinear, 4) << " | " << c.truthSamples << " | "
         << fixed(100.0 * c.truthRelativeError, 2) << " % | [sheet](contact/" << c.scene << "-" << c.width << "x"
         << c.height << "-truth.png) |\n";
    }
    md << "\n";
    md << "### What each part of the model brings\n\n"
       << "The CPU reference (the model in double, the `reference` settings) with one part switched off at a time "
          "(render::ModelSwitches), against the same truth; mean: the image's mean over the truth's.\n\n"
       << "| scene | size | model | RMSE of the rgb mean | mean / truth's | RMSE linear | PSNR dB | SSIM |\n|---|---|---|---|---|---|---|---|\n";
    for (const ModelVariantResult& v : report.modelVariants)
      md << "| " << v.scene << " | " << v.width << "x" << v.height << " | " << v.variant << " | " << fixed(v.rmse, 4)
         << " | " << fixed(v.meanRatio, 3) << " | " << fixed(v.error.rmseLinear, 4) << " | "
         << fixed(v.error.psnr_dB, 2) << " | " << fixed(v.error.ssim, 4) << " |\n";
    md << "\n";
  }
  md << "Flicker: RMS change of the error between consecutive frames (8-bit levels); ghosting: share of the previous "
        "frame left in a frame (0 none, 1 all), against the configuration's own history-free frames (0 for "
        "configurations that reuse no history). Definitions: renderer/bench/include/sky/bench/metrics.hpp.\n";
  return md.str();
}

Result<std::vector<std::string>> writePlots(const BenchReport& report, const std::filesystem::path& outDir) {
  const std::filesystem::path dir = std::filesystem::absolute(outDir / "plots");
  std::error_code ec;
  std::filesystem::create_directories(dir, ec);
  if (ec) return fail(ErrorCode::Io, dir.string() + ": " + ec.message());
  std::map<std::string, std::vector<const CaseResult*>> byScene;
  for (const CaseResult& c : report.cases)
    byScene[c.scene + "-" + std::to_string(c.width) + "x" + std::to_string(c.height)].push_back(&c);
  std::vector<std::string> pngs;
  std::optional<Error> firstError;
  for (const auto& [stem, cases] : byScene) {
    std::ostringstream dat;
    dat << "# configuration  median_wall_ms  one_minus_ssim  rmse_linear\n";
    for (const CaseResult* c : cases)
      dat << '"' << c->configuration << "\" " << c->wall_ms.median << ' ' << (1.0 - c->error.ssim) << ' '
          << c->error.rmseLinear << "\n";
    const auto datFile = dir / (stem + ".dat"), gpFile = dir / (stem + ".gp"), pngFile = dir / (stem + ".png");
    std::ostringstream gp;
    gp << "# skyshell-bench: time against error for " << stem << "; run: gnuplot " << gpFile.filename().string() << "\n"
       << "set terminal pngcairo size 1100,440 font ',10'\n"
       << "set output '" << pngFile.string() << "'\n"
       << "set multiplot layout 1,2 title '" << stem << ": median wall time per frame against error, one point per "
       << "configuration (lower left is better)'\n"
       << "set logscale x\nset grid\nset offsets graph 0.15, graph 0.15, graph 0.1, graph 0.1\n"
       << "set xlabel 'median wall ms per frame'\n"
       << "set ylabel '1 - SSIM'\n"
       << "plot '" << datFile.string() << "' using 2:3 with points pt 7 ps 1.3 notitle, '' using 2:3:1 with labels "
       << "offset 1,0.6 left notitle\n"
       << "set ylabel 'RMSE of linear radiance'\n"
       << "plot '" << datFile.string() << "' using 2:4 with points pt 7 ps 1.3 notitle, '' using 2:4:1 with labels "
       << "offset 1,0.6 left notitle\n"
       << "unset multiplot\n";
    if (auto ok = writeFile(datFile, dat.str()); !ok) return tl::unexpected(ok.error());
    if (auto ok = writeFile(gpFile, gp.str()); !ok) return tl::unexpected(ok.error());
    if (firstError) continue;
    if (auto ok = runGnuplot(gpFile, dir / "gnuplot.log"); !ok) {
      firstError = ok.error();
      continue;
    }
    pngs.push_back("plots/" + pngFile.filename().string());
  }
  if (firstError) return tl::unexpected(*firstError);
  return pngs;
}

Result<void> writeReport(const BenchReport& report, const std::filesystem::path& outDir) {
  if (auto ok = writeFile(outDir / "results.json", reportJson(report)); !ok) return ok;
  return writeFile(outDir / "results.md", reportMarkdown(report));
}

}  // namespace sky::bench
