// GRIB2 files into the live weather (see forecast_files.hpp).
#include "sky/server/forecast_files.hpp"

#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <fstream>

#include "sky/server/weather_store.hpp"

namespace sky::server {

// Equal files share one copy; the key names, it does not protect.
std::string fileKey(std::span<const std::byte> bytes) {
  std::uint64_t h = 1469598103934665603ull;
  for (std::byte b : bytes) {
    h ^= static_cast<std::uint8_t>(b);
    h *= 1099511628211ull;
  }
  char buf[48];
  std::snprintf(buf, sizeof buf, "%016llx-%zu", static_cast<unsigned long long>(h), bytes.size());
  return buf;
}

namespace {

Result<std::vector<std::byte>> readAll(const std::filesystem::path& p, std::size_t maxBytes) {
  std::error_code ec;
  const auto size = std::filesystem::file_size(p, ec);
  if (ec) return fail(ErrorCode::Io, p.filename().string() + ": " + ec.message());
  if (size > maxBytes) return fail(ErrorCode::TooLarge, p.filename().string() + ": larger than " + std::to_string(maxBytes) + " bytes");
  std::vector<std::byte> bytes(size);
  std::ifstream in(p, std::ios::binary);
  if (!in.read(reinterpret_cast<char*>(bytes.data()), static_cast<std::streamsize>(size)))
    return fail(ErrorCode::Io, p.filename().string() + ": cannot read");
  return bytes;
}

// A temporary file holding `bytes`, removed with this object.
class TempFile {
 public:
  static Result<TempFile> write(std::span<const std::byte> bytes) {
    std::string tmpl = (std::filesystem::temp_directory_path() / "skyshell-grib-XXXXXX").string();
    const int fd = ::mkstemp(tmpl.data());
    if (fd < 0) return fail(ErrorCode::Io, "cannot make a temporary file for the GRIB bytes");
    TempFile t(tmpl);
    std::size_t at = 0;
    while (at < bytes.size()) {
      const ssize_t n = ::write(fd, bytes.data() + at, bytes.size() - at);
      if (n <= 0) {
        ::close(fd);
        return fail(ErrorCode::Io, "cannot write the temporary GRIB file " + tmpl);
      }
      at += static_cast<std::size_t>(n);
    }
    ::close(fd);
    return t;
  }
  TempFile(TempFile&& o) noexcept : path_(std::move(o.path_)) { o.path_.clear(); }
  TempFile& operator=(TempFile&&) = delete;
  ~TempFile() {
    std::error_code ec;
    if (!path_.empty()) std::filesystem::remove(path_, ec);
  }
  const std::filesystem::path& path() const { return path_; }

