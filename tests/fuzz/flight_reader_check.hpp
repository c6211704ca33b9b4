// What every flight reader's fuzz target checks of one parse: a flight or an
// error, never a crash; nothing from the input reaches a message raw (every
// error and warning is well-formed UTF-8); a flight it returns keeps the
// documented invariants (two or more fixes, increasing time). A broken
// promise aborts, which libFuzzer reports with the input.
#pragma once

#include <cstddef>
#include <cstdlib>

#include "sky/flight/flight.hpp"
#include "sky/flight/utf8_text.hpp"

namespace sky::fuzz {

inline void checkFlightParse(const Result<flight::ParsedFlight>& parsed) {
  if (!parsed && flight::firstInvalidUtf8(parsed.error().detail)) std::abort();
  if (!parsed) return;
  for (const auto& w : parsed->warnings)
    if (flight::firstInvalidUtf8(w)) std::abort();
  if (parsed->fixes.size() < 2) std::abort();
  for (std::size_t i = 1; i < parsed->fixes.size(); ++i)
    if (!(parsed->fixes[i].time_s > parsed->fixes[i - 1].time_s)) std::abort();
}

}  // namespace sky::fuzz
