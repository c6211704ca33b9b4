// METAR batch -> station regions (see metar_changes.hpp).
#include "sky/server/metar_changes.hpp"

#include <algorithm>
#include <bit>
#include <charconv>
#include <cmath>
#include <map>
#include <numbers>
#include <set>
#include <sstream>
#include <unordered_map>

#include "sky/weather/precipitation.hpp"

namespace sky::server {

std::uint32_t metarSlot(const weather::CloudLayer& layer) {
  using weather::CloudType;
  if (layer.type == CloudType::Cumulonimbus) return kMetarCumulonimbusSlot;
  // Towering cumulus is mapped to a deep cumulus (metar.hpp).
  if (layer.type == CloudType::Cumulus && layer.thickness_m >= kToweringCumulusThickness_m)
    return kMetarToweringCumulusSlot;
  const auto band = std::upper_bound(kMetarBandTops_m.begin(), kMetarBandTops_m.end(), layer.base_m);
  return kMetarFirstBandSlot + static_cast<std::uint32_t>(band - kMetarBandTops_m.begin());
}

namespace {

// Mean Earth radius (IUGG R1): distances between stations are measured on
// the sphere, then shortened by kSphereMargin so that they never exceed the
// WGS84 geodesic the regions' weights use (the two differ by under 0.5 %).
constexpr double kMeanEarthRadius_m = 6371008.8;
constexpr double kSphereMargin = 0.99;
constexpr double kDegToRad = std::numbers::pi / 180.0;
// A degree of latitude on that sphere, m: two stations further apart in
// latitude than d / this are further apart than d.
constexpr double kSphereMetresPerDegree = kMeanEarthRadius_m * kDegToRad;

// A station's layers in slots, by slot.
std::vector<weather::CloudLayer> slotted(const StationWeather& s) {
  std::map<std::uint32_t, weather::CloudLayer> out;
  for (std::size_t i = 0; i < s.layers.size(); ++i) {
    weather::CloudLayer l = s.layers[i];
    // Fog (a VV group, or an obscuration: metar.hpp) comes first and starts at the station.
    const bool fog = l.type == weather::CloudType::Fog;
    const std::uint32_t slot =
        fog ? kMetarFogSlot : weather::isPrecipitation(l.type) ? kMetarPrecipitationSlot : metarSlot(l);
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
  std::vector<weather::CloudLayer> v;
  for (auto& [slot, l] : out) v.push_back(l);
  return v;
}

// Whether a region is a METAR station's: an id of theirs, the mark only
// stations carry (their weather replaces every layer: CIGI and the console
// never set it) and their shape (a circle that stays put), so that a region
// another input put in that range (a CIGI host may use any 16-bit id) is
// neither reshaped nor taken over.
bool isStationRegion(const weather::Region& r) {
  return isMetarRegion(r.id) && r.replacesAllLayers && !r.driftsWithWind && r.rotation_deg == 0 &&
         r.sizeX_m == r.sizeY_m && r.cornerRadius_m == r.sizeX_m / 2;
}

// Longitude as LiveWeather stores a region's centre.
double storedLon(double lon_deg) { return std::remainder(lon_deg, 360.0); }

// A position to 1e-7 degree (about a centimetre): a station's region is
// found at its station's position whatever the arithmetic its centre went
// through since it was placed (the weather's regions come back with their
// longitude normalised by GeographicLib, 14.4576 as 14.457600000000014,
// and through the store's JSON).
struct PositionKey {
  std::int64_t lat, lon;
  bool operator==(const PositionKey&) const = default;
};
struct PositionHash {
  std::size_t operator()(const PositionKey& k) const {
    return static_cast<std::size_t>((std::uint64_t(k.lat) * 1099511628211ull) ^ std::uint64_t(k.lon));
  }
};
PositionKey keyOf(double lat_deg, double lon_deg) {
  double lon = storedLon(lon_deg);
  if (lon >= 180 - 0.5e-7) lon -= 360;  // 180 and -180 are one meridian
  return {std::llround(lat_deg * 1e7), std::llround(lon * 1e7)};
}

std::uint32_t icaoHash(std::string_view icao) {
  std::uint32_t h = 2166136261u;  // FNV-1a
  for (unsigned char c : icao) {
    h ^= c;
    h *= 16777619u;
  }
  return h;
}

// A station's place, for the geometry.
struct Site {
  double lat_deg = 0, lon_deg = 0;
  double x = 0, y = 0, z = 0;  // unit vector
  double core_m = kStationCoreRadius_m, transition_m = 0;
};

Site siteAt(double lat_deg, double lon_deg) {
  const double lat = lat_deg * kDegToRad, lon = lon_deg * kDegToRad;
  return {lat_deg, lon_deg, std::cos(lat) * std::cos(lon), std::cos(lat) * std::sin(lon), std::sin(lat)};
}

// Great-circle distance on the sphere, shortened by kSphereMargin.
double safeDistance_m(const Site& a, const Site& b) {
  const double chord = std::hypot(a.x - b.x, a.y - b.y, a.z - b.z);
  return kSphereMargin * 2 * kMeanEarthRadius_m * std::asin(std::min(1.0, chord / 2));
}

// Every site's core and transition (see the scheme in metar_changes.hpp).
// Sites further apart than reach_m in latitude are never compared: by
// latitude order this is O(n k), k the sites within reach_m of a latitude.
void shape(std::vector<Site>& sites, double radius_m) {
  const double reach_m = std::max(radius_m + 2 * kStationCoreRadius_m, 4 * kStationCoreRadius_m) / kSphereMargin;
  const double reach_deg = reach_m / kSphereMetresPerDegree;
  std::vector<std::size_t> order(sites.size());
  for (std::size_t i = 0; i < order.size(); ++i) order[i] = i;
  std::sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) { return sites[a].lat_deg < sites[b].lat_deg; });
  // Calls f(i, j, distance) for every pair within reach, both ways.
  auto pairs = [&](auto&& f) {
    for (std::size_t n = 0; n < order.size(); ++n)
      for (std::size_t m = n + 1; m < order.size() && sites[order[m]].lat_deg - sites[order[n]].lat_deg <= reach_deg;
           ++m) {
        const double d = safeDistance_m(sites[order[n]], sites[order[m]]);
        f(order[n], order[m], d);
        f(order[m], order[n], d);
      }
  };
  for (Site& s : sites) s.core_m = kStationCoreRadius_m;
  pairs([&](std::size_t i, std::size_t, double d) {
    sites[i].core_m = std::max(kMinStationCoreRadius_m, std::min(sites[i].core_m, d / 4));
  });
  for (Site& s : sites) s.transition_m = radius_m;
  pairs([&](std::size_t i, std::size_t j, double d) {
    sites[i].transition_m = std::max(0.0, std::min(sites[i].transition_m, d - sites[i].core_m - sites[j].core_m));
  });
}

void setGeometry(weather::Region& r, const Site& s) {
  r.sizeX_m = r.sizeY_m = 2 * s.core_m;
  r.cornerRadius_m = s.core_m;
  r.rotation_deg = 0;
  r.transition_m = s.transition_m;
}

bool sameGeometry(const weather::Region& a, const weather::Region& b) {
  return a.sizeX_m == b.sizeX_m && a.sizeY_m == b.sizeY_m && a.cornerRadius_m == b.cornerRadius_m &&
         a.transition_m == b.transition_m;
}

// Whether report a was made after report b (by its time; a report without
// one, or of the same minute, counts as later when it comes later).
bool newer(const MetarReport& a, const MetarReport& b) {
  if (!a.time || !b.time) return true;
  const int ma = (a.time->day * 24 + a.time->hour) * 60 + a.time->minute;
  const int mb = (b.time->day * 24 + b.time->hour) * 60 + b.time->minute;
  // Days of different months: a jump of over half a month backwards is the
  // month turning over.
  constexpr int kHalfMonth_min = 15 * 24 * 60;
  if (ma < mb - kHalfMonth_min) return true;
  if (ma > mb + kHalfMonth_min) return false;
  return ma >= mb;
}

}  // namespace

