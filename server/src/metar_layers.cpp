// METAR report -> cloud layers, the batch over a station table, and the
// inverse-distance interpolation of cover between stations (see metar.hpp).
#include "sky/server/metar.hpp"

#include <algorithm>
#include <cmath>
#include <string_view>
#include <unordered_map>

#include "sky/geo/geodetic.hpp"
#include "sky/weather/precipitation.hpp"
#include "sky/weather/query.hpp"

namespace sky::server {

namespace {

constexpr double kMetresPerFoot = 0.3048;
constexpr double kMpsPerKnot = 1852.0 / 3600.0;
// Inverse-distance weighting: weight = 1 / d^kIdwPower (Shepard's method with
// the usual power 2); closer than kIdwSnap_m a station gives its own value.
constexpr double kIdwPower = 2;
constexpr double kIdwSnap_m = 1;

double coverageOf(CloudAmount amount) {
  switch (amount) {
    case CloudAmount::Few: return kFewCoverage;
    case CloudAmount::Scattered: return kScatteredCoverage;
    case CloudAmount::Broken: return kBrokenCoverage;
    case CloudAmount::Overcast: return kOvercastCoverage;
    case CloudAmount::Unknown: break;
  }
  return 0;
}

// Type from amount and base above the station (WMO étages, formulas.md).
weather::CloudType typeFromHeight(CloudAmount amount, double heightAgl_m) {
  using weather::CloudType;
  const bool patchy = amount == CloudAmount::Few || amount == CloudAmount::Scattered;
  if (heightAgl_m < kLowCloudTop_m) {
    if (patchy) return CloudType::Cumulus;
    if (amount == CloudAmount::Overcast && heightAgl_m < kStratusMaxBase_m) return CloudType::Stratus;
    return CloudType::Stratocumulus;
  }
  if (heightAgl_m < kMiddleCloudTop_m) return patchy ? CloudType::Altocumulus : CloudType::Altostratus;
  return CloudType::Cirrus;
}

double thicknessOf(weather::CloudType type) {
  using weather::CloudType;
  switch (type) {
    case CloudType::Stratus: return kStratusThickness_m;
    case CloudType::Stratocumulus: return kStratocumulusThickness_m;
    case CloudType::Altocumulus: return kAltocumulusThickness_m;
    case CloudType::Altostratus: return kAltostratusThickness_m;
    case CloudType::Cirrus: return kCirrusThickness_m;
    default: return kCumulusThickness_m;
  }
}

weather::LayerWind layerWind(const std::optional<MetarWind>& wind) {
  weather::LayerWind out;
  if (!wind) return out;  // missing wind: still air
  out.speed_mps = wind->speed_kt * kMpsPerKnot;
  // VRB has no direction: 0 (north) stands in; the speed is still right.
  const int dir = wind->direction_deg.value_or(0);
  out.fromDirection_deg = dir == 360 ? 0.0 : static_cast<double>(dir);
  return out;
}

enum class Obscuration { None, ShallowFog, Fog, Mist, Haze, Precipitation };

// What a present-weather group says obscures the view at the station, and
// how much of the area it covers. In the vicinity (VC) is not at the station.
Obscuration obscurationOf(std::string_view g, double& coverage) {
  if (g.substr(0, 2) == "VC") return Obscuration::None;
  if (!g.empty() && (g[0] == '+' || g[0] == '-')) g.remove_prefix(1);
  std::string_view descriptor = g.substr(0, 2);
  const bool hasDescriptor = std::find(std::begin(kWeatherDescriptors), std::end(kWeatherDescriptors), descriptor) !=
                             std::end(kWeatherDescriptors);
  std::string_view phenomena = hasDescriptor ? g.substr(2) : g;
  auto has = [&](std::string_view code) {
    for (std::size_t i = 0; i + 1 < phenomena.size(); i += 2)
      if (phenomena.substr(i, 2) == code) return true;
    return false;
  };
  if (has("FG")) {
    coverage = descriptor == "BC" ? kFogPatchesCoverage : descriptor == "PR" ? kPartialFogCoverage : 1.0;
    return descriptor == "MI" ? Obscuration::ShallowFog : Obscuration::Fog;
  }
  coverage = 1.0;
  if (has("BR")) return Obscuration::Mist;
  for (std::string_view code : {"HZ", "FU", "DU", "SA", "VA"})
    if (has(code)) return Obscuration::Haze;
  for (std::string_view code : {"DZ", "RA", "SN", "SG", "PL", "GR", "GS", "IC", "UP"})
    if (has(code)) return Obscuration::Precipitation;
  return Obscuration::None;
}

// Which obscuration names the layer when a report has several.
int rank(Obscuration o) {
  switch (o) {
    case Obscuration::Fog: return 5;
    case Obscuration::ShallowFog: return 4;
    case Obscuration::Mist: return 3;
    case Obscuration::Haze: return 2;
    case Obscuration::Precipitation: return 1;
    case Obscuration::None: break;
  }
  return 0;
}

// The report's obscuration layer's thickness, visibility and coverage, if it
// has one (metar.hpp's rule).
struct ObscurationLayer {
  double thickness_m = 0;
  double visibility_m = 0;
  double coverage = 1;
};

std::optional<ObscurationLayer> obscurationLayer(const MetarReport& report) {
  Obscuration worst = Obscuration::None;
  double coverage = 1.0;
  // Fog before mist before haze before precipitation (rank).
  for (const std::string& g : report.weather) {
    double c = 1.0;
    const Obscuration o = obscurationOf(g, c);
    if (o == Obscuration::None) continue;
    if (rank(o) > rank(worst)) {
      worst = o;
      coverage = c;
    }
  }
  // The visibility the report gives under 10 km; -1: none given.
  const double given_m = report.visibility_m && !report.visibilityAbove && *report.visibility_m < kClearVisibility_m
                             ? *report.visibility_m
                             : -1.0;
  const auto reportedOr = [given_m](double fallback_m) { return given_m >= 0 ? given_m : fallback_m; };
  ObscurationLayer out;
  out.coverage = coverage;
  if (report.verticalVisibility) {
    out.thickness_m = std::max(report.verticalVisibility_ft.value_or(kUnknownVerticalVisibility_ft) * kMetresPerFoot,
                               kMinFogThickness_m);
    out.visibility_m = reportedOr(kFogDefaultVisibility_m);
    return out;
  }
  // 10 km or more: whatever obscures is elsewhere (patches around, haze
  // aloft); nothing to draw at the station.
  if (report.visibilityAbove || (report.visibility_m && *report.visibility_m >= kClearVisibility_m))
    return std::nullopt;
  if (worst == Obscuration::Precipitation) {
    if (given_m < 0 || given_m >= kHazeDefaultVisibility_m) return std::nullopt;
    double lowest_m = kPrecipitationObscurationTop_m;
    for (const MetarCloud& cloud : report.clouds)
      if (cloud.height_ft) lowest_m = std::min(lowest_m, *cloud.height_ft * kMetresPerFoot);
    out.thickness_m = std::max(lowest_m, kMinFogThickness_m);
    out.visibility_m = given_m;
    return out;
  }
  // Depth and the visibility a group implies without one given (metar.hpp).
  struct Kind {
    Obscuration kind;
    double thickness_m, defaultVisibility_m;
  };
  static constexpr Kind kKinds[] = {{Obscuration::Fog, kFogThickness_m, kFogDefaultVisibility_m},
                                    {Obscuration::ShallowFog, kShallowFogThickness_m, kFogDefaultVisibility_m},
                                    {Obscuration::Mist, kMistThickness_m, kMistDefaultVisibility_m},
                                    {Obscuration::Haze, kHazeThickness_m, kHazeDefaultVisibility_m}};
  for (const Kind& k : kKinds)
    if (k.kind == worst) {
      out.thickness_m = k.thickness_m;
      out.visibility_m = reportedOr(k.defaultVisibility_m);
      return out;
    }
  return std::nullopt;
}

// An obscured sky (VV) is a fog layer however much of the visibility the
// precipitation takes: at least the extinction of a 10 km visibility.
constexpr double kObscuredSkyFloor_perm = weather::kKoschmiederDepth / kClearVisibility_m;

// The heaviest precipitation a report gives at the station (metar.hpp's rule).
struct PrecipitationGroup {
  weather::CloudType type = weather::CloudType::None;
  double rate_mmph = 0;
  bool showers = false;  // SH or TS: from a convective cloud
  bool drizzle = false;  // drizzle alone (from stratus)
};

std::optional<PrecipitationGroup> precipitationOf(const MetarReport& report) {
  std::optional<PrecipitationGroup> best;
  for (std::string_view g : report.weather) {
    if (g.substr(0, 2) == "VC") continue;
    int intensity = 1;
    if (!g.empty() && (g[0] == '+' || g[0] == '-')) {
      intensity = g[0] == '+' ? 2 : 0;
      g.remove_prefix(1);
    }
    const std::string_view descriptor = g.substr(0, 2);
    bool hasDescriptor = false;
    for (std::string_view d : kWeatherDescriptors) hasDescriptor = hasDescriptor || descriptor == d;
    if (descriptor == "DR" || descriptor == "BL") continue;  // lifted by the wind, not falling
    const std::string_view phenomena = hasDescriptor ? g.substr(2) : g;
    auto has = [&](std::string_view code) {
      for (std::size_t i = 0; i + 1 < phenomena.size(); i += 2)
        if (phenomena.substr(i, 2) == code) return true;
      return false;
    };
    const bool rain = has("RA") || has("UP"), drizzle = has("DZ"), snow = has("SN") || has("SG");
    PrecipitationGroup p;
    if (has("GR") || has("GS")) p.type = weather::CloudType::Hail;
    else if (has("PL") || ((rain || drizzle) && snow)) p.type = weather::CloudType::Sleet;
    else if (snow) p.type = weather::CloudType::Snow;
    else if (rain || drizzle) p.type = weather::CloudType::Rain;
    else continue;
    const bool snowRates = p.type == weather::CloudType::Snow;
    const double rates[3] = {snowRates ? weather::kLightSnow_mmph : weather::kLightRain_mmph,
                             snowRates ? weather::kModerateSnow_mmph : weather::kModerateRain_mmph,
                             snowRates ? weather::kHeavySnow_mmph : weather::kHeavyRain_mmph};
    p.rate_mmph = rates[intensity] * (drizzle && !rain && !snow ? weather::kDrizzleFactor : 1.0);
    p.showers = descriptor == "SH" || descriptor == "TS";
    p.drizzle = drizzle && !rain && !snow;
    if (!best || p.rate_mmph > best->rate_mmph) best = p;
  }
  return best;
}

// The cloud that drops the precipitation, among the report's mapped cloud
// layers (metar.hpp's rule); null without one.
weather::CloudLayer* carrierOf(std::vector<weather::CloudLayer>& layers, const PrecipitationGroup& p) {
  weather::CloudLayer* lowest = nullptr;
  weather::CloudLayer* lowestCeiling = nullptr;
  weather::CloudLayer* convective = nullptr;
  for (weather::CloudLayer& l : layers) {
    if (l.type == weather::CloudType::Fog || weather::isPrecipitation(l.type)) continue;
    if (!lowest || l.base_m < lowest->base_m) lowest = &l;
    if (l.coverage >= kBrokenCoverage && (!lowestCeiling || l.base_m < lowestCeiling->base_m)) lowestCeiling = &l;
    if ((l.type == weather::CloudType::Cumulonimbus || l.thickness_m >= kToweringCumulusThickness_m) &&
        (!convective || l.base_m < convective->base_m))
      convective = &l;
  }
  if (p.showers && convective) return convective;
  return lowestCeiling ? lowestCeiling : lowest;
}

}  // namespace

Result<MetarSky> skyFromMetar(const MetarReport& report, const Station& station) {
  if (report.nil)
    return fail(ErrorCode::InvalidArgument, report.icao + ": NIL report (no observation)");
  if (report.icao != station.icao)
    return fail(ErrorCode::InvalidArgument,
                "report of " + report.icao + " given station " + station.icao);
  if (!std::isfinite(station.lat_deg) || !std::isfinite(station.lon_deg) ||
      !std::isfinite(station.elevation_m) || std::abs(station.lat_deg) > 90)
    return fail(ErrorCode::InvalidArgument, station.icao + ": station position not finite or lat outside [-90, 90]");

  const weather::LayerWind wind = layerWind(report.wind);
  std::vector<weather::CloudLayer> layers;
  auto add = [&](weather::CloudType type, double base_m, double thickness_m, double coverage) {
    weather::CloudLayer layer;
    layer.id = static_cast<std::uint32_t>(layers.size() + 1);
    layer.type = type;
    layer.base_m = base_m;
    layer.thickness_m = thickness_m;
    layer.transitionBand_m = kTransitionFraction * thickness_m;
    layer.coverage = coverage;
    layer.density = 1;
    layer.wind = wind;
    layers.push_back(layer);
  };

  const std::optional<ObscurationLayer> fog = obscurationLayer(report);
  if (fog) add(weather::CloudType::Fog, station.elevation_m, fog->thickness_m, fog->coverage);
  for (const MetarCloud& cloud : report.clouds) {
    if (!cloud.height_ft) continue;  // cannot place
    // A base seen without an amount: cloud is there, FEW the least it can be.
    const CloudAmount amount = cloud.amount == CloudAmount::Unknown ? CloudAmount::Few : cloud.amount;
    const double heightAgl_m = *cloud.height_ft * kMetresPerFoot;
    const double base_m = station.elevation_m + heightAgl_m;
    weather::CloudType type;
    double thickness_m;
    if (cloud.convective == ConvectiveCloud::Cumulonimbus) {
      type = weather::CloudType::Cumulonimbus;
      thickness_m = std::max(kCumulonimbusTop_m - base_m, kCumulonimbusMinThickness_m);
    } else if (cloud.convective == ConvectiveCloud::ToweringCumulus) {
      type = weather::CloudType::Cumulus;  // CIGI has no towering cumulus: a deep cumulus
      thickness_m = kToweringCumulusThickness_m;
    } else {
      type = typeFromHeight(amount, heightAgl_m);
      thickness_m = thicknessOf(type);
    }
    add(type, base_m, thickness_m, coverageOf(amount));
  }

  // The precipitation's extinction at the station, which the fog's adds to.
  double precipitationExtinction_perm = 0;
  if (const std::optional<PrecipitationGroup> p = precipitationOf(report)) {
    weather::CloudLayer* carrier = carrierOf(layers, *p);
    if (carrier && !p->showers && !p->drizzle && carrier->coverage >= kBrokenCoverage &&
        (carrier->type == weather::CloudType::Stratocumulus || carrier->type == weather::CloudType::Altostratus)) {
      carrier->type = weather::CloudType::Nimbostratus;
      carrier->thickness_m = std::max(carrier->thickness_m, kNimbostratusThickness_m);
      carrier->transitionBand_m = kTransitionFraction * carrier->thickness_m;
    }
    double top_m = station.elevation_m + kPrecipitationObscurationTop_m, coverage = 1.0;
    if (carrier) {
      top_m = carrier->base_m + std::min(kPrecipitationInCloud_m, carrier->thickness_m);
      coverage = carrier->coverage;
    }
    if (fog) top_m = std::max(top_m, station.elevation_m + fog->thickness_m);
    // No more than the reported visibility allows (a 9999 caps it at 10 km),
    // less what an obscured sky's fog keeps at least (below).
    double rate = p->rate_mmph;
    const std::optional<double> seen =
        report.visibility_m && *report.visibility_m >= kClearVisibility_m ? std::optional<double>(kClearVisibility_m)
                                                                           : report.visibility_m;
    if (seen && !report.visibilityBelow) {
      const double allowed_perm = weather::kKoschmiederDepth / *seen - (report.verticalVisibility ? kObscuredSkyFloor_perm : 0.0);
      rate = std::min(rate, weather::precipitationRate_mmph(p->type, std::max(allowed_perm, 0.0) / coverage));
    }
    add(p->type, station.elevation_m, std::max(top_m - station.elevation_m, kMinFogThickness_m), coverage);
    layers.back().density = weather::precipitationDensityForRate(p->type, rate);
    layers.back().transitionBand_m = 0;  // it ends at the ground and inside its cloud
    precipitationExtinction_perm = coverage * weather::precipitationExtinction_perm(
                                                  p->type, weather::precipitationRateForDensity(p->type, layers.back().density));
  }
  if (fog) {
    // What the precipitation leaves of the reported visibility's extinction;
    // patches denser than the prevailing visibility, so that a sight line
    // through patches and gaps (and the point query's coverage x density)
    // sees the reported one.
    double extinction_perm = weather::kKoschmiederDepth / fog->visibility_m - precipitationExtinction_perm;
    if (report.verticalVisibility) extinction_perm = std::max(extinction_perm, kObscuredSkyFloor_perm);
    if (extinction_perm > 0) {
      layers.front().density = std::min(1.0, extinction_perm / weather::kCloudExtinctionPerDensity_perm / fog->coverage);
    } else {
      layers.erase(layers.begin());
      for (std::size_t i = 0; i < layers.size(); ++i) layers[i].id = static_cast<std::uint32_t>(i + 1);
    }
  }

  for (const weather::CloudLayer& layer : layers)
    if (auto ok = weather::validate(layer); !ok)
      return fail(ok.error().code, report.icao + ": " + ok.error().detail);
  const bool reportedClear = report.cavok || report.noCloud != NoCloud::None;
  // Fog under a sky the report does not give ("1200 BR //////"): the sky
  // around the station stays as it is, and so does its air (the station
  // replaces every layer or none; fog over another source's clouds is not
  // drawn).
  const bool skyRead = reportedClear || report.verticalVisibility ||
                       std::any_of(layers.begin(), layers.end(),
                                   [](const weather::CloudLayer& l) {
                                     return l.type != weather::CloudType::Fog && !weather::isPrecipitation(l.type);
                                   });
  if (!skyRead) layers.clear();
  return MetarSky{skyRead, std::move(layers)};
}

std::vector<Result<StationWeather>> layersFromMetarBatch(std::span<const std::string> reports,
                                                         std::span<const Station> stations) {
  std::vector<Result<StationWeather>> out;
  out.reserve(reports.size());
  // A continent's table holds thousands of stations: found by ICAO in O(1).
  std::unordered_map<std::string_view, const Station*> byIcao;
  byIcao.reserve(stations.size());
  for (const Station& s : stations) byIcao.emplace(s.icao, &s);
  for (std::size_t i = 0; i < reports.size(); ++i) {
    const std::string where = "report " + std::to_string(i + 1) + ": ";
    auto report = parseMetar(reports[i]);
    if (!report) {
      out.push_back(fail(report.error().code, where + report.error().detail));
      continue;
    }
    const auto found = byIcao.find(report->icao);
    if (found == byIcao.end()) {
      out.push_back(fail(ErrorCode::InvalidArgument,
                         where + "station " + report->icao + " is not in the station table"));
      continue;
    }
    const Station* station = found->second;
    auto sky = skyFromMetar(*report, *station);
    if (!sky) {
      out.push_back(fail(sky.error().code, where + sky.error().detail));
      continue;
    }
    out.push_back(StationWeather{*station, std::move(*report), sky->observed, std::move(sky->layers)});
  }
  return out;
}

double totalCoverage(std::span<const weather::CloudLayer> layers) {
  double total = 0;
  for (const weather::CloudLayer& layer : layers) total = std::max(total, layer.coverage);
  return total;
}

std::optional<double> coverageAt(double lat_deg, double lon_deg,
                                 std::span<const StationWeather> stations) {
  if (stations.empty()) return std::nullopt;
  double weightSum = 0;
  double weighted = 0;
  for (const StationWeather& s : stations) {
    const double d_m =
        geo::geodesicDistance_m(lat_deg, lon_deg, s.station.lat_deg, s.station.lon_deg);
    const double cover = totalCoverage(s.layers);
    if (d_m < kIdwSnap_m) return cover;
    const double w = 1.0 / std::pow(d_m, kIdwPower);
    weightSum += w;
    weighted += w * cover;
  }
  return weighted / weightSum;
}

}  // namespace sky::server
