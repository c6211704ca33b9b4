// The bench's report files from a run's results: results.json (everything,
// per-frame times included), results.md (one table per resolution), and per
// scene a plot of frame time against error (gnuplot, when installed).
#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include "sky/bench/results.hpp"
#include "sky/core/result.hpp"

namespace sky::bench {

// JSON of the whole report; non-finite numbers (PSNR of identical images) are null.
std::string reportJson(const BenchReport& report);

// Markdown: the machine, how it was timed, then a table per resolution.
std::string reportMarkdown(const BenchReport& report);

// Writes outDir/plots/<scene>-<W>x<H>.{dat,gp} and runs gnuplot on each
// script to make the PNG: median wall ms (log scale) against 1 - SSIM and
// against linear RMSE, one labelled point per configuration. Returns the PNG
// files made. Without gnuplot on PATH the scripts are still written and the
// error is Unsupported; Io when a file cannot be written or gnuplot fails.
Result<std::vector<std::string>> writePlots(const BenchReport& report, const std::filesystem::path& outDir);

// Writes results.json and results.md into outDir. Errors: Io.
Result<void> writeReport(const BenchReport& report, const std::filesystem::path& outDir);

}  // namespace sky::bench
