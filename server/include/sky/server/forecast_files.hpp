// GRIB2 files into the live weather: the ways a forecast arrives
// (skyshell-weatherd --grib FILE|DIR, POST /api/grib with the file or a path
// inside --grib-dir, a restart from the store) share this: the files are
// decoded in decoder processes (grib_isolated.hpp), made one forecast
// (forecast.hpp), their bytes kept in the store, then loaded as one change.
#pragma once

#include <filesystem>
#include <functional>
#include <span>
#include <string>
#include <vector>

#include "sky/server/grib_isolated.hpp"
#include "sky/server/live_weather.hpp"

namespace sky::server {

class WeatherStore;

struct GribInput {
  std::filesystem::path path;
  std::string name;  // shown to the operator: the file's name, never its directory
};

// FILE: that file; DIR: its regular files holding "GRIB" in their first 4
// bytes, by name (at most kMaxGribFiles). Io when nothing is there.
inline constexpr std::size_t kMaxGribFiles = 256;
Result<std::vector<GribInput>> gribInputs(const std::filesystem::path& fileOrDir);

// A relative path inside `dir` (POST /api/grib {"path": ...}): InvalidArgument
// for an absolute path, "..", or a path whose real location (symlinks
// resolved) is outside dir.
Result<std::filesystem::path> pathInside(const std::filesystem::path& dir, std::string_view relative);

// The files decoded and made a forecast, placed at `anchorClock_s` (its first
// valid time there), with what each file's decoding skipped, and their bytes
// for the store.
struct DecodedForecast {
  LoadedForecast loaded;
  std::vector<std::vector<std::byte>> bytes;  // by loaded.files
  std::vector<std::string> skipped;           // "gfs.grib2 message 3: ..."
};
Result<DecodedForecast> decodeForecast(const std::vector<GribInput>& files, const std::string& name,
                                       double anchorClock_s, const GribDecoder& decoder);

// The same for one file's bytes (an upload), named `name`.
Result<DecodedForecast> decodeUploadedForecast(std::span<const std::byte> bytes, const std::string& name,
                                               double anchorClock_s, const GribDecoder& decoder);

// Keeps the files' bytes in the weather's store (if it has one) and hands
// them to its file keeper (if it has one: the NATS cluster's), then loads
// the forecast as one change.
Result<AppliedChange> applyForecast(LiveWeather& weather, DecodedForecast decoded, const std::string& author,
                                    const std::string& source);

// For LiveWeather::restore: a saved forecast decoded again from its files'
// bytes, each read by `fetch` under its key (the SQLite store's, or the
// NATS cluster's files stream). A file whose bytes do not have the key
// they were read under (fileKey) is refused: Malformed.
using FileFetch = std::function<Result<std::vector<std::byte>>(const std::string& key)>;
LiveWeather::ForecastLoader forecastLoader(FileFetch fetch, GribDecoder decoder);
// The same from the files the store keeps.
LiveWeather::ForecastLoader storeForecastLoader(const WeatherStore& store, GribDecoder decoder);

// The key a file's bytes are kept under: a 64-bit FNV-1a hash and the size.
std::string fileKey(std::span<const std::byte> bytes);

}  // namespace sky::server
