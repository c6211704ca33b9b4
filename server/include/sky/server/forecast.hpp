// A numerical forecast as cloud layers: the fields of GRIB2 files (NCEP GFS
// and NAM, ECMWF) turned into coverage per layer on the forecast's grid at
// each forecast step, interpolated in space and in time. The layers take
// fixed ids (slots), so a forecast's low layer is one layer of the weather
// however many files or steps fed it, and METAR stations (slots 40-44) and
// hand-made layers keep theirs.
//
// From the fields to layers:
// * Cover given per layer: GFS's `tcc` on the boundary-layer, low, middle,
//   high and convective cloud layers (level types 211, 214, 224, 234, 244),
//   or ECMWF's `lcc`/`mcc`/`hcc` (discipline 0, category 6, numbers 3/4/5).
//   Units from the message (% or a fraction).
// * Cover not given (NAM): from relative humidity on pressure levels by
//   Sundqvist's scheme, C = 1 - sqrt((1 - RH) / (1 - RHc)) above RHc, the
//   layer's cover the largest of its levels' (maximum overlap), the layers
//   split at 642 and 350 hPa (the low/middle/high limits of NCEP's post-
//   processor).
// * Base and top: the layer's bottom/top pressure where the file has it
//   (GFS 212/213, 222/223, 232/233, 242/243) through the standard
//   atmosphere; the heights of the humid levels (their geopotential, else the
//   standard atmosphere) for derived cover; a cloud-base height (level type
//   2) for the lowest layer; otherwise each slot's typical height. One base
//   and thickness per layer (the median over the grid points with cloud):
//   the weather model has one per layer, and tiles vary cover, not height.
// * Type: each slot's (stratocumulus, altocumulus, cirrus, ...); the
//   convective layer is cumulus blending to cumulonimbus as its cover grows.
// * Precipitation: the surface precipitation rate (`prate`, discipline 0,
//   category 1, number 7, kg m-2 s-1 = mm/s) becomes a precipitation layer
//   (slot 35) from the ground to 500 m above the lowest cloud layer's base,
//   covering the points with at least kMinForecastPrecipitation_mmph at
//   their rate's density (precipitation.hpp). Its type is the one NCEP's
//   categorical fields (crain, cfrzr, cicep, csnow: category 1, numbers
//   192-195) give most of the raining points (freezing rain and ice pellets
//   as sleet), rain without them.
// Missing values stay missing: a point with no value (bitmap, outside the
// grid) gives no cover there, never 0.
#pragma once

#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "sky/core/result.hpp"
#include "sky/server/forecast_air.hpp"
#include "sky/server/forecast_wind.hpp"
#include "sky/server/grib.hpp"
#include "sky/server/snapshot_builder.hpp"
#include "sky/weather/model.hpp"

namespace sky::server {

inline constexpr std::uint32_t kForecastBoundarySlot = 30, kForecastLowSlot = 31, kForecastMiddleSlot = 32,
                               kForecastHighSlot = 33, kForecastConvectiveSlot = 34, kForecastPrecipitationSlot = 35;
// Below this rate (mm/h) a grid point has no precipitation layer: a trace.
inline constexpr double kMinForecastPrecipitation_mmph = 0.1;

// The fields a forecast reads (the decoder keeps only these): cloud cover,
// pressure and height of cloud bases, tops and layer limits, relative
// humidity and geopotential on pressure levels, wind (u, v, w) on pressure
// levels and at 10 m, temperature.
bool forecastWants(const GribMeta& meta);

// One layer's cover at one valid time, as a fraction on a grid.
struct CoverGrid {
  GribGrid grid;
  std::vector<float> fraction;  // [0, 1] per grid point (valueIndex), NaN: missing; the
                                // precipitation layer's holds the rate, mm/h, instead
  std::string source;           // "tcc lowCloudLayer, field 1" or "Sundqvist on r at 12 levels, fields 40-51"
};

struct ForecastLayer {
  weather::CloudLayer layer;  // id (slot), type, base, thickness; coverage 0 (the tiles carry it)
  struct Step {
    std::int64_t valid_unix = 0;
    std::shared_ptr<const CoverGrid> cover;
  };
  std::vector<Step> steps;  // by valid time, at least one
  std::string heightFrom;   // how base and top were found
};

class Forecast {
 public:
  // The layers of every field of `files` (several files: several forecast
  // steps, or a file per step; fields of one layer and valid time after the
  // first are ignored). InvalidArgument naming the files when no field gives
  // any layer's cover.
  static Result<Forecast> fromGrib(const std::vector<const GribFile*>& files, std::string name);

