// What a live channel draws without a server's weather (see fallback_weather.hpp).
#include "sky/app/fallback_weather.hpp"

#include <algorithm>
#include <fstream>

#include <spdlog/spdlog.h>

#include "sky/flight/utf8_text.hpp"

namespace sky::app {

Result<std::string> readFile(const std::string& path, std::size_t maxBytes) {
  std::ifstream in(path, std::ios::binary);
  if (!in) return fail(ErrorCode::Io, flight::messageText(path) + ": cannot open for reading");
  // Read in chunks up to the bound (a pipe or a growing file has no size
  // to check first).
  constexpr std::size_t kChunkBytes = std::size_t{1} << 20;
  std::string text;
  while (in) {
    const std::size_t at = text.size();
    // One byte past the bound, to tell a file of maxBytes from a longer one.
    const std::size_t left = maxBytes - at;  // text.size() <= maxBytes here
    const std::size_t want = left < kChunkBytes ? left + 1 : kChunkBytes;
    text.resize(at + want);
    in.read(text.data() + at, static_cast<std::streamsize>(want));
    text.resize(at + static_cast<std::size_t>(in.gcount()));
    if (text.size() > maxBytes)
      return fail(ErrorCode::TooLarge, flight::messageText(path) + ": larger than " + std::to_string(maxBytes) +
                                           " bytes, the most read");
  }
  if (in.bad()) return fail(ErrorCode::Io, flight::messageText(path) + ": read error");
  return text;
}

Result<WeatherView> scenarioWeather(const std::string& path, std::chrono::steady_clock::time_point now) {
  auto text = readFile(path);
  if (!text) return tl::unexpected(text.error());
  auto scenario = weather::parseScenario(*text, path);
  if (!scenario) return tl::unexpected(scenario.error());
  WeatherView v;
  v.snapshot.weatherClock_s = scenario->clock.start_s;
  v.snapshot.layers = scenario->layers;
  v.clock = weather::WeatherClock(scenario->clock.start_s, scenario->clock.rate, now);
  v.version = 1;
  return v;
}

const char* toString(WeatherSource s) {
  switch (s) {
    case WeatherSource::Server: return "server";
    case WeatherSource::File: return "file";
    case WeatherSource::Clear: return "clear";
    case WeatherSource::None: break;
  }
  return "none";
}

FallbackWeather::FallbackWeather(std::optional<WeatherView> file, std::string fileName, std::string serverName,
                                 double weatherTimeout_s, std::chrono::steady_clock::time_point start)
    : file_(std::move(file)),
      fileName_(std::move(fileName)),
      serverName_(std::move(serverName)),
      weatherTimeout_s_(weatherTimeout_s),
      start_(start) {
  clear_.clock = weather::WeatherClock(0.0, 1.0, start);
  clear_.version = 1;
}

WeatherSource FallbackWeather::choose(const WeatherView& streamed, std::chrono::steady_clock::time_point now) {
  WeatherSource next = WeatherSource::None;
  if (streamed.version > 0) {
    next = WeatherSource::Server;
  } else {
    if (streamed.connected && !connectedSince_) connectedSince_ = now;
    if (!streamed.connected) connectedSince_.reset();
    const double sinceStart_s = std::chrono::duration<double>(now - start_).count();
    const bool due = connectedSince_
                         ? std::chrono::duration<double>(now - *connectedSince_).count() > weatherTimeout_s_
                         : sinceStart_s > kConnectGrace_s;
    // Once drawn, the fallback stays until the server's weather comes (a
    // reconnect in between does not blank the picture).
    if (due || last_ == WeatherSource::File || last_ == WeatherSource::Clear)
      next = file_ ? WeatherSource::File : WeatherSource::Clear;
  }
  if (next != last_ && next != WeatherSource::None) {
    if (next == WeatherSource::Server) {
      if (last_ != WeatherSource::None) spdlog::info("weather from {}: drawing it from now on", serverName_);
    } else {
      spdlog::warn("no weather from {}{}: drawing {} until it comes (start skyshell-weatherd there, or give "
                   "--server HOST:PORT; the channel switches to it without a restart)",
                   serverName_, streamed.connected ? " yet" : " (not connected)",
                   file_ ? "the layers of " + fileName_ : std::string("a clear sky (--weather-file FILE for a scenario)"));
    }
  }
  if (next != WeatherSource::None) last_ = next;
  return next;
}

const WeatherView& FallbackWeather::view(WeatherSource source, const WeatherView& streamed) const {
  if (source == WeatherSource::File && file_) return *file_;
  if (source == WeatherSource::Clear) return clear_;
  return streamed;
}

}  // namespace sky::app
