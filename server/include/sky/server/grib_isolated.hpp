// GRIB2 files from outside, decoded in a child process. ecCodes is not safe
// on hostile bytes (a damaged message can make it read out of bounds or
// assert), so the server never runs it in its own process: the decoder
// executable (skyshell-grib-decode, server/grib_decode.cpp) decodes the
// messages one after the other and writes each field down a pipe; when it
// dies on a message, that message is skipped with the reason and a new
// decoder goes on from the next one. The server checks everything the
// decoder says (sizes, grids, counts) against the same limits.
#pragma once

#include <chrono>
#include <cstdint>
#include <filesystem>
#include <span>
#include <stop_token>
#include <string>
#include <string_view>

#include "sky/core/result.hpp"
#include "sky/server/grib.hpp"

namespace sky::server {

// Which fields a decoder keeps: every field (tests, conformance) or those a
// forecast uses (forecast.hpp's forecastWants).
enum class GribSelection : std::uint8_t { All, Forecast };

struct GribDecoder {
  std::filesystem::path executable;                // skyshell-grib-decode
  std::chrono::milliseconds timeout{120000};       // the whole file, all decoders together
  std::size_t maxFileBytes = std::size_t{1} << 30; // 1 GiB: a whole 0.25 degree GFS run step is ~500 MB
  std::size_t maxRestarts = 64;                    // decoders that died before the file is refused
  // Asked to stop (the server closing while an upload decodes): the decoder
  // process is killed at once and the file refused (Io, "stopped"). The
  // default token is never asked.
  std::stop_token stop;
};

// The decoder next to this program's executable (the build tree and the
// install layout both put it there).
std::filesystem::path defaultGribDecoder();

// Reads `file` (at most decoder.maxFileBytes) and decodes it in decoder
// processes. Errors (Io, TooLarge, Malformed, Timeout) name `sourceName`.
// Blocks for as long as the decoders take (up to decoder.timeout): callers
// that serve sockets run it on a thread of their own (worker_slots.hpp).
Result<GribFile> readGribIsolated(const std::filesystem::path& file, std::string_view sourceName,
                                  GribSelection selection, const GribDecoder& decoder, const GribLimits& limits = {});

// The decoder's side of the pipe (skyshell-grib-decode's main): decodes the
// fields of `file` from the index-th one splitGrib finds on and writes the
// records readGribIsolated reads to `fd`. Returns the process's exit code.
int runGribDecoder(const std::filesystem::path& file, std::size_t firstFieldIndex, GribSelection selection, int fd);

// The records of one decoder's output, parsed with every count and size
// checked (exposed for the fuzz target): fields in `into`, skips there too;
// `fieldsDone` is how many fields the decoder finished; `error` a fatal
// error the decoder reported.
struct DecoderOutput {
  std::size_t fieldsDone = 0;
  std::optional<Error> error;
};
Result<DecoderOutput> parseDecoderOutput(std::span<const std::byte> bytes, const GribLimits& limits,
                                         std::size_t& kept, GribFile& into);

}  // namespace sky::server
