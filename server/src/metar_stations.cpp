// The METAR stations and their latest applied reports (see metar_stations.hpp).
#include "sky/server/metar_stations.hpp"

#include <algorithm>
#include <cmath>

#include "sky/core/utf8.hpp"
#include "sky/server/api_json.hpp"
#include "sky/server/metar_changes.hpp"

namespace sky::server {

namespace {

using nlohmann::json;

const Station* findStation(std::span<const Station> stations, const std::string& icao) {
  const auto it = std::find_if(stations.begin(), stations.end(), [&](const Station& s) { return s.icao == icao; });
  return it == stations.end() ? nullptr : &*it;
}

json stationJson(const Station& s) {
  return {{"icao", s.icao}, {"lat_deg", s.lat_deg}, {"lon_deg", s.lon_deg}, {"elevation_m", s.elevation_m},
          {"report", nullptr}};
}

}  // namespace

void MetarStationBoard::remember(const MetarRequest& request, const json& reply,
                                 std::span<const Station> serverStations) {
  const std::span<const Station> stations =
      request.stations ? std::span<const Station>(*request.stations) : serverStations;
  for (const std::string& icao : request.remove) latest_.erase(icao);
  const json& applied = reply.value("applied", json());
  if (!applied.is_object()) return;
  for (const json& r : reply.value("reports", json::array())) {
    if (!r.value("ok", false) || !r.contains("region_id")) continue;
    const std::size_t index = r.value("index", std::size_t{0});
    const std::string icao = r.value("icao", "");
    const Station* station = findStation(stations, icao);
    if (index < 1 || index > request.reports.size() || !station) continue;
    // Later reports of a station in the batch replace earlier ones, as the plan does.
    latest_[icao] = {*station,
                     utf8::sanitise(request.reports[index - 1]),
                     r["region_id"].get<std::uint32_t>(),
                     applied.value("sequence", std::uint64_t{0}),
                     applied.value("clock_s", 0.0),
                     r.value("sky", json("read"))};
  }
}

std::vector<Station> MetarStationBoard::known(std::span<const Station> serverStations) const {
  std::vector<Station> out(serverStations.begin(), serverStations.end());
  for (const auto& entry : latest_)
    if (!findStation(serverStations, entry.first)) out.push_back(entry.second.station);
  return out;
}

json MetarStationBoard::list(std::span<const Station> serverStations, const WeatherView& now) const {
  std::map<std::uint32_t, const weather::Region*> regions;
  for (const auto& r : now.regions) regions[r.id] = &r;
  auto layersOf = [](const weather::Region& r) {
    json layers = json::array();
    for (const auto& l : r.layers) layers.push_back(toJson(l));
    return layers;
  };
  auto withReport = [&](const Station& s) {
    json station = stationJson(s);
    if (const auto it = latest_.find(s.icao); it != latest_.end()) {
      const Entry& e = it->second;
      if (const auto region = regions.find(e.regionId); region != regions.end()) {
        // The layers the report became: its region's, as they are now.
        station["report"] = {{"text", e.text},         {"region_id", e.regionId}, {"sequence", e.sequence},
                             {"clock_s", e.clock_s},   {"sky", e.sky},            {"layers", layersOf(*region->second)}};
        return station;
      }
    }
    // Not remembered (the server restarted since): the station's region is
    // found by its centre, the station's own position, as the conformance
    // check finds it; its layers without the report's text.
    for (const auto& r : now.regions) {
      if (isMetarRegion(r.id) && std::abs(s.lat_deg - r.centerLat_deg) < 1e-9 &&
          std::abs(std::remainder(s.lon_deg - r.centerLon_deg, 360.0)) < 1e-9) {
        station["report"] = {{"text", nullptr}, {"region_id", r.id},   {"sequence", nullptr},
                             {"clock_s", nullptr}, {"sky", "read"}, {"layers", layersOf(r)}};
        break;
      }
    }
    return station;
  };
  json out = json::array();
  for (const Station& s : known(serverStations)) out.push_back(withReport(s));
  return {{"stations", out}};
}

}  // namespace sky::server