 private:
  explicit TempFile(std::filesystem::path p) : path_(std::move(p)) {}
  std::filesystem::path path_;
};

}  // namespace

Result<std::vector<GribInput>> gribInputs(const std::filesystem::path& fileOrDir) {
  std::error_code ec;
  if (std::filesystem::is_regular_file(fileOrDir, ec)) return std::vector<GribInput>{{fileOrDir, fileOrDir.filename().string()}};
  if (!std::filesystem::is_directory(fileOrDir, ec))
    return fail(ErrorCode::Io, fileOrDir.string() + ": no such file or directory");
  std::vector<GribInput> out;
  for (const auto& e : std::filesystem::directory_iterator(fileOrDir, ec)) {
    if (!e.is_regular_file(ec)) continue;
    char magic[4] = {};
    std::ifstream in(e.path(), std::ios::binary);
    if (!in.read(magic, 4) || std::string_view(magic, 4) != "GRIB") continue;
    out.push_back({e.path(), e.path().filename().string()});
  }
  if (ec) return fail(ErrorCode::Io, fileOrDir.string() + ": " + ec.message());
  std::sort(out.begin(), out.end(), [](const GribInput& a, const GribInput& b) { return a.name < b.name; });
  if (out.empty()) return fail(ErrorCode::Io, fileOrDir.string() + ": no GRIB file in it");
  if (out.size() > kMaxGribFiles)
    return fail(ErrorCode::TooLarge, fileOrDir.string() + ": more than " + std::to_string(kMaxGribFiles) + " GRIB files");
  return out;
}

Result<std::filesystem::path> pathInside(const std::filesystem::path& dir, std::string_view relative) {
  const std::filesystem::path rel(relative);
  if (relative.empty() || rel.is_absolute())
    return fail(ErrorCode::InvalidArgument, "path: '" + std::string(relative) + "' is not a path inside the GRIB directory");
  for (const auto& part : rel)
    if (part == "..") return fail(ErrorCode::InvalidArgument, "path: '" + std::string(relative) + "' leaves the GRIB directory");
  std::error_code ec;
  const auto base = std::filesystem::canonical(dir, ec);
  if (ec) return fail(ErrorCode::Io, "the GRIB directory: " + ec.message());
  const auto real = std::filesystem::weakly_canonical(base / rel, ec);
  if (ec) return fail(ErrorCode::Io, "path: '" + std::string(relative) + "': " + ec.message());
  const auto [b, r] = std::mismatch(base.begin(), base.end(), real.begin(), real.end());
  if (b != base.end()) return fail(ErrorCode::InvalidArgument, "path: '" + std::string(relative) + "' leads outside the GRIB directory");
  return real;
}

Result<DecodedForecast> decodeForecast(const std::vector<GribInput>& files, const std::string& name,
                                       double anchorClock_s, const GribDecoder& decoder) {
  DecodedForecast out;
  std::vector<GribFile> decoded;
  decoded.reserve(files.size());
  for (const GribInput& in : files) {
    auto bytes = readAll(in.path, decoder.maxFileBytes);
    if (!bytes) return tl::unexpected(bytes.error());
    auto file = readGribIsolated(in.path, in.name, GribSelection::Forecast, decoder);
    if (!file) return tl::unexpected(file.error());
    for (const GribSkip& s : file->skipped)
      out.skipped.push_back(in.name + " message " + std::to_string(s.message) +
                            (s.field ? " field " + std::to_string(s.field) : "") + ": " + s.reason);
    out.loaded.files.push_back({fileKey(*bytes), in.name});
    out.bytes.push_back(std::move(*bytes));
    decoded.push_back(std::move(*file));
  }
  std::vector<const GribFile*> ptrs;
  for (const GribFile& f : decoded) ptrs.push_back(&f);
  auto forecast = Forecast::fromGrib(ptrs, name);
  if (!forecast) return tl::unexpected(forecast.error());
  out.loaded.placement = {anchorClock_s, forecast->firstValid_unix()};
  out.loaded.forecast = std::make_shared<const Forecast>(std::move(*forecast));
  return out;
}

Result<DecodedForecast> decodeUploadedForecast(std::span<const std::byte> bytes, const std::string& name,
                                               double anchorClock_s, const GribDecoder& decoder) {
  auto tmp = TempFile::write(bytes);
  if (!tmp) return tl::unexpected(tmp.error());
  return decodeForecast({{tmp->path(), name}}, name, anchorClock_s, decoder);
}

Result<AppliedChange> applyForecast(LiveWeather& weather, DecodedForecast decoded, const std::string& author,
                                    const std::string& source) {
  if (WeatherStore* store = weather.store())
    for (std::size_t k = 0; k < decoded.bytes.size(); ++k)
      if (auto ok = store->putFile(decoded.loaded.files[k].key, decoded.loaded.files[k].name, decoded.bytes[k]); !ok)
        return tl::unexpected(ok.error());
  if (const LiveWeather::FileKeeper& keep = weather.fileKeeper())
    for (std::size_t k = 0; k < decoded.bytes.size(); ++k)
      if (auto ok = keep(decoded.loaded.files[k].key, decoded.bytes[k]); !ok) return tl::unexpected(ok.error());
  return weather.loadForecast(std::move(decoded.loaded), author, source);
}

LiveWeather::ForecastLoader forecastLoader(FileFetch fetch, GribDecoder decoder) {
  return [fetch = std::move(fetch), decoder](const nlohmann::json& saved) -> Result<LoadedForecast> {
    auto files = forecastFilesFromJson(saved);
    if (!files) return tl::unexpected(files.error());
    // As many as a load takes: a state from elsewhere (a NATS entry) naming
    // more would fetch and decode each, however often it names one file.
    if (files->size() > kMaxGribFiles)
      return fail(ErrorCode::TooLarge, "forecast: " + std::to_string(files->size()) + " files, more than the " +
                                           std::to_string(kMaxGribFiles) + " a forecast is loaded from");
    auto placement = forecastPlacementFromJson(saved);
    if (!placement) return tl::unexpected(placement.error());
    std::vector<GribFile> decoded;
    for (const auto& f : *files) {
      auto bytes = fetch(f.key);
      if (!bytes) return tl::unexpected(bytes.error());
      if (fileKey(*bytes) != f.key)
        return fail(ErrorCode::Malformed, "file " + f.name + ": its bytes do not have its key " + f.key);
      auto tmp = TempFile::write(*bytes);
      if (!tmp) return tl::unexpected(tmp.error());
      auto file = readGribIsolated(tmp->path(), f.name, GribSelection::Forecast, decoder);
      if (!file) return tl::unexpected(file.error());
      decoded.push_back(std::move(*file));
    }
    std::vector<const GribFile*> ptrs;
    for (const GribFile& f : decoded) ptrs.push_back(&f);
    auto forecast = Forecast::fromGrib(ptrs, saved.value("name", std::string("forecast")));
    if (!forecast) return tl::unexpected(forecast.error());
    LoadedForecast loaded;
    loaded.files = std::move(*files);
    loaded.placement = *placement;
    loaded.forecast = std::make_shared<const Forecast>(std::move(*forecast));
    return loaded;
  };
}

LiveWeather::ForecastLoader storeForecastLoader(const WeatherStore& store, GribDecoder decoder) {
  return forecastLoader([&store](const std::string& key) { return store.getFile(key); }, std::move(decoder));
}

}  // namespace sky::server
