// Flight files from disk: read the bytes, pick the reader by extension.
#include "sky/sim/flight_file.hpp"

#include <fstream>

#include "sky/flight/file_limits.hpp"
#include "sky/flight/utf8_text.hpp"

namespace sky::sim {

Result<std::string> readFlightFile(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) return fail(ErrorCode::Io, flight::messageText(path) + ": cannot open for reading");
  // Read in chunks up to the bound (a pipe or a growing file has no size
  // to check first).
  constexpr std::size_t kChunkBytes = std::size_t{1} << 20;
  std::string text;
  while (in) {
    const std::size_t at = text.size();
    // One byte past the bound, to tell a file of the bound from a longer one.
    const std::size_t left = flight::kMaxFlightFileBytes - at;  // text.size() <= the bound here
    const std::size_t want = left < kChunkBytes ? left + 1 : kChunkBytes;
    text.resize(at + want);
    in.read(text.data() + at, static_cast<std::streamsize>(want));
    text.resize(at + static_cast<std::size_t>(in.gcount()));
    if (text.size() > flight::kMaxFlightFileBytes)
      return fail(ErrorCode::TooLarge, flight::messageText(path) + ": larger than " +
                                           std::to_string(flight::kMaxFlightFileBytes) +
                                           " bytes, the most a flight file may hold (kMaxFlightFileBytes)");
  }
  if (in.bad()) return fail(ErrorCode::Io, flight::messageText(path) + ": read error");
  return text;
}

Result<flight::ParsedFlight> loadFlight(const std::string& path, const flight::ReadOptions& options) {
  auto text = readFlightFile(path);
  if (!text) return tl::unexpected(text.error());
  return flight::parseFlight(*text, path, options);
}

}  // namespace sky::sim
