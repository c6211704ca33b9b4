// What a live channel draws before and without a weather server: nothing
// during the first connect's grace, then clear sky (or --weather-file's
// layers) while no server answers or a connected one stays silent past
// --weather-timeout, and the server's weather as soon as it has some, for
// good; the fallback, once drawn, is not blanked by a reconnect.
#include <string>

#include <gtest/gtest.h>

#include "east_track.hpp"
#include "sky/app/fallback_weather.hpp"

namespace sky::app {
namespace {

using test::at;

WeatherView streamed(bool connected, std::uint64_t version) {
  WeatherView v;
  v.connected = connected;
  v.version = version;
  return v;
}

TEST(FallbackWeather, NoServerDrawsClearSkyAfterTheGraceThenTheServersWeather) {
  FallbackWeather f(std::nullopt, "", "127.0.0.1:47800", 30.0, at(0));
  EXPECT_EQ(f.choose(streamed(false, 0), at(0.5)), WeatherSource::None);
  EXPECT_EQ(f.choose(streamed(false, 0), at(FallbackWeather::kConnectGrace_s + 0.01)), WeatherSource::Clear);
  const auto& clear = f.view(WeatherSource::Clear, streamed(false, 0));
  EXPECT_TRUE(clear.snapshot.layers.empty());
  EXPECT_GT(clear.version, 0u);
  // A reconnect without weather yet keeps the picture.
  EXPECT_EQ(f.choose(streamed(true, 0), at(5)), WeatherSource::Clear);
  // The server's weather, from its first snapshot on.
  const auto server = streamed(true, 3);
  EXPECT_EQ(f.choose(server, at(6)), WeatherSource::Server);
  EXPECT_EQ(&f.view(WeatherSource::Server, server), &server);
}

TEST(FallbackWeather, AConnectedServerGetsItsTimeoutBeforeTheFallback) {
  FallbackWeather f(std::nullopt, "", "127.0.0.1:47800", 10.0, at(0));
  EXPECT_EQ(f.choose(streamed(true, 0), at(0.2)), WeatherSource::None);
  EXPECT_EQ(f.choose(streamed(true, 0), at(5)), WeatherSource::None);
  EXPECT_EQ(f.choose(streamed(true, 0), at(10.3)), WeatherSource::Clear);
}

TEST(FallbackWeather, AScenarioFileIsDrawnOnItsOwnClock) {
  const std::string path = SKY_SOURCE_DIR "/deploy/scenarios/skeleton-cumulus.toml";
  auto file = scenarioWeather(path, at(0));
  ASSERT_TRUE(file) << file.error().detail;
  ASSERT_FALSE(file->snapshot.layers.empty());
  const double clock0 = file->clockNow(at(0));
  FallbackWeather f(*file, path, "127.0.0.1:47800", 30.0, at(0));
  EXPECT_EQ(f.choose(streamed(false, 0), at(2)), WeatherSource::File);
  const auto& v = f.view(WeatherSource::File, streamed(false, 0));
  EXPECT_EQ(v.snapshot.layers.size(), file->snapshot.layers.size());
  EXPECT_NEAR(v.clockNow(at(10)) - clock0, 10.0 * v.clock.rate(), 1e-9);

  const auto missing = scenarioWeather("/nonexistent/weather.toml", at(0));
  ASSERT_FALSE(missing);
  EXPECT_NE(missing.error().detail.find("/nonexistent/weather.toml"), std::string::npos);
}

}  // namespace
}  // namespace sky::app
