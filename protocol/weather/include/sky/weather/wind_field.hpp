// The wind as a field: a layer's wind at any point, from its wind tiles
// where it has them (a forecast, a region's own wind) and its own wind
// elsewhere. One formula for the server, the renderers' CPU code (the weather
// map the shader samples is built from it) and the CIGI answer, so a flight
// model flies in the wind that moves the clouds it sees.
#pragma once

#include <cstdint>
#include <memory>
#include <span>
#include <unordered_map>

#include "sky/weather/model.hpp"

namespace sky::weather {

// A wind as components of the air's motion (m/s): east and north parallel to
// the ellipsoid, up. The one conversion from "blows from" (LayerWind).
struct WindVector {
  double east_mps = 0;
  double north_mps = 0;
  double up_mps = 0;
};
WindVector toVector(const LayerWind& wind);
// Back to speed and "from" direction in [0, 360); calm is "from" 0.
LayerWind fromVector(const WindVector& v);

// A snapshot's wind tiles, indexed. Between tile centres the field is a
// smooth weighted mean over the point's cell and its neighbours (weights
// (1 - (d / r)^2)^2 of the distance d from each cell's centre, r one cell
// edge: a tile's own wind at its centre), a cell without a tile weighing in
// with the layer's own wind: no step at cell edges, so a shear line drawn by tiles moves clouds
// apart smoothly instead of tearing them along S2 edges.
class WindField {
 public:
  WindField() = default;
  explicit WindField(const WeatherSnapshot& snapshot);
  explicit WindField(int level, std::span<const WindTile> tiles);

  // Whether the layer has wind tiles (its wind varies over the area).
  bool varies(std::uint32_t layerId) const { return byLayer_.count(layerId) != 0; }
  bool empty() const { return byLayer_.empty(); }
  int level() const { return level_; }
  WindVector at(const CloudLayer& layer, double lat_deg, double lon_deg) const;
  LayerWind windAt(const CloudLayer& layer, double lat_deg, double lon_deg) const {
    return fromVector(at(layer, lat_deg, lon_deg));
  }

 private:
  int level_ = 0;
  std::unordered_map<std::uint32_t, std::unordered_map<std::uint64_t, WindVector>> byLayer_;
};

}  // namespace sky::weather
