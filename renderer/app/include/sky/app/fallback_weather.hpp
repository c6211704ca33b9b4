// The weather a live channel draws before (or without) a weather server: a
// channel draws from the host's first pose even when no skyshell-weatherd is
// running, and switches to the server's weather, without a restart, once it
// connects and sends some.
//
// Before the server's weather: clear sky, or the layers of --weather-file (a
// scenario, as headless replay takes it) on that file's clock. The fallback
// is drawn at once while there is no connection (after a short grace for
// the first connect), and after --weather-timeout while a connected server
// has sent nothing.
#pragma once

#include <chrono>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>

#include "sky/app/shared_state.hpp"
#include "sky/core/result.hpp"
#include "sky/weather/scenario.hpp"

namespace sky::app {

// The whole file at `path`; the error names it (cleaned for a message).
// A file of more than maxBytes is an error (TooLarge), found by reading no
// more than maxBytes + 1 bytes.
Result<std::string> readFile(const std::string& path, std::size_t maxBytes = SIZE_MAX);

// A scenario file's layers and clock, as a view anchored at `now` (no tiles:
// each layer uniform at its coverage).
Result<WeatherView> scenarioWeather(const std::string& path, std::chrono::steady_clock::time_point now);

enum class WeatherSource { Server, File, Clear, None };
const char* toString(WeatherSource s);  // "server", "file", "clear", "none"

class FallbackWeather {
 public:
  // How long the first connect may take before the fallback is drawn. 1 s:
  // a loopback or LAN connect takes milliseconds; a server that is not
  // running is refused at once.
  static constexpr double kConnectGrace_s = 1.0;

  // file: the --weather-file view (none: clear sky). serverName: HOST:PORT,
  // for the messages. weatherTimeout_s: how long a connected server may be
  // silent before the fallback is drawn.
  FallbackWeather(std::optional<WeatherView> file, std::string fileName, std::string serverName,
                  double weatherTimeout_s, std::chrono::steady_clock::time_point start);

  // What to draw now, given what the stream has brought: the streamed view
  // once it has weather; else the fallback when it is due; else none (wait).
  // Logs each change of source once.
  WeatherSource choose(const WeatherView& streamed, std::chrono::steady_clock::time_point now);

  // The view for a source choose() returned (the streamed one for Server).
  const WeatherView& view(WeatherSource source, const WeatherView& streamed) const;

 private:
  std::optional<WeatherView> file_;
  WeatherView clear_;
  std::string fileName_, serverName_;
  double weatherTimeout_s_;
  std::chrono::steady_clock::time_point start_;
  std::optional<std::chrono::steady_clock::time_point> connectedSince_;
  WeatherSource last_ = WeatherSource::None;
};

}  // namespace sky::app
