// What a flight file holds, in a few human lines: the format, the aircraft,
// the time span, the bounding box, where the altitude came from and what the
// cleaning kept and dropped. skyshell-replay --info prints it; pure text in,
// text out.
#pragma once

#include <string>
#include <string_view>
#include <vector>

#include "sky/flight/clean.hpp"
#include "sky/flight/flight.hpp"

namespace sky::flight {

// The format parseFlight reads a file as, by sourceName's extension and
// (for .csv) its header: "Skyshell CSV", "ADS-B CSV", "IGC", "GPX",
// "readsb trace JSON", "KML", "KMZ", "X-Plane FDR"; any other extension as ".ext (unknown)".
std::string formatName(std::string_view text, std::string_view sourceName);

// The lines of --info for a parsed (and, when cleaning is given, cleaned)
// flight: one "key: value" line each for format, aircraft, time, UTC start,
// fixes, bounding box, altitude, then the cleaning report's lines (or
// "cleaning: off"), then the reader's warnings, if any. Hold fixes the
// cleaning added are not counted as fixes.
std::vector<std::string> describeFlight(const ParsedFlight& flight, std::string_view format,
                                        const CleanReport* cleaning, const CleanOptions& options);

}  // namespace sky::flight
