// METAR report -> cloud layers, the batch over a station table, and the
// inverse-distance interpolation of cover between stations (see metar.hpp).
#include "sky/server/metar.hpp"

#include <algorithm>
#include <cmath>
#include <string_view>
#include <unordered_map>

#include "sky/geo/geodetic.hpp"
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

  if (const std::optional<ObscurationLayer> fog = obscurationLayer(report)) {
    add(weather::CloudType::Fog, station.elevation_m, fog->thickness_m, fog->coverage);
    // Patches denser than the prevailing visibility, so that a sight line
    // through patches and gaps (and the point query's coverage x density)
    // sees the reported one.
    layers.back().density = std::min(1.0, weather::fogDensityForVisibility(fog->visibility_m) / fog->coverage);
  }
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
                                   [](const weather::CloudLayer& l) { return l.type != weather::CloudType::Fog; });
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
