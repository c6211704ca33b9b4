// The weather at a point (see query.hpp).
#include "sky/weather/query.hpp"

#include <algorithm>
#include <cmath>
#include <map>
#include <memory>
#include <numbers>
#include <vector>

#include "sky/weather/advection.hpp"
#include "sky/weather/precipitation.hpp"
#include "sky/weather/tiling.hpp"
#include "sky/weather/wind_field.hpp"

namespace sky::weather {

// The GLSL's functions in a named namespace (external linkage), so that one
// this file does not call raises no unused-function warning.
namespace presence_glsl {
using real = double;
using std::clamp;
using std::min;
#include "sky/weather/layer_presence.glsl"
}  // namespace presence_glsl

namespace {

// Vertical presence of a layer at an altitude, [0, 1]: the renderer's
// (layer_presence.glsl) over the layer's shell.
double presence(const CloudLayer& l, double alt_m) {
  const double band = std::max(l.transitionBand_m, 0.0);
  const double shell = l.thickness_m + 2 * band;
  if (!(shell > 0)) return 0.0;
  return presence_glsl::layerPresence((alt_m - (l.base_m - band)) / shell, band / shell);
}

}  // namespace

PointWeather weatherAt(std::span<const CloudLayer> layers, const CoverageLookup& lookup, double lat_deg,
                       double lon_deg, double alt_m, const WindLookup& windLookup) {
  PointWeather out;
  if (layers.empty()) return out;
  // Each layer with its wind at this point.
  std::vector<CloudLayer> local(layers.begin(), layers.end());
  if (windLookup)
    for (CloudLayer& l : local) l.wind = windLookup(l, lat_deg, lon_deg);
  // A precipitation layer has the wind of the cloud that drops it and of
  // the air it falls through, not a wind of its own that would replace the
  // air's under the cloud: the winds are the other layers'.
  std::vector<const CloudLayer*> byBase;
  for (const auto& l : local)
    if (!isPrecipitation(l.type)) byBase.push_back(&l);
  if (byBase.empty())
    for (const auto& l : local) byBase.push_back(&l);
  std::sort(byBase.begin(), byBase.end(), [](const CloudLayer* a, const CloudLayer* b) { return a->base_m < b->base_m; });

  // Wind.
  const CloudLayer* inside = nullptr;
  for (const CloudLayer* l : byBase)
    if (alt_m >= l->base_m && alt_m <= l->base_m + l->thickness_m) inside = l;  // the highest-based wins on overlap
  if (inside) {
    out.wind = inside->wind;
  } else if (alt_m < byBase.front()->base_m) {
    out.wind = byBase.front()->wind;
  } else {
    // Below the first layer based above alt, above the highest top below it.
    const CloudLayer* above = nullptr;
    const CloudLayer* below = nullptr;
    for (const CloudLayer* l : byBase) {
      if (l->base_m > alt_m) {
        if (!above) above = l;
      } else if (!below || l->base_m + l->thickness_m > below->base_m + below->thickness_m) {
        below = l;
      }
    }
    if (!above) {
      out.wind = below->wind;
    } else {
      const double z0 = below->base_m + below->thickness_m, z1 = above->base_m;
      const double f = z1 > z0 ? std::clamp((alt_m - z0) / (z1 - z0), 0.0, 1.0) : 0.0;
      const WindVector a = toVector(below->wind), b = toVector(above->wind);
      out.wind = fromVector({a.east_mps + f * (b.east_mps - a.east_mps), a.north_mps + f * (b.north_mps - a.north_mps),
                             a.up_mps + f * (b.up_mps - a.up_mps)});
    }
  }

  // Cloud.
  for (const auto& l : layers) {
    const double p = presence(l, alt_m);
    if (p <= 0) continue;
    double coverage = l.coverage, density = l.density;
    if (lookup) {
      if (const auto tile = lookup(l, lat_deg, lon_deg)) {
        coverage = tile->coverage;
        density = tile->density;
      }
    }
    const double d = coverage * density * p;
    if (isPrecipitation(l.type)) {
      const double rate = precipitationRateForDensity(l.type, d);
      if (rate > out.precipitationRate_mmph) {
        out.precipitationRate_mmph = rate;
        out.precipitationType = l.type;
      }
    } else if (d > out.cloudDensity) {
      out.cloudDensity = d;
      out.layerId = l.id;
    }
  }
  out.extinction_perm = kCloudExtinctionPerDensity_perm * out.cloudDensity +
                        precipitationExtinction_perm(out.precipitationType, out.precipitationRate_mmph);
  return out;
}

CoverageLookup snapshotLookup(const WeatherSnapshot& snapshot, double clock_s) {
  // (layer id, cell) -> tile; layers that have tiles at all.
  auto index = std::make_shared<std::map<std::pair<std::uint32_t, std::uint64_t>, CoverageTile>>();
  auto tiled = std::make_shared<std::map<std::uint32_t, bool>>();
  for (const auto& t : snapshot.tiles) {
    (*index)[{t.layerId, t.cellId}] = t;
    (*tiled)[t.layerId] = true;
  }
  const double since_s = clock_s - snapshot.weatherClock_s;
  const int level = snapshot.tileLevel;
  auto wind = std::make_shared<const WindField>(snapshot);
  return [index, tiled, since_s, level, wind](const CloudLayer& layer, double lat_deg,
                                              double lon_deg) -> std::optional<CoverageTile> {
    if (!tiled->count(layer.id)) return std::nullopt;
    const SurfacePoint upwind =
        layer.tilesDrift ? upwindOf({lat_deg, lon_deg}, wind->at(layer, lat_deg, lon_deg), since_s)
                         : SurfacePoint{lat_deg, lon_deg};
    const auto it = index->find({layer.id, cellAt(upwind.lat_deg, upwind.lon_deg, level)});
    if (it == index->end()) {
      CoverageTile empty;
      empty.layerId = layer.id;
      empty.coverage = 0;
      return empty;
    }
    return it->second;
  };
}

WindLookup snapshotWindLookup(const WeatherSnapshot& snapshot) {
  auto wind = std::make_shared<const WindField>(snapshot);
  return [wind](const CloudLayer& layer, double lat_deg, double lon_deg) {
    return wind->windAt(layer, lat_deg, lon_deg);
  };
}

double koschmiederVisibility_m(double extinction_perm) {
  if (!(extinction_perm > 0)) return kUnlimitedVisibility_m;
  return std::min(kKoschmiederDepth / extinction_perm, kUnlimitedVisibility_m);
}

double cloudVisibility_m(double cloudDensity) {
  return koschmiederVisibility_m(kCloudExtinctionPerDensity_perm * cloudDensity);
}

double visibilityAt_m(const PointWeather& point) { return koschmiederVisibility_m(point.extinction_perm); }

double fogDensityForVisibility(double visibility_m) {
  if (!(visibility_m > kMinFogVisibility_m)) return 1.0;
  return kKoschmiederDepth / (kCloudExtinctionPerDensity_perm * visibility_m);
}

double isaTemperature_c(double alt_m) {
  const double h = std::clamp(alt_m, -1000.0, 20000.0);
  return h <= 11000.0 ? 15.0 - 0.0065 * h : -56.5;
}

double isaPressure_hpa(double alt_m) {
  const double h = std::clamp(alt_m, -1000.0, 20000.0);
  if (h <= 11000.0) return 1013.25 * std::pow(1.0 - 2.25577e-5 * h, 5.25588);
  return 226.32 * std::exp(-(h - 11000.0) / 6341.62);
}

double isaAltitude_m(double pressure_hpa) {
  // The inverse of isaPressure_hpa on its domain, -1 to 20 km.
  const double p = std::clamp(pressure_hpa, isaPressure_hpa(20000.0), isaPressure_hpa(-1000.0));
  if (p >= 226.32) return (1.0 - std::pow(p / 1013.25, 1.0 / 5.25588)) / 2.25577e-5;
  return 11000.0 - 6341.62 * std::log(p / 226.32);
}

}  // namespace sky::weather
