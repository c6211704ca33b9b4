// A saved weather state cut by S2 cell (see state_cells.hpp).
#include "sky/server/state_cells.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <optional>
#include <set>
#include <utility>

#include "ramp_math.hpp"
#include "sky/server/api_json.hpp"
#include "sky/server/snapshot_builder.hpp"

namespace sky::server {

namespace {

const nlohmann::json* member(const nlohmann::json& j, const char* key) {
  if (!j.is_object()) return nullptr;
  const auto it = j.find(key);
  return it == j.end() ? nullptr : &*it;
}

double number(const nlohmann::json& j, const char* key, double otherwise) {
  const nlohmann::json* v = member(j, key);
  return v && v->is_number() ? v->get<double>() : otherwise;
}

// The cap a saved region reaches, or none when it must stay global.
std::optional<weather::SphericalCap> capOf(const nlohmann::json& region) {
  const nlohmann::json* drifts = member(region, "drifts_with_wind");
  if (!drifts || !drifts->is_boolean() || drifts->get<bool>()) return std::nullopt;
  const double lat = number(region, "center_lat_deg", NAN), lon = number(region, "center_lon_deg", NAN);
  const double sx = number(region, "size_x_m", NAN), sy = number(region, "size_y_m", NAN);
  const double transition = number(region, "transition_m", NAN);
  if (!std::isfinite(lat) || !std::isfinite(lon) || !std::isfinite(sx) || !std::isfinite(sy) ||
      !std::isfinite(transition) || std::abs(lat) > 90 || sx < 0 || sy < 0 || transition < 0)
    return std::nullopt;
  // The snapshot builder's reach: past it a region weighs 0 in a tile.
  weather::Region r;
  r.sizeX_m = sx;
  r.sizeY_m = sy;
  r.transition_m = transition;
  const double reach_m = server::reachOf(r);
  if (reach_m > kMaxCellRegionReach_m) return std::nullopt;
  return weather::SphericalCap{lat, lon, reach_m};
}

std::uint64_t unsignedOr(const nlohmann::json& j, const char* key, std::uint64_t otherwise) {
  const nlohmann::json* v = member(j, key);
  return v && v->is_number_unsigned() ? v->get<std::uint64_t>() : otherwise;
}

// Points along a ramp at most this far apart: the caps around them, widened
// by half of it, cover the path between.
constexpr double kRampStep_m = 20e3;

// The cells a region ramp's region passes through (the ramp moves its centre
// from `from` to `to` as lerpRegion does, and a ramp from nothing grows in
// where it ends); none when it must stay global (drifting, too large, or a
// path longer than a region may reach).
std::set<std::string> rampCells(const nlohmann::json& ramp, CellReach& reach) {
  const nlohmann::json* fromJ = member(ramp, "from");
  const nlohmann::json* toJ = member(ramp, "to");
  const nlohmann::json* absent = member(ramp, "from_absent");
  if (!fromJ || !toJ || !absent || !absent->is_boolean()) return {};
  auto to = regionFromJson(*toJ, "to", true);
  auto from = absent->get<bool>() ? to : regionFromJson(*fromJ, "from", true);
  if (!to || !from || to->driftsWithWind || from->driftsWithWind) return {};
  std::set<std::string> cells;
  const double path_m = sphereDistance_m(from->centerLat_deg, from->centerLon_deg, to->centerLat_deg, to->centerLon_deg);
  if (path_m > kMaxCellRegionReach_m) return {};
  const int steps = static_cast<int>(std::ceil(path_m / kRampStep_m));
  const double widen_m = steps > 0 ? 0.5 * path_m / steps : 0.0;
  for (int k = 0; k <= steps; ++k) {
    const weather::Region at = lerpRegion(*from, *to, steps > 0 ? double(k) / steps : 1.0);
    const double reach_m = std::max(reachOf(*from), reachOf(*to)) + widen_m;
    if (reach_m > kMaxCellRegionReach_m) return {};
    const auto& keys = reach.cellsOfCap({at.centerLat_deg, at.centerLon_deg, reach_m});
    cells.insert(keys.begin(), keys.end());
  }
  return cells;
}

}  // namespace

std::string cellKey(std::uint64_t cellId) {
  // An S2 token: the id in hex without its trailing zeros.
  char hex[17];
  std::snprintf(hex, sizeof hex, "%016llx", static_cast<unsigned long long>(cellId));
  std::string token(hex);
  token.erase(token.find_last_not_of('0') + 1);
  return "c." + (token.empty() ? std::string("X") : token);
}

const std::vector<std::string>& CellReach::cellsOf(const nlohmann::json& region) {
  static const std::vector<std::string> kGlobal;
  const auto cap = capOf(region);
  if (!cap) return kGlobal;
  return cellsOfCap(*cap);
}

const std::vector<std::string>& CellReach::cellsOfCap(const weather::SphericalCap& c) {
  const weather::SphericalCap* cap = &c;
  char placement[96];
  std::snprintf(placement, sizeof placement, "%.9g %.9g %.9g", cap->centerLat_deg, cap->centerLon_deg,
                cap->radius_m);
  if (auto it = byPlacement_.find(placement); it != byPlacement_.end()) return it->second;
  if (byPlacement_.size() >= kMaxEntries) byPlacement_.clear();
  std::vector<std::string> keys;
  for (const std::uint64_t id : weather::coverCap(*cap, kStateCellLevel, kMaxCellsPerArea)) keys.push_back(cellKey(id));
  std::sort(keys.begin(), keys.end());
  keys.erase(std::unique(keys.begin(), keys.end()), keys.end());
  return byPlacement_.emplace(placement, std::move(keys)).first->second;
}

StateCells splitState(nlohmann::json state, CellReach& reach) {
  StateCells out;
  out.global = std::move(state);
  if (!out.global.is_object()) return out;
  auto cellOf = [&out](const std::string& key) -> nlohmann::json& {
    auto [it, added] = out.cells.try_emplace(key);
    if (added) it->second = {{"regions", nlohmann::json::array()}, {"region_ramps", nlohmann::json::array()}};
    return it->second;
  };
  // Each item moves to the global part or to its last cell, and is copied
  // to the others: a state of thousands of regions is cut after every
  // change.
  auto cut = [&](const char* name, auto&& cellsOf) {
    const auto found = out.global.find(name);
    if (found == out.global.end() || !found->is_array()) return;
    nlohmann::json items = std::move(*found);
    nlohmann::json kept = nlohmann::json::array();
    for (auto& item : items) {
      const std::vector<std::string> cells = cellsOf(item);
      if (cells.empty()) {
        kept.push_back(std::move(item));
        continue;
      }
      for (std::size_t k = 0; k + 1 < cells.size(); ++k) cellOf(cells[k])[name].push_back(item);
      cellOf(cells.back())[name].push_back(std::move(item));
    }
    out.global[name] = std::move(kept);
  };
  cut("regions", [&](const nlohmann::json& r) { return reach.cellsOf(r); });
  cut("region_ramps", [&](const nlohmann::json& r) {
    const std::set<std::string> cells = rampCells(r, reach);
    return std::vector<std::string>(cells.begin(), cells.end());
  });
  return out;
}

nlohmann::json joinState(const nlohmann::json& global, const std::vector<const nlohmann::json*>& cells) {
  nlohmann::json state = global;
  if (!state.is_object()) return state;
  std::map<std::uint64_t, const nlohmann::json*> regions;
  std::map<std::pair<std::uint64_t, std::uint64_t>, const nlohmann::json*> ramps;
  auto take = [&](const nlohmann::json* part) {
    if (!part) return;
    if (const nlohmann::json* rs = member(*part, "regions"); rs && rs->is_array())
      for (const auto& r : *rs) regions.emplace(unsignedOr(r, "id", 0), &r);
    if (const nlohmann::json* rs = member(*part, "region_ramps"); rs && rs->is_array())
      for (const auto& r : *rs) ramps.emplace(std::pair{unsignedOr(r, "sequence", 0), unsignedOr(r, "region_id", 0)}, &r);
  };
  take(&global);
  for (const nlohmann::json* c : cells) take(c);
  nlohmann::json rs = nlohmann::json::array();
  for (const auto& [id, r] : regions) rs.push_back(*r);
  nlohmann::json rr = nlohmann::json::array();
  for (const auto& [key, r] : ramps) rr.push_back(*r);
  if (state.contains("regions") || !rs.empty()) state["regions"] = std::move(rs);
  if (state.contains("region_ramps") || !rr.empty()) state["region_ramps"] = std::move(rr);
  return state;
}

std::vector<std::string> cellsForAreas(const std::vector<weather::SphericalCap>& areas, CellReach& cache,
                                       bool& tooMany) {
  tooMany = false;
  std::set<std::string> keys;
  for (const auto& a : areas) {
    const auto& covering = cache.cellsOfCap(a);
    if (covering.size() > kMaxCellsPerArea) {
      tooMany = true;
      return {};
    }
    keys.insert(covering.begin(), covering.end());
  }
  return {keys.begin(), keys.end()};
}

}  // namespace sky::server
