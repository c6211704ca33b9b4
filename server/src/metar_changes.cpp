// METAR batch -> station regions (see metar_changes.hpp).
#include "sky/server/metar_changes.hpp"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <map>
#include <sstream>

namespace sky::server {

std::uint32_t metarSlot(const weather::CloudLayer& layer) {
  using weather::CloudType;
  switch (layer.type) {
    case CloudType::Cumulonimbus: return kMetarConvectiveSlot;
    case CloudType::Altocumulus:
    case CloudType::Altostratus: return kMetarMiddleSlot;
    case CloudType::Cirrus:
    case CloudType::Cirrostratus:
    case CloudType::Cirrocumulus: return kMetarHighSlot;
    default: break;
  }
  // Towering cumulus is mapped to a deep cumulus (metar.hpp).
  if (layer.type == CloudType::Cumulus && layer.thickness_m >= kToweringCumulusThickness_m)
    return kMetarConvectiveSlot;
  return kMetarLowSlot;
}

namespace {

// Merges a station's layers into slots.
std::map<std::uint32_t, weather::CloudLayer> slotted(const StationWeather& s) {
  std::map<std::uint32_t, weather::CloudLayer> out;
  for (std::size_t i = 0; i < s.layers.size(); ++i) {
    weather::CloudLayer l = s.layers[i];
    // A VV group comes first and starts at the station: fog.
    const bool fog = s.report.verticalVisibility && i == 0;
    const std::uint32_t slot = fog ? kMetarFogSlot : metarSlot(l);
    l.id = slot;
    auto it = out.find(slot);
    if (it == out.end()) {
      out[slot] = l;
      continue;
    }
    weather::CloudLayer& m = it->second;
    const double top = std::max(m.base_m + m.thickness_m, l.base_m + l.thickness_m);
    if (l.coverage > m.coverage) {
      m.type = l.type;
      m.coverage = l.coverage;
    }
    m.base_m = std::min(m.base_m, l.base_m);
    m.thickness_m = top - m.base_m;
    m.transitionBand_m = std::max(m.transitionBand_m, l.transitionBand_m);
  }
  return out;
}

}  // namespace

MetarPlan planMetar(std::span<const std::string> reports, std::span<const Station> stations,
                    const MetarOptions& options) {
  MetarPlan plan;
  plan.reports = layersFromMetarBatch(reports, stations);
  // The newest report per station (later in the batch wins).
  std::map<std::string, const StationWeather*> newest;
  for (const auto& r : plan.reports)
    if (r) newest[r->station.icao] = &*r;
  std::map<std::string, std::map<std::uint32_t, weather::CloudLayer>> slots;
  std::map<std::uint32_t, weather::CloudLayer> anySlot;  // an example of every slot used
  for (const auto& [icao, s] : newest) {
    slots[icao] = slotted(*s);
    for (const auto& [slot, l] : slots[icao]) anySlot.emplace(slot, l);
  }
  for (std::size_t index = 0; index < stations.size(); ++index) {
    const auto it = newest.find(stations[index].icao);
    if (it == newest.end()) continue;
    const Station& st = stations[index];
    weather::Region r;
    r.id = kMetarRegionBase + static_cast<std::uint32_t>(index);
    r.centerLat_deg = st.lat_deg;
    r.centerLon_deg = st.lon_deg;
    r.sizeX_m = r.sizeY_m = kStationCore_m;
    r.cornerRadius_m = kStationCore_m / 2;
    r.transition_m = options.radius_m;
    const auto& mine = slots[st.icao];
    for (const auto& [slot, example] : anySlot) {
      auto own = mine.find(slot);
      if (own != mine.end()) {
        r.layers.push_back(own->second);
      } else {
        weather::CloudLayer none = example;
        none.coverage = 0;
        // The station's own wind, if it reported any layer.
        if (!mine.empty()) none.wind = mine.begin()->second.wind;
        r.layers.push_back(none);
      }
    }
    plan.changes.push_back(SetRegion{std::move(r), options.timing});
  }
  return plan;
}

Result<std::vector<Station>> parseStationTable(std::string_view text, std::string_view sourceName) {
  std::vector<Station> out;
  std::istringstream in{std::string(text)};
  std::string line;
  int number = 0;
  auto bad = [&](const std::string& what) {
    return fail(ErrorCode::Malformed, std::string(sourceName) + ":" + std::to_string(number) + ": " + what);
  };
  while (std::getline(in, line)) {
    ++number;
    if (!line.empty() && line.back() == '\r') line.pop_back();
    if (number == 1) {
      if (line != "icao,lat_deg,lon_deg,elevation_m") return bad("header must be icao,lat_deg,lon_deg,elevation_m");
      continue;
    }
    if (line.empty() || line[0] == '#') continue;
    std::vector<std::string> f;
    std::stringstream ls(line);
    std::string cell;
    while (std::getline(ls, cell, ',')) f.push_back(cell);
    if (f.size() != 4) return bad(std::to_string(f.size()) + " fields, expected 4");
    Station s;
    s.icao = f[0];
    if (s.icao.size() != 4 || !std::all_of(s.icao.begin(), s.icao.end(), [](char c) {
          return (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9');
        }))
      return bad("icao '" + s.icao + "' is not four letters or digits");
    const char* names[] = {"lat_deg", "lon_deg", "elevation_m"};
    double* values[] = {&s.lat_deg, &s.lon_deg, &s.elevation_m};
    const double lo[] = {-90, -180, -500}, hi[] = {90, 180, 9000};
    for (int k = 0; k < 3; ++k) {
      const std::string& v = f[k + 1];
      double d = 0;
      const auto [end, err] = std::from_chars(v.data(), v.data() + v.size(), d);
      if (err != std::errc() || end != v.data() + v.size() || !std::isfinite(d))
        return bad(std::string(names[k]) + " '" + v + "' is not a number");
      if (d < lo[k] || d > hi[k])
        return bad(std::string(names[k]) + " " + v + " outside [" + std::to_string(int(lo[k])) + ", " +
                   std::to_string(int(hi[k])) + "]");
      *values[k] = d;
    }
    if (std::any_of(out.begin(), out.end(), [&](const Station& o) { return o.icao == s.icao; }))
      return bad("station " + s.icao + " listed twice");
    out.push_back(s);
  }
  if (number == 0) return fail(ErrorCode::Malformed, std::string(sourceName) + ": empty, expected a header line");
  return out;
}

}  // namespace sky::server
