// The METAR stations and their latest applied reports (see metar_stations.hpp).
#include "sky/server/metar_stations.hpp"

#include <algorithm>

#include "sky/core/utf8.hpp"
#include "sky/server/api_json.hpp"

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

json MetarStationBoard::list(std::span<const Station> serverStations, const WeatherView& now) const {
  std::map<std::uint32_t, const weather::Region*> regions;
  for (const auto& r : now.regions) regions[r.id] = &r;
  json out = json::array();
  auto withReport = [&](json station, const std::string& icao) {
    const auto it = latest_.find(icao);
    if (it == latest_.end()) return station;
    const Entry& e = it->second;
    const auto region = regions.find(e.regionId);
    if (region == regions.end()) return station;
    // The layers the report became: its region's, as they are now.
    json layers = json::array();
    for (const auto& l : region->second->layers) layers.push_back(toJson(l));
    station["report"] = {{"text", e.text}, {"region_id", e.regionId}, {"sequence", e.sequence},
                         {"clock_s", e.clock_s}, {"sky", e.sky}, {"layers", layers}};
    return station;
  };
  for (const Station& s : serverStations) out.push_back(withReport(stationJson(s), s.icao));
  for (const auto& [icao, e] : latest_)
    if (!findStation(serverStations, icao)) out.push_back(withReport(stationJson(e.station), icao));
  return {{"stations", out}};
}

}  // namespace sky::server
