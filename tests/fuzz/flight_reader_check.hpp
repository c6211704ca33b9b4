// What every flight reader's fuzz target checks of one parse: a flight or an
// error, never a crash; nothing from the input reaches a message raw (every
// error and warning is well-formed UTF-8); a flight it returns keeps the
// documented invariants (two or more fixes, increasing time); the cleaning
// (clean.hpp) run on what it parsed, holding a long gap and ending at one,
// keeps them too and reports (and --info describes) in well-formed UTF-8.
// A broken promise aborts, which libFuzzer reports with the input.
#pragma once

#include <cstddef>
#include <cstdlib>

#include "sky/flight/clean.hpp"
#include "sky/flight/flight.hpp"
#include "sky/flight/info.hpp"
#include "sky/flight/utf8_text.hpp"

namespace sky::fuzz {

inline void checkFlightInvariants(const flight::ParsedFlight& f) {
  if (f.fixes.size() < 2) std::abort();
  if (!f.fixLines.empty() && f.fixLines.size() != f.fixes.size()) std::abort();
  for (std::size_t i = 1; i < f.fixes.size(); ++i)
    if (!(f.fixes[i].time_s > f.fixes[i - 1].time_s)) std::abort();
}

inline void checkCleaning(flight::ParsedFlight f, const flight::CleanOptions& options) {
  const std::size_t before = f.fixes.size();
  const auto report = flight::clean(f, options, "fuzz");
  if (!report) {
    if (flight::firstInvalidUtf8(report.error().detail)) std::abort();
    return;
  }
  checkFlightInvariants(f);
  if (report->input != before || report->kept > before) std::abort();
  for (const auto& line : report->lines(options))
    if (flight::firstInvalidUtf8(line)) std::abort();
  for (const auto& line : flight::describeFlight(f, "fuzz", &*report, options))
    if (flight::firstInvalidUtf8(line)) std::abort();
}

inline void checkFlightParse(const Result<flight::ParsedFlight>& parsed) {
  if (!parsed && flight::firstInvalidUtf8(parsed.error().detail)) std::abort();
  if (!parsed) return;
  for (const auto& w : parsed->warnings)
    if (flight::firstInvalidUtf8(w)) std::abort();
  checkFlightInvariants(*parsed);
  checkCleaning(*parsed, {});
  checkCleaning(*parsed, {50.0, 2.0, flight::LongGap::End});
}

}  // namespace sky::fuzz
