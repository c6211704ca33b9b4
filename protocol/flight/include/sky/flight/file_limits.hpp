// The largest flight file the loaders read (skyshell-replay's loadFlight and
// skyshell-render --replay): protocol/ opens no files, so the bound both
// enforce is stated here, once.
#pragma once

#include <cstddef>

namespace sky::flight {

// 1 GiB: the ADS-B reader's kMaxAdsbRows (10 million rows) at ~100 bytes
// an OpenSky row; every other format's real files are far smaller (an IGC
// day at 1 Hz is ~3 MB, a long-haul KML ~1 MB). A larger file is refused
// with its size before it is read, not swallowed into memory.
inline constexpr std::size_t kMaxFlightFileBytes = std::size_t{1} << 30;

}  // namespace sky::flight