MetarPlan planMetar(std::span<const std::string> reports, std::span<const Station> stations,
                    const MetarOptions& options, const MetarContext& now, std::span<const std::string> remove) {
  MetarPlan plan;
  plan.reports = layersFromMetarBatch(reports, stations);

  // The newest report with a sky per station, stations in the order of
  // their first report.
  std::vector<std::string> order;
  std::unordered_map<std::string, std::size_t> newest;  // icao -> index into plan.reports
  for (std::size_t i = 0; i < plan.reports.size(); ++i) {
    const auto& r = plan.reports[i];
    if (!r || !r->skyObserved) continue;
    auto [it, added] = newest.try_emplace(r->station.icao, i);
    if (added) order.push_back(r->station.icao);
    else if (newer(r->report, plan.reports[it->second]->report)) it->second = i;
  }

  // The METAR stations already in the weather, by position.
  std::unordered_map<PositionKey, std::size_t, PositionHash> existingAt;  // -> index into now.regions
  std::set<std::uint32_t> taken;
  for (std::size_t k = 0; k < now.regions.size(); ++k) {
    taken.insert(now.regions[k].id);
    if (isStationRegion(now.regions[k]))
      existingAt.emplace(keyOf(now.regions[k].centerLat_deg, now.regions[k].centerLon_deg), k);
  }
  std::unordered_map<std::string_view, const Station*> table;
  for (const Station& s : stations) table.emplace(s.icao, &s);

  // Stations removed on purpose.
  std::set<std::size_t> goes;  // indices into now.regions
  for (const std::string& icao : remove) {
    const auto st = table.find(icao);
    if (st == table.end()) {
      plan.removeErrors.push_back("remove " + icao + ": not in the station table");
      continue;
    }
    const auto at = existingAt.find(keyOf(st->second->lat_deg, st->second->lon_deg));
    if (at == existingAt.end()) {
      plan.removeErrors.push_back("remove " + icao + ": the station has no weather to remove");
      continue;
    }
    if (goes.insert(at->second).second) plan.removed.push_back({icao, now.regions[at->second].id, true});
  }

  // The layers every station region clears: the global ones.
  std::vector<weather::CloudLayer> cleared;
  for (weather::CloudLayer l : now.layers) {
    l.coverage = 0;
    cleared.push_back(l);
  }

  // The new stations' regions, ids and layers; geometry follows.
  struct Placed {
    weather::Region region;
    std::size_t site = 0;
  };
  std::vector<Placed> placed;
  std::vector<Site> sites;
  std::set<std::size_t> replacedExisting;  // indices into now.regions
  const std::uint32_t idCount = kMetarRegionLast - kMetarRegionFirst + 1;
  for (const std::string& icao : order) {
    const std::size_t index = newest.at(icao);
    StationWeather& sw = *plan.reports[index];
    const Station& st = sw.station;
    weather::Region r;
    r.centerLat_deg = st.lat_deg;
    r.centerLon_deg = storedLon(st.lon_deg);
    r.layers = slotted(sw);
    // The report is the whole sky at the station: layers that come later (a
    // forecast loaded after it) are cleared there too.
    r.replacesAllLayers = true;
    // Every global layer, and every layer of other regions reaching the
    // station, at coverage 0 (its own slot of the same id wins).
    auto clear = [&](const weather::CloudLayer& l) {
      if (std::none_of(r.layers.begin(), r.layers.end(), [&](const auto& own) { return own.id == l.id; })) {
        weather::CloudLayer none = l;
        none.coverage = 0;
        r.layers.push_back(none);
      }
    };
    for (const weather::CloudLayer& l : cleared) clear(l);
    for (const weather::Region& other : now.regions)
      if (!isStationRegion(other) && weather::regionWeight(other, st.lat_deg, st.lon_deg) > 0)
        for (const weather::CloudLayer& l : other.layers) clear(l);
    if (r.layers.size() > weather::kMaxRegionLayers) {
      plan.reports[index] = fail(ErrorCode::InvalidArgument,
                                 "report " + std::to_string(index + 1) + ": " + icao + ": " +
                                     std::to_string(r.layers.size()) +
                                     " layers with the global and regional ones it clears, at most " +
                                     std::to_string(weather::kMaxRegionLayers));
      continue;
    }
    std::sort(r.layers.begin(), r.layers.end(), [](const auto& a, const auto& b) { return a.id < b.id; });
    const auto existing = existingAt.find(keyOf(st.lat_deg, st.lon_deg));
    bool replaced = false;
    if (existing != existingAt.end()) {
      r.id = now.regions[existing->second].id;
      replaced = true;
      replacedExisting.insert(existing->second);
      // A report and a removal of one station: the report wins.
      goes.erase(existing->second);
      std::erase_if(plan.removed, [&](const MetarStationChange& c) { return c.regionId == r.id; });
    } else {
      const std::uint32_t h = icaoHash(icao);
      for (std::uint32_t k = 0; k < idCount && r.id == 0; ++k) {
        const std::uint32_t id = kMetarRegionFirst + (h + k) % idCount;
        if (!taken.count(id)) r.id = id;
      }
      if (r.id == 0) {
        plan.reports[index] = fail(ErrorCode::InvalidArgument, "report " + std::to_string(index + 1) + ": " +
                                                                   icao + ": no free METAR region id");
        continue;
      }
      taken.insert(r.id);
    }
    plan.stations.push_back({icao, r.id, replaced});
    placed.push_back({std::move(r), sites.size()});
    sites.push_back(siteAt(st.lat_deg, st.lon_deg));
  }
  std::vector<std::size_t> kept;  // earlier stations that stay, indices into now.regions
  for (const auto& [key, k] : existingAt)
    if (!replacedExisting.count(k) && !goes.count(k)) kept.push_back(k);
  std::sort(kept.begin(), kept.end());
  const std::size_t firstKept = sites.size();
  for (std::size_t k : kept) sites.push_back(siteAt(now.regions[k].centerLat_deg, now.regions[k].centerLon_deg));
  shape(sites, options.radius_m);

  for (Placed& p : placed) {
    setGeometry(p.region, sites[p.site]);
    plan.changes.push_back(SetRegion{std::move(p.region), options.timing});
  }
  for (std::size_t n = 0; n < kept.size(); ++n) {
    weather::Region r = now.regions[kept[n]];
    setGeometry(r, sites[firstKept + n]);
    if (sameGeometry(r, now.regions[kept[n]])) continue;
    plan.changes.push_back(SetRegion{std::move(r), options.timing});
    ++plan.neighboursReshaped;
  }
  for (std::size_t k : goes) plan.changes.push_back(RemoveRegion{now.regions[k].id, options.timing});
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
