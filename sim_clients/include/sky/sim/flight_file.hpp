// Reading a recorded flight from disk: the file I/O half of the flight readers
// in protocol/ (which parse text and open nothing).
#pragma once

#include <string>

#include "sky/core/result.hpp"
#include "sky/flight/flight.hpp"

namespace sky::sim {

// The bytes of a flight file; more than flight::kMaxFlightFileBytes
// (file_limits.hpp) is an error (TooLarge) found without reading further.
Result<std::string> readFlightFile(const std::string& path);

// Reads and parses a flight file; the format is chosen by extension, in any
// letter case: .csv (ours, or ADS-B by its header), .igc or .gpx; options go
// to the reader (flight.hpp: ReadOptions). Errors name the file, and the
// parser's errors the line and field; the parser's warnings come with the
// flight for the caller to log.
Result<flight::ParsedFlight> loadFlight(const std::string& path, const flight::ReadOptions& options = {});

}  // namespace sky::sim
