// The air's temperature and humidity as a field, from a snapshot's air tiles
// (a forecast's): one formula for the server's point query and the
// renderers' CIGI answer, so a flight model is told the temperature of the
// forecast the clouds come from. Where the field has nothing the caller
// falls back to the standard atmosphere (query.hpp).
#pragma once

#include <cstdint>
#include <optional>
#include <unordered_map>
#include <vector>

#include "sky/weather/model.hpp"

namespace sky::weather {

struct AirValues {
  double temperature_c = 0;
  double humidity_pct = 0;  // relative to water; kNoHumidity (< 0) where none is given
};

// How far past the highest or lowest air level the field still answers
// (m): the nearest level's humidity, and its temperature carried along the
// standard atmosphere's profile.
inline constexpr double kAirBeyondLevels_m = 1500;

class AirField {
 public:
  AirField() = default;
  explicit AirField(const WeatherSnapshot& snapshot);

  bool empty() const { return byLevel_.empty(); }
  // At a point and height (m MSL). In each level: the smooth kernel over the
  // point's cell and its neighbours (wind_field.hpp's), of the cells that
  // have a tile of that level (none in reach: no value there). Between two
  // levels with a value, linear in height; beyond them see
  // kAirBeyondLevels_m. The humidity the same way over the tiles that have
  // one (kNoHumidity where none reaches). nullopt where no temperature does.
  std::optional<AirValues> at(double lat_deg, double lon_deg, double alt_m) const;

 private:
  int cellLevel_ = 0;
  std::vector<float> levels_m_;
  std::vector<std::unordered_map<std::uint64_t, AirValues>> byLevel_;  // by air level
};

}  // namespace sky::weather
