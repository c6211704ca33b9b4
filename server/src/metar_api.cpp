// POST /api/metar (see metar_api.hpp).
#include "sky/server/metar_api.hpp"

#include <algorithm>
#include <cmath>
#include <map>
#include <optional>

#include "sky/core/utf8.hpp"
#include "sky/server/api_json.hpp"

namespace sky::server {

namespace {

using nlohmann::json;

constexpr std::size_t kMaxStations = 8192;

tl::unexpected<Error> bad(const std::string& path, const std::string& what) {
  return fail(ErrorCode::Malformed, path + ": " + what);
}

Result<double> number(const json& o, const std::string& path) {
  if (!o.is_number()) return bad(path, "expected a number");
  const double v = o.get<double>();
  if (!std::isfinite(v)) return bad(path, "must be finite");
  return v;
}

}  // namespace

Result<MetarRequest> parseMetarRequest(std::string_view body) {
  const json doc = json::parse(body, nullptr, false);
  if (doc.is_discarded()) return fail(ErrorCode::Malformed, "body: not JSON");
  if (!doc.is_object()) return bad("body", "expected an object");
  MetarRequest r;
  for (auto it = doc.begin(); it != doc.end(); ++it) {
    const std::string& key = it.key();
    const json& v = it.value();
    if (key == "reports" || key == "remove") {
      if (!v.is_array() || v.size() > kMaxMetarReports)
        return bad(key, "expected an array of at most " + std::to_string(kMaxMetarReports) + " strings");
      auto& out = key == "reports" ? r.reports : r.remove;
      for (std::size_t i = 0; i < v.size(); ++i) {
        if (!v[i].is_string()) return bad(key + "[" + std::to_string(i) + "]", "expected a string");
        const std::string text = v[i].get<std::string>();
        if (key == "remove" && (text.size() != 4 || !std::all_of(text.begin(), text.end(), [](char c) {
                                  return (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9');
                                })))
          return bad(key + "[" + std::to_string(i) + "]", "expected a four-character ICAO id");
        out.push_back(text.substr(0, 1024));
      }
    } else if (key == "stations") {
      if (!v.is_array() || v.size() > kMaxStations)
        return bad("stations", "expected an array of at most " + std::to_string(kMaxStations) + " stations");
      std::vector<Station> stations;
      for (std::size_t i = 0; i < v.size(); ++i) {
        const std::string at = "stations[" + std::to_string(i) + "]";
        const json& s = v[i];
        if (!s.is_object()) return bad(at, "expected an object");
        Station st;
        for (auto f = s.begin(); f != s.end(); ++f) {
          if (f.key() == "icao") {
            if (!f.value().is_string()) return bad(at + ".icao", "expected a string");
            st.icao = f.value().get<std::string>();
            continue;
          }
          double* out = f.key() == "lat_deg" ? &st.lat_deg
                        : f.key() == "lon_deg" ? &st.lon_deg
                        : f.key() == "elevation_m" ? &st.elevation_m
                                                   : nullptr;
          if (!out) return bad(at + "." + f.key(), "unknown key (expected icao, lat_deg, lon_deg, elevation_m)");
          auto n = number(f.value(), at + "." + f.key());
          if (!n) return tl::unexpected(n.error());
          *out = *n;
        }
        if (st.icao.size() != 4) return bad(at + ".icao", "expected a four-character ICAO id");
        if (std::abs(st.lat_deg) > 90) return bad(at + ".lat_deg", "outside [-90, 90]");
        if (std::abs(st.lon_deg) > 180) return bad(at + ".lon_deg", "outside [-180, 180]");
        if (st.elevation_m < -500 || st.elevation_m > 9000) return bad(at + ".elevation_m", "outside [-500, 9000]");
        stations.push_back(st);
      }
      r.stations = std::move(stations);
    } else if (key == "radius_m") {
      auto n = number(v, key);
      if (!n) return tl::unexpected(n.error());
      if (*n <= 0 || *n > 2e6) return bad(key, "outside (0, 2000000]");
      r.options.radius_m = *n;
    } else if (key == "ramp_s") {
      auto n = number(v, key);
      if (!n) return tl::unexpected(n.error());
      r.options.timing.ramp_s = *n;
    } else if (key == "at_s") {
      auto n = number(v, key);
      if (!n) return tl::unexpected(n.error());
      r.options.timing.at_s = *n;
    } else if (key == "apply") {
      if (!v.is_boolean()) return bad(key, "expected true or false");
      r.apply = v.get<bool>();
    } else if (key == "author") {
      if (!v.is_string()) return bad(key, "expected a string");
      r.author = std::string(utf8::cut(v.get<std::string>(), kMaxAuthor_bytes));
    } else {
      return bad(key, "unknown key (expected one of: reports, remove, stations, radius_m, ramp_s, at_s, apply, author)");
    }
  }
  if (r.reports.empty() && r.remove.empty()) return bad("reports", "missing (required: reports or remove)");
  return r;
}

namespace {

json notesJson(const std::vector<MetarGroupNote>& notes) {
  json out = json::array();
  for (const MetarGroupNote& n : notes)
    out.push_back({{"group", n.position}, {"text", utf8::sanitise(n.text)}, {"reason", n.reason}});
  return out;
}

}  // namespace

MetarReply handleMetar(const MetarRequest& request, std::span<const Station> serverStations,
                       WeatherService& weather) {
  const std::span<const Station> stations =
      request.stations ? std::span<const Station>(*request.stations) : serverStations;
  const WeatherView now = weather.view();
  const MetarPlan plan = planMetar(request.reports, stations, request.options, {now.layers, now.regions},
                                   request.remove);
  std::map<std::string, std::uint32_t> regionOf;
  for (const MetarStationChange& s : plan.stations) regionOf[s.icao] = s.regionId;
  json reports = json::array();
  for (std::size_t i = 0; i < plan.reports.size(); ++i) {
    const auto& r = plan.reports[i];
    if (r) {
      json layers = json::array();
      for (const auto& l : r->layers) layers.push_back(toJson(l));
      json one = {{"index", i + 1},
                  {"icao", r->station.icao},
                  {"ok", true},
                  {"sky", r->skyObserved ? "read" : "not_observed"},
                  {"layers", layers},
                  {"skipped", notesJson(r->report.skipped)},
                  {"skipped_count", r->report.skippedCount},
                  {"joined", notesJson(r->report.joined)}};
      if (const auto it = regionOf.find(r->station.icao); it != regionOf.end()) one["region_id"] = it->second;
      reports.push_back(std::move(one));
    } else {
      reports.push_back({{"index", i + 1}, {"ok", false}, {"error", utf8::sanitise(r.error().detail)}});
    }
  }
  std::size_t replaced = 0;
  for (const MetarStationChange& s : plan.stations) replaced += s.replaced ? 1 : 0;
  json changes = json::array();
  for (const auto& c : plan.changes) {
    if (const auto* set = std::get_if<SetRegion>(&c))
      changes.push_back({{"op", "set_region"}, {"region", toJson(set->region)}});
    else
      changes.push_back({{"op", "remove_region"}, {"id", std::get<RemoveRegion>(c).regionId}});
  }
  MetarReply reply{200,
                   {{"reports", reports},
                    {"stations",
                     {{"set", plan.stations.size()},
                      {"replaced", replaced},
                      {"reshaped", plan.neighboursReshaped},
                      {"removed", plan.removed.size()}}},
                    {"remove_errors", plan.removeErrors},
                    {"changes", changes},
                    {"applied", nullptr}}};
  if (!request.apply) return reply;
  if (plan.changes.empty()) {
    reply.status = 400;
    reply.body["error"] = "reports: none of the " + std::to_string(plan.reports.size()) +
                          " reports sets a station's weather and nothing is removed; nothing applied";
    return reply;
  }
  const std::string author = request.author.empty() ? "metar" : request.author;
  const std::string what = std::to_string(plan.stations.size()) + " METAR station(s) set (" +
                           std::to_string(replaced) + " replaced), " + std::to_string(plan.neighboursReshaped) +
                           " reshaped, " + std::to_string(plan.removed.size()) + " removed";
  std::optional<AppliedChange> first, last;
  std::size_t submits = 0;
  for (std::size_t at = 0; at < plan.changes.size(); at += kMaxChangesPerSubmit) {
    const auto end = plan.changes.begin() + static_cast<std::ptrdiff_t>(std::min(plan.changes.size(), at + kMaxChangesPerSubmit));
    auto applied = weather.submit(ChangeRequest{{plan.changes.begin() + static_cast<std::ptrdiff_t>(at), end}, author, "metar"});
    if (!applied) {
      reply.status = 400;
      reply.body["error"] = "changes " + std::to_string(at + 1) + "..: " + applied.error().detail +
                            (submits ? " (the " + std::to_string(at) + " changes before were applied)" : "");
      break;
    }
    ++submits;
    if (!first) first = *applied;
    last = *applied;
  }
  if (last)
    reply.body["applied"] = {{"sequence", last->sequence}, {"first_sequence", first->sequence},
                             {"submits", submits},        {"clock_s", last->clock_s},
                             {"summary", what}};
  return reply;
}

}  // namespace sky::server
