// libFuzzer target: GRIB2 files as the server gets them (an upload, a file
// of --grib): the bytes written to a file and decoded by readGribIsolated in
// skyshell-grib-decode processes (ecCodes may crash there; the server's side
// may not), then made a forecast. And the same bytes read as a decoder's
// output (a decoder that writes nonsense): parseDecoderOutput may refuse
// them, never crash or keep more than its limits. Every field kept has a
// valid grid and as many values as points; every cover sampled is in [0, 1]
// or missing. Seeds: tests/fuzz/corpus/grib/ (single messages of the GFS and
// NAM samples).
#include <unistd.h>

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <span>

#include "sky/server/forecast.hpp"
#include "sky/server/grib_isolated.hpp"

namespace {

void check(const sky::server::GribFile& file) {
  for (const auto& f : file.fields) {
    if (!sky::server::validate(f.meta.grid)) std::abort();
    if (f.values.size() != static_cast<std::size_t>(f.meta.grid.ni) * f.meta.grid.nj) std::abort();
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::span<const std::byte> bytes(reinterpret_cast<const std::byte*>(data), size);
  {
    sky::server::GribLimits limits;
    limits.maxValuesKept = 1u << 20;
    sky::server::GribFile into;
    std::size_t kept = 0;
    (void)sky::server::parseDecoderOutput(bytes, limits, kept, into);
    if (kept > limits.maxValuesKept) std::abort();
    check(into);
  }
  // One scratch file per process, removed when it ends.
  static const struct Scratch {
    std::filesystem::path path =
        std::filesystem::temp_directory_path() / ("fuzz_grib_" + std::to_string(::getpid()) + ".grib2");
    ~Scratch() {
      std::error_code ec;
      std::filesystem::remove(path, ec);
    }
  } scratch;
  const std::filesystem::path& path = scratch.path;
  std::ofstream(path, std::ios::binary | std::ios::trunc).write(reinterpret_cast<const char*>(data),
                                                                static_cast<std::streamsize>(size));
  sky::server::GribDecoder decoder;
  decoder.executable = SKY_GRIB_DECODER;
  decoder.timeout = std::chrono::milliseconds(5000);
  auto file = sky::server::readGribIsolated(path, "fuzz.grib2", sky::server::GribSelection::Forecast, decoder);
  if (!file) return 0;
  check(*file);
  auto forecast = sky::server::Forecast::fromGrib({&*file}, "fuzz");
  if (!forecast) return 0;
  for (const auto& layer : forecast->layers()) {
    if (!sky::weather::validate(layer.layer)) std::abort();
    for (double lat : {-90.0, -30.0, 0.0, 45.0, 90.0})
      for (double lon : {-180.0, -97.5, 0.0, 10.0, 179.9}) {
        const float c = forecast->coverage(layer, lat, lon, static_cast<double>(forecast->firstValid_unix()));
        if (!std::isnan(c) && (c < 0 || c > 1)) std::abort();
      }
  }
  return 0;
}
