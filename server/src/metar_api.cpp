// POST /api/metar (see metar_api.hpp).
#include "sky/server/metar_api.hpp"

#include <cmath>

#include "sky/core/utf8.hpp"
#include "sky/server/api_json.hpp"

namespace sky::server {

namespace {

using nlohmann::json;

constexpr std::size_t kMaxReports = 64;
constexpr std::size_t kMaxStations = 4096;

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
    if (key == "reports") {
      if (!v.is_array() || v.empty() || v.size() > kMaxReports)
        return bad("reports", "expected an array of 1 to " + std::to_string(kMaxReports) + " strings");
      for (std::size_t i = 0; i < v.size(); ++i) {
        if (!v[i].is_string()) return bad("reports[" + std::to_string(i) + "]", "expected a string");
        r.reports.push_back(v[i].get<std::string>().substr(0, 1024));
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
      return bad(key, "unknown key (expected one of: reports, stations, radius_m, ramp_s, at_s, apply, author)");
    }
  }
  if (r.reports.empty()) return bad("reports", "missing (required)");
  return r;
}

MetarReply handleMetar(const MetarRequest& request, std::span<const Station> serverStations,
                       WeatherService& weather) {
  const std::span<const Station> stations =
      request.stations ? std::span<const Station>(*request.stations) : serverStations;
  const MetarPlan plan = planMetar(request.reports, stations, request.options);
  json reports = json::array();
  std::size_t good = 0;
  for (std::size_t i = 0; i < plan.reports.size(); ++i) {
    const auto& r = plan.reports[i];
    if (r) {
      ++good;
      json layers = json::array();
      for (const auto& l : r->layers) layers.push_back(toJson(l));
      reports.push_back({{"index", i + 1}, {"icao", r->station.icao}, {"ok", true}, {"layers", layers}});
    } else {
      reports.push_back({{"index", i + 1}, {"ok", false}, {"error", r.error().detail}});
    }
  }
  json changes = json::array();
  for (const auto& c : plan.changes)
    changes.push_back({{"op", "set_region"}, {"region", toJson(std::get<SetRegion>(c).region)}});
  MetarReply reply{200, {{"reports", reports}, {"changes", changes}, {"applied", nullptr}}};
  if (!request.apply) return reply;
  if (plan.changes.empty()) {
    reply.status = 400;
    reply.body["error"] = "reports: none of the " + std::to_string(plan.reports.size()) +
                          " reports maps to weather; nothing applied";
    return reply;
  }
  auto applied = weather.submit(
      ChangeRequest{plan.changes, request.author.empty() ? "metar" : request.author, "metar"});
  if (!applied) {
    reply.status = 400;
    reply.body["error"] = applied.error().detail;
    return reply;
  }
  reply.body["applied"] = {{"sequence", applied->sequence}, {"clock_s", applied->clock_s},
                           {"summary", applied->summary}};
  return reply;
}

}  // namespace sky::server
