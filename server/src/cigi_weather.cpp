#include "sky/server/cigi_weather.hpp"

#include <algorithm>
#include <cmath>
#include <string>
#include <utility>

#include "sky/cigi/precipitation_layers.hpp"
#include "sky/weather/precipitation.hpp"
#include "sky/weather/query.hpp"

namespace sky::server {
namespace {

bool sameLayer(const weather::CloudLayer& a, const weather::CloudLayer& b) {
  return a.id == b.id && a.type == b.type && a.base_m == b.base_m && a.thickness_m == b.thickness_m &&
         a.transitionBand_m == b.transitionBand_m && a.coverage == b.coverage && a.density == b.density &&
         a.wind.speed_mps == b.wind.speed_mps && a.wind.fromDirection_deg == b.wind.fromDirection_deg &&
         a.wind.vertical_mps == b.wind.vertical_mps;
}

bool sameRegion(const weather::Region& a, const weather::Region& b) {
  if (a.id != b.id || a.centerLat_deg != b.centerLat_deg || a.centerLon_deg != b.centerLon_deg ||
      a.sizeX_m != b.sizeX_m || a.sizeY_m != b.sizeY_m || a.cornerRadius_m != b.cornerRadius_m ||
      a.rotation_deg != b.rotation_deg || a.transition_m != b.transition_m ||
      a.layers.size() != b.layers.size())
    return false;
  for (std::size_t i = 0; i < a.layers.size(); ++i)
    if (!sameLayer(a.layers[i], b.layers[i])) return false;
  return true;
}

bool cloudLayerId(cigi::LayerId id) {
  auto n = static_cast<std::uint8_t>(id);
  return n <= 7 || n >= 10;  // ground fog (0) is our fog layer 0; 4-7 precipitation
}

// The rate a severity (0-5) stands for, mm/h.
double severityRate_mmph(weather::CloudType type, std::uint8_t severity) {
  const bool snow = type == weather::CloudType::Snow;
  const double light = snow ? weather::kLightSnow_mmph : weather::kLightRain_mmph;
  const double moderate = snow ? weather::kModerateSnow_mmph : weather::kModerateRain_mmph;
  const double heavy = snow ? weather::kHeavySnow_mmph : weather::kHeavyRain_mmph;
  if (severity <= 1) return light;
  if (severity <= 3) return moderate;
  return severity == 4 ? heavy : 2 * heavy;
}

std::string where(std::size_t index, const char* packet) {
  return "packet " + std::to_string(index) + " (" + packet + ")";
}

weather::Region regionWithLayers(const weather::Region& geometry,
                                 const std::map<std::uint32_t, weather::CloudLayer>& layers) {
  weather::Region r = geometry;
  r.layers.clear();
  for (const auto& [id, layer] : layers) r.layers.push_back(layer);
  return r;
}

}  // namespace

Result<std::optional<weather::CloudLayer>> cloudLayerFrom(const cigi::WeatherControl& p) {
  if (!cloudLayerId(p.layerId)) return std::optional<weather::CloudLayer>{};
  const std::string what = "Weather Control layer " + std::to_string(static_cast<int>(p.layerId));
  auto bad = [&](const char* field, double v, const char* range) {
    return fail(ErrorCode::InvalidArgument, what + ": " + field + " " + std::to_string(v) + " outside " + range);
  };
  if (!(p.coverage_pct >= 0 && p.coverage_pct <= 100)) return bad("coverage", p.coverage_pct, "[0, 100] %");
  if (!(p.windDirection_deg >= -180 && p.windDirection_deg <= 360))
    return bad("wind direction", p.windDirection_deg, "[-180, 360] deg");
  const bool fog = p.layerId == cigi::LayerId::GroundFog;
  if (fog && !(p.visibility_m > 0 && std::isfinite(p.visibility_m)))
    return bad("visibility range", p.visibility_m, "(0, inf) m for ground fog");
  const weather::CloudType precipitation = cigi::precipitationTypeOf(p.layerId);
  if (precipitation != weather::CloudType::None && !(p.visibility_m >= 0 && std::isfinite(p.visibility_m)))
    return bad("visibility range", p.visibility_m, "[0, inf) m for precipitation (0: by severity)");
  weather::CloudLayer layer;
  layer.id = static_cast<std::uint8_t>(p.layerId);
  layer.type = fog ? weather::CloudType::Fog : precipitation != weather::CloudType::None ? precipitation : p.cloudType;
  layer.base_m = p.baseElevation_m;
  layer.thickness_m = p.thickness_m;
  layer.transitionBand_m = p.transitionBand_m;
  layer.coverage = p.coverage_pct / 100.0;
  // Ground fog's density is its visibility range; a cloud layer's visibility
  // range (in cloud) is not used: the cloud's own density draws it.
  layer.density = fog ? weather::fogDensityForVisibility(p.visibility_m) : 1.0;
  if (precipitation != weather::CloudType::None)
    layer.density = p.visibility_m > 0 ? weather::precipitationDensityForVisibility(p.visibility_m)
                                       : weather::precipitationDensityForRate(precipitation,
                                                                              severityRate_mmph(precipitation, p.severity));
  layer.wind.speed_mps = p.horizontalWind_mps;
  double from = std::fmod(static_cast<double>(p.windDirection_deg), 360.0);
  if (from < 0) from += 360;
  layer.wind.fromDirection_deg = from;
  layer.wind.vertical_mps = p.verticalWind_mps;
  if (auto ok = weather::validate(layer); !ok)
    return fail(ErrorCode::InvalidArgument, what + ": " + ok.error().detail);
  return std::optional<weather::CloudLayer>{layer};
}

void CigiWeatherMapper::reset() {
  globalSent_.clear();
  regions_.clear();
}

Result<std::vector<WeatherChange>> CigiWeatherMapper::map(const cigi::Datagram& datagram) {
  // Work on copies so a rejected datagram leaves the remembered state alone.
  auto global = globalSent_;
  auto regions = regions_;
  std::size_t ignored = 0;
  std::vector<WeatherChange> changes;
  std::map<std::uint32_t, bool> regionTouched;
  std::map<std::uint32_t, std::optional<weather::CloudLayer>> wantedGlobal;  // none: disabled

  for (std::size_t i = 0; i < datagram.packets.size(); ++i) {
    const auto& packet = datagram.packets[i];
    if (const auto* wc = std::get_if<cigi::WeatherControl>(&packet)) {
      if (wc->scope == cigi::WeatherScope::Entity)
        return fail(ErrorCode::InvalidArgument,
                    where(i, "Weather Control") + ": scope entity: no entity weather in our model");
      auto layer = cloudLayerFrom(*wc);
      if (!layer) return fail(ErrorCode::InvalidArgument, where(i, "Weather Control") + ": " + layer.error().detail);
      if (!*layer) {
        ++ignored;
        continue;
      }
      const std::uint32_t id = (*layer)->id;
      if (wc->scope == cigi::WeatherScope::Global) {
        // The last packet for a layer in the datagram is what the host wants.
        wantedGlobal[id] = wc->weatherEnable ? std::optional<weather::CloudLayer>(**layer) : std::nullopt;
      } else {
        if (wc->entityOrRegionId == 0)
          return fail(ErrorCode::InvalidArgument, where(i, "Weather Control") + ": region id 0 outside [1, 65535]");
        auto& region = regions[wc->entityOrRegionId];
        if (wc->weatherEnable) region.layers[id] = **layer;
        else region.layers.erase(id);
        regionTouched[wc->entityOrRegionId] = true;
      }
    } else if (const auto* erc = std::get_if<cigi::EnvironmentalRegionControl>(&packet)) {
      if (erc->regionId == 0)
        return fail(ErrorCode::InvalidArgument,
                    where(i, "Environmental Region Control") + ": region id 0 outside [1, 65535]");
      auto& region = regions[erc->regionId];
      if (erc->state == cigi::RegionState::Active) {
        weather::Region geometry;
        geometry.id = erc->regionId;
        geometry.centerLat_deg = erc->lat_deg;
        geometry.centerLon_deg = erc->lon_deg;
        geometry.sizeX_m = erc->sizeX_m;
        geometry.sizeY_m = erc->sizeY_m;
        geometry.cornerRadius_m = erc->cornerRadius_m;
        geometry.rotation_deg = erc->rotation_deg;
        geometry.transition_m = erc->transitionPerimeter_m;
        if (auto ok = weather::validate(geometry); !ok)
          return fail(ErrorCode::InvalidArgument,
                      where(i, "Environmental Region Control") + " region " + std::to_string(erc->regionId) +
                          ": " + ok.error().detail);
        region.geometry = geometry;
        region.active = true;
      } else {
        region.active = false;
        if (erc->state == cigi::RegionState::Destroyed) {
          // Forgotten, but what the server has must still go.
          const auto sent = region.lastSent;
          region = RegionState{};
          region.lastSent = sent;
        }
      }
      regionTouched[erc->regionId] = true;
    }
  }

  // Global layers: the datagram's net effect against what this input set.
  for (const auto& [id, want] : wantedGlobal) {
    auto it = global.find(id);
    if (want) {
      if (it != global.end() && it->second && sameLayer(*it->second, *want)) continue;
      global[id] = *want;
      changes.push_back(SetLayer{*want, {}});
    } else {
      // Only layers this input set are removed: a disabled layer we never
      // enabled (hosts send all three every frame) is left alone.
      if (it == global.end() || !it->second) continue;
      global[id] = std::nullopt;
      changes.push_back(RemoveLayer{id, {}});
    }
  }

  // Regions whose state, geometry or layers were given: removed if no longer
  // active, else sent whole when different from what the server has.
  for (const auto& [id, touched] : regionTouched) {
    auto it = regions.find(id);
    if (it == regions.end()) continue;
    if (!it->second.active || !it->second.geometry) {
      if (!it->second.active && it->second.lastSent) {
        changes.emplace_back(RemoveRegion{id, {}});
        it->second.lastSent.reset();
      }
      if (!it->second.active && !it->second.geometry && it->second.layers.empty()) regions.erase(it);
      continue;
    }
    weather::Region full = regionWithLayers(*it->second.geometry, it->second.layers);
    if (auto ok = weather::validate(full); !ok)
      return fail(ErrorCode::InvalidArgument, "region " + std::to_string(id) + ": " + ok.error().detail);
    if (it->second.lastSent && sameRegion(*it->second.lastSent, full)) continue;
    it->second.lastSent = full;
    changes.push_back(SetRegion{std::move(full), {}});
  }

  if (regions.size() > kMaxCigiRegionsPerSender)
    return fail(ErrorCode::InvalidArgument, "regions: this host would have " + std::to_string(regions.size()) +
                                                " regions, at most " + std::to_string(kMaxCigiRegionsPerSender));
  globalSent_ = std::move(global);
  regions_ = std::move(regions);
  ignoredLayers_ += ignored;
  return changes;
}

}  // namespace sky::server
