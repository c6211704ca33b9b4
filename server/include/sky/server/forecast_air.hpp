// A forecast's air: temperature and relative humidity on pressure levels and
// near the ground (2 m), per forecast step. The snapshot carries them at the
// levels' heights (air tiles); a reader interpolates between the levels
// (weather::AirField), so the server only samples each level, bilinear in
// space and linear in time between steps.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "sky/server/grib.hpp"
#include "sky/weather/air_field.hpp"

namespace sky::server {

class ForecastAir {
 public:
  // The temperature (and humidity, where given) of every field of `files`
  // at each height any step has; what was read goes to `notes`. Empty when
  // no file has a temperature on a level.
  static ForecastAir fromGrib(const std::vector<const GribFile*>& files, std::vector<std::string>& notes);

  bool empty() const { return levels_m_.empty(); }
  // The levels' heights, m MSL, ascending (a pressure level's through the
  // standard atmosphere, as the layers' and the winds'; a level above the
  // ground at its height above sea level, the terrain not being read).
  const std::vector<double>& levels_m() const { return levels_m_; }
  // The air at level `level` at a point and valid time; humidity NaN where
  // the forecast gives none there; nullopt without a temperature.
  std::optional<weather::AirValues> at(std::size_t level, double lat_deg, double lon_deg, double valid_unix) const;

 private:
  struct Level {
    GribGrid grid;
    std::vector<float> temperature_c;  // empty: the step has no temperature at this level
    GribGrid humidityGrid;
    std::vector<float> humidity_pct;   // empty: none
  };
  struct Step {
    std::int64_t valid_unix = 0;
    std::vector<Level> levels;  // by index into levels_m_
  };
  std::optional<weather::AirValues> atStep(const Step& step, std::size_t level, double lat_deg, double lon_deg) const;
  std::vector<double> levels_m_;
  std::vector<Step> steps_;  // by valid time
};

}  // namespace sky::server
