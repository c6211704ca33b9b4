// A forecast's winds: u and v (and w where given) on pressure levels and at
// 10 m above the ground, per forecast step, turned earth-relative (NAM's
// Lambert winds are along its grid). The wind at any point and height is
// linear in height between the levels round it and in time between steps,
// so a layer of the forecast moves, and is answered, with the wind at its own
// height and place.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "sky/server/grib.hpp"
#include "sky/weather/wind_field.hpp"

namespace sky::server {

class ForecastWind {
 public:
  // The winds of every field of `files`; what was read goes to `notes`, one
  // line each. Empty when no file has both u and v on a level.
  static ForecastWind fromGrib(const std::vector<const GribFile*>& files, std::vector<std::string>& notes);

  bool empty() const { return steps_.empty(); }
  std::size_t levelCount() const;  // of the step with most levels

  // The wind at a point and height (m MSL) at a valid time: linear in height
  // between the two levels round it (the nearest level's up to 1500 m outside
  // them, none further),
  // linear in time between the steps round it (the first or last outside);
  // nullopt where no level has a value there.
  std::optional<weather::WindVector> at(double lat_deg, double lon_deg, double alt_m, double valid_unix) const;

 private:
  struct Level {
    double alt_m = 0;                            // the level's height, m MSL
    GribGrid grid;                               // of u (and v, and w when present)
    std::vector<float> u, v, w;                  // w empty: not given; m/s
  };
  struct Step {
    std::int64_t valid_unix = 0;
    std::vector<Level> levels;  // by height, upwards
  };
  std::optional<weather::WindVector> atStep(const Step& step, double lat_deg, double lon_deg, double alt_m) const;
  std::vector<Step> steps_;  // by valid time
};

}  // namespace sky::server