  const std::string& name() const { return name_; }
  const std::vector<ForecastLayer>& layers() const { return layers_; }
  std::int64_t reference_unix() const { return reference_unix_; }
  std::int64_t firstValid_unix() const { return firstValid_unix_; }
  std::int64_t lastValid_unix() const { return lastValid_unix_; }
  std::size_t stepCount() const { return stepCount_; }  // distinct valid times
  // What was read, derived or left out, one line each, for the log and the console.
  const std::vector<std::string>& notes() const { return notes_; }
  // The winds of the files (empty when they have none).
  const ForecastWind& wind() const { return wind_; }
  // Their temperature and humidity (empty when they have none).
  const ForecastAir& air() const { return air_; }
  // A layer's wind at a point: the forecast's at the middle of the layer's
  // height; nullopt where the forecast has no wind there.
  std::optional<weather::WindVector> windAt(const ForecastLayer& layer, double lat_deg, double lon_deg,
                                            double valid_unix) const;

  // Cover of a layer at a point at a valid time: linear in time between the
  // steps around it (the first or last step outside them), bilinear in
  // space. NaN where no step has a value there.
  float coverage(const ForecastLayer& layer, double lat_deg, double lon_deg, double valid_unix) const;
  // The tile of a layer at a point (coverage, density 1, the convective
  // layer's cumulonimbus blend; the precipitation layer's: coverage 1 where
  // it rains, density its rate's); coverage NaN where the forecast has none.
  weather::CoverageTile tileAt(const ForecastLayer& layer, double lat_deg, double lon_deg, double valid_unix) const;
  // Where a point's cover comes from, for the console: the step(s), the
  // field, and the nearest grid point ("nam.grib2: Sundqvist on r ..., grid
  // point (41, 30) at 38.95, -97.21"). Empty outside the grid.
  std::string sourceAt(const ForecastLayer& layer, double lat_deg, double lon_deg, double valid_unix) const;

 private:
  std::string name_;
  std::vector<ForecastLayer> layers_;
  std::int64_t reference_unix_ = 0, firstValid_unix_ = 0, lastValid_unix_ = 0;
  std::size_t stepCount_ = 0;
  std::vector<std::string> notes_;
  ForecastWind wind_;
  ForecastAir air_;
};

// Where a forecast sits on the weather clock: at clock c the weather is the
// forecast's valid time anchorValid_unix + (c - anchorClock_s).
struct ForecastPlacement {
  double anchorClock_s = 0;
  std::int64_t anchorValid_unix = 0;
  double validAt(double clock_s) const { return static_cast<double>(anchorValid_unix) + (clock_s - anchorClock_s); }
};

// Forecast time in whole steps of this (s): the tiles of a forecast change
// once a minute of forecast time, not at every heartbeat, so a snapshot
// between two quanta is the cached one. Cloud cover moves by well under
// 1/255 (the wire's step) in a minute between six-hourly steps.
inline constexpr double kForecastTimeQuantum_s = 60;

// A forecast at one valid time, as the snapshot builder samples it.
class ForecastField final : public LayerField {
 public:
  // valid_unix is rounded down to kForecastTimeQuantum_s; `serial` names the
  // forecast (a new load, a new serial).
  ForecastField(std::shared_ptr<const Forecast> forecast, std::uint64_t serial, double valid_unix);
  bool gives(std::uint32_t layerId) const override;
  void sample(std::uint32_t layerId, std::span<const weather::CellCentre> at,
              std::span<weather::CoverageTile> out) const override;
  std::uint64_t key() const override { return key_; }
  // The forecast's winds for its own layers, at each layer's middle height.
  bool givesWind(std::uint32_t layerId) const override;
  void sampleWind(std::uint32_t layerId, std::span<const weather::CellCentre> at,
                  std::span<weather::WindVector> out) const override;
  // The forecast's temperature and humidity at its levels.
  std::vector<double> airLevels() const override;
  void sampleAir(std::size_t level, std::span<const weather::CellCentre> at,
                 std::span<weather::AirValues> out) const override;
  double valid_unix() const { return valid_unix_; }
  const Forecast& forecast() const { return *forecast_; }

 private:
  std::shared_ptr<const Forecast> forecast_;
  double valid_unix_ = 0;
  std::uint64_t key_ = 0;
};

}  // namespace sky::server
