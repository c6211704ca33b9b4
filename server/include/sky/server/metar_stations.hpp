// GET /api/metar/stations: the METAR stations the console marks on its map,
// each with the latest report applied to it through POST /api/metar (the raw
// text and the layers it became) while its region is still in the weather.
// The texts are kept in memory by the HTTP API: after a restart the stations'
// regions are back (the store keeps them) and listed with their layers, the
// texts are not.
#pragma once

#include <cstdint>
#include <map>
#include <span>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "sky/server/change.hpp"
#include "sky/server/metar.hpp"
#include "sky/server/metar_api.hpp"

namespace sky::server {

class MetarStationBoard {
 public:
  // Remembers the reports of an applied POST /api/metar: `reply` is
  // handleMetar's body for `request` (status 200, "applied" set). A report
  // that set a station's region replaces that station's entry; a removed
  // station is forgotten.
  void remember(const MetarRequest& request, const nlohmann::json& reply, std::span<const Station> serverStations);

  // {"stations": [{"icao", "lat_deg", "lon_deg", "elevation_m", "report": null or
  //   {"text", "region_id", "sequence", "clock_s", "sky", "layers": [LAYER...]}}]}:
  // the server's table in its order, then stations only requests brought
  // (by ICAO). A report is shown only while its region is in `now`, with
  // that region's layers as they are in `now` (the layers it became). A
  // station with no remembered report whose region is in `now` (found by its
  // centre) gets {"text": null, "region_id", "sequence": null, "clock_s":
  // null, "sky": "read", "layers"}.
  nlohmann::json list(std::span<const Station> serverStations, const WeatherView& now) const;

  // The server's table, then the stations only requests brought (by ICAO):
  // every station whose name the conformance check can give.
  std::vector<Station> known(std::span<const Station> serverStations) const;

 private:
  struct Entry {
    Station station;
    std::string text;
    std::uint32_t regionId = 0;
    std::uint64_t sequence = 0;
    double clock_s = 0;
    nlohmann::json sky;
  };
  std::map<std::string, Entry> latest_;  // by ICAO
};

}  // namespace sky::server
