// The readers' warnings as the flight tests look at them.
#pragma once

#include <algorithm>
#include <string>

#include "sky/flight/flight.hpp"

namespace sky::flight {

// Whether any warning holds needle.
inline bool anyWarningHas(const ParsedFlight& f, const std::string& needle) {
  return std::any_of(f.warnings.begin(), f.warnings.end(),
                     [&](const std::string& w) { return w.find(needle) != std::string::npos; });
}

// Every warning, one a line (for a failure's message).
inline std::string allWarnings(const ParsedFlight& f) {
  std::string out;
  for (const auto& w : f.warnings) out += w + "\n";
  return out;
}

}  // namespace sky::flight
