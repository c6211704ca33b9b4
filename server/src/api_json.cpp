// JSON of the HTTP API (see api_json.hpp).
#include "sky/server/api_json.hpp"

#include <initializer_list>

#include "sky/core/utf8.hpp"
#include "sky/weather/region.hpp"

namespace sky::server {

namespace {

using nlohmann::json;

tl::unexpected<Error> bad(const std::string& path, const std::string& what) {
  return fail(ErrorCode::Malformed, path + ": " + what);
}

Result<void> onlyKeys(const json& o, std::initializer_list<const char*> allowed, const std::string& path) {
  for (auto it = o.begin(); it != o.end(); ++it) {
    bool known = false;
    for (const char* a : allowed) known = known || it.key() == a;
    if (!known) {
      std::string list;
      for (const char* a : allowed) list += (list.empty() ? "" : ", ") + std::string(a);
      return bad(path + (path.empty() ? "" : ".") + it.key(), "unknown key (expected one of: " + list + ")");
    }
  }
  return {};
}

Result<double> number(const json& o, const char* key, const std::string& path) {
  const std::string at = path + "." + key;
  if (!o.contains(key)) return bad(at, "missing (required)");
  const json& v = o.at(key);
  if (!v.is_number()) return bad(at, "expected a number");
  return v.get<double>();
}

Result<std::optional<double>> optionalNumber(const json& o, const char* key, const std::string& path) {
  if (!o.contains(key)) return std::optional<double>{};
  auto v = number(o, key, path);
  if (!v) return tl::unexpected(v.error());
  return std::optional<double>(*v);
}

Result<std::uint32_t> id(const json& o, const char* key, const std::string& path) {
  const std::string at = path + "." + key;
  if (!o.contains(key)) return bad(at, "missing (required)");
  const json& v = o.at(key);
  if (!v.is_number_integer() || v.get<std::int64_t>() < 0 || v.get<std::int64_t>() > 65535)
    return bad(at, "expected an integer in [0, 65535]");
  return static_cast<std::uint32_t>(v.get<std::int64_t>());
}

Result<Timing> timing(const json& o, const std::string& path) {
  Timing t;
  auto ramp = optionalNumber(o, "ramp_s", path);
  if (!ramp) return tl::unexpected(ramp.error());
  t.ramp_s = ramp->value_or(0.0);
  auto at = optionalNumber(o, "at_s", path);
  if (!at) return tl::unexpected(at.error());
  t.at_s = *at;
  return t;
}

Result<weather::CloudLayer> parseLayer(const json& o, const std::string& path) {
  if (!o.is_object()) return bad(path, "expected an object");
  if (auto r = onlyKeys(o, {"id", "type", "base_m", "thickness_m", "transition_band_m", "coverage", "density", "wind"},
                        path);
      !r)
    return tl::unexpected(r.error());
  weather::CloudLayer l;
  auto i = id(o, "id", path);
  if (!i) return tl::unexpected(i.error());
  l.id = *i;
  if (!o.contains("type") || !o.at("type").is_string()) return bad(path + ".type", "expected a cloud type name");
  const auto type = weather::cloudTypeFromString(o.at("type").get<std::string>());
  if (!type) return bad(path + ".type", "'" + o.at("type").get<std::string>() + "' is not a cloud type");
  l.type = *type;
  struct Field {
    const char* key;
    double* out;
  };
  for (const Field& f : {Field{"base_m", &l.base_m}, Field{"thickness_m", &l.thickness_m},
                         Field{"transition_band_m", &l.transitionBand_m}, Field{"coverage", &l.coverage},
                         Field{"density", &l.density}}) {
    auto v = number(o, f.key, path);
    if (!v) return tl::unexpected(v.error());
    *f.out = *v;
  }
  if (!o.contains("wind") || !o.at("wind").is_object()) return bad(path + ".wind", "expected an object");
  const json& w = o.at("wind");
  if (auto r = onlyKeys(w, {"speed_mps", "from_deg", "vertical_mps"}, path + ".wind"); !r) return tl::unexpected(r.error());
  for (const Field& f : {Field{"speed_mps", &l.wind.speed_mps}, Field{"from_deg", &l.wind.fromDirection_deg},
                         Field{"vertical_mps", &l.wind.vertical_mps}}) {
    auto v = number(w, f.key, path + ".wind");
    if (!v) return tl::unexpected(v.error());
    *f.out = *v;
  }
  return l;
}

Result<weather::Region> parseRegion(const json& o, const std::string& path, bool withPlacement) {
  if (!o.is_object()) return bad(path, "expected an object");
  if (auto r = withPlacement
                   ? onlyKeys(o, {"id", "center_lat_deg", "center_lon_deg", "size_x_m", "size_y_m", "corner_radius_m",
                                  "rotation_deg", "transition_m", "drifts_with_wind", "layers", "placed_at_clock_s",
                                  "replaces_all_layers"},
                              path)
                   : onlyKeys(o, {"id", "center_lat_deg", "center_lon_deg", "size_x_m", "size_y_m", "corner_radius_m",
                                  "rotation_deg", "transition_m", "drifts_with_wind", "layers",
                                  "replaces_all_layers"},
                              path);
      !r)
    return tl::unexpected(r.error());
  weather::Region g;
  auto i = id(o, "id", path);
  if (!i) return tl::unexpected(i.error());
  g.id = *i;
  struct Field {
    const char* key;
    double* out;
    bool required;
  };
  for (const Field& f : {Field{"center_lat_deg", &g.centerLat_deg, true}, Field{"center_lon_deg", &g.centerLon_deg, true},
                         Field{"size_x_m", &g.sizeX_m, true}, Field{"size_y_m", &g.sizeY_m, true},
                         Field{"corner_radius_m", &g.cornerRadius_m, false},
                         Field{"rotation_deg", &g.rotation_deg, false}, Field{"transition_m", &g.transition_m, false},
                         Field{"placed_at_clock_s", &g.placedAtClock_s, false}}) {
    if (!f.required && !o.contains(f.key)) continue;
    auto v = number(o, f.key, path);
    if (!v) return tl::unexpected(v.error());
    *f.out = *v;
  }
  if (o.contains("drifts_with_wind")) {
    if (!o.at("drifts_with_wind").is_boolean()) return bad(path + ".drifts_with_wind", "expected true or false");
    g.driftsWithWind = o.at("drifts_with_wind").get<bool>();
  }
  if (o.contains("replaces_all_layers")) {
    if (!o.at("replaces_all_layers").is_boolean()) return bad(path + ".replaces_all_layers", "expected true or false");
    g.replacesAllLayers = o.at("replaces_all_layers").get<bool>();
  }
  if (!o.contains("layers") || !o.at("layers").is_array()) return bad(path + ".layers", "expected an array of layers");
  const json& layers = o.at("layers");
  if (layers.size() > weather::kMaxRegionLayers)
    return bad(path + ".layers", std::to_string(layers.size()) + " layers, at most " +
                                     std::to_string(weather::kMaxRegionLayers));
  for (std::size_t k = 0; k < layers.size(); ++k) {
    auto l = parseLayer(layers.at(k), path + ".layers[" + std::to_string(k) + "]");
    if (!l) return tl::unexpected(l.error());
    g.layers.push_back(*l);
  }
  return g;
}

Result<WeatherChange> change(const json& o, const std::string& path) {
  if (!o.is_object()) return bad(path, "expected an object");
  if (!o.contains("op") || !o.at("op").is_string()) return bad(path + ".op", "expected set_layer, remove_layer, set_clock, set_region or remove_region");
  const std::string op = o.at("op").get<std::string>();
  if (op == "set_layer") {
    if (auto r = onlyKeys(o, {"op", "layer", "ramp_s", "at_s"}, path); !r) return tl::unexpected(r.error());
    if (!o.contains("layer")) return bad(path + ".layer", "missing (required)");
    auto l = parseLayer(o.at("layer"), path + ".layer");
    if (!l) return tl::unexpected(l.error());
    auto t = timing(o, path);
    if (!t) return tl::unexpected(t.error());
    return SetLayer{*l, *t};
  }
  if (op == "remove_layer") {
    if (auto r = onlyKeys(o, {"op", "id", "ramp_s", "at_s"}, path); !r) return tl::unexpected(r.error());
    auto i = id(o, "id", path);
    if (!i) return tl::unexpected(i.error());
    auto t = timing(o, path);
    if (!t) return tl::unexpected(t.error());
    return RemoveLayer{*i, *t};
  }
  if (op == "set_clock") {
    if (auto r = onlyKeys(o, {"op", "rate", "jump_to_s"}, path); !r) return tl::unexpected(r.error());
    SetClock c;
    auto rate = optionalNumber(o, "rate", path);
    if (!rate) return tl::unexpected(rate.error());
    auto jump = optionalNumber(o, "jump_to_s", path);
    if (!jump) return tl::unexpected(jump.error());
    c.rate = *rate;
    c.jumpTo_s = *jump;
    return c;
  }
  if (op == "set_region") {
    if (auto r = onlyKeys(o, {"op", "region", "ramp_s", "at_s"}, path); !r) return tl::unexpected(r.error());
    if (!o.contains("region")) return bad(path + ".region", "missing (required)");
    auto g = parseRegion(o.at("region"), path + ".region", false);
    if (!g) return tl::unexpected(g.error());
    auto t = timing(o, path);
    if (!t) return tl::unexpected(t.error());
    return SetRegion{*g, *t};
  }
  if (op == "remove_region") {
    if (auto r = onlyKeys(o, {"op", "id", "ramp_s", "at_s"}, path); !r) return tl::unexpected(r.error());
    auto i = id(o, "id", path);
    if (!i) return tl::unexpected(i.error());
    auto t = timing(o, path);
    if (!t) return tl::unexpected(t.error());
    return RemoveRegion{*i, *t};
  }
  return bad(path + ".op",
             "'" + op + "' is not one of set_layer, remove_layer, set_clock, set_region, remove_region");
}

}  // namespace

Result<ChangeRequest> parseChangeRequest(std::string_view body) {
  const json doc = json::parse(body, nullptr, false);
  if (doc.is_discarded()) return fail(ErrorCode::Malformed, "body: not JSON");
  if (!doc.is_object()) return bad("body", "expected an object");
  if (auto r = onlyKeys(doc, {"author", "changes"}, ""); !r) return tl::unexpected(r.error());
  ChangeRequest req;
  if (doc.contains("author")) {
    if (!doc.at("author").is_string()) return bad("author", "expected a string");
    // Issue 18: a byte cut here split a character, the broken name was stored
    // and every later GET /api/events threw while writing it.
    req.author = std::string(utf8::cut(doc.at("author").get<std::string>(), kMaxAuthor_bytes));
  }
  if (!doc.contains("changes") || !doc.at("changes").is_array()) return bad("changes", "expected an array");
  const json& list = doc.at("changes");
  for (std::size_t i = 0; i < list.size(); ++i) {
    auto c = change(list.at(i), "changes[" + std::to_string(i) + "]");
    if (!c) return tl::unexpected(c.error());
    req.changes.push_back(*c);
  }
  return req;
}

Result<FlashRequest> parseFlashRequest(std::string_view body) {
  const json doc = json::parse(body, nullptr, false);
  if (doc.is_discarded()) return fail(ErrorCode::Malformed, "body: not JSON");
  if (!doc.is_object()) return bad("body", "expected an object");
  if (auto r = onlyKeys(doc, {"lightning"}, ""); !r) return tl::unexpected(r.error());
  if (!doc.contains("lightning") || !doc.at("lightning").is_object())
    return bad("lightning", "expected an object (the only event one can ask for)");
  const json& o = doc.at("lightning");
  if (auto r = onlyKeys(o, {"lat_deg", "lon_deg", "kind", "energy_j"}, "lightning"); !r) return tl::unexpected(r.error());
  FlashRequest req;
  auto lat = number(o, "lat_deg", "lightning");
  if (!lat) return tl::unexpected(lat.error());
  if (!(*lat >= -90 && *lat <= 90)) return bad("lightning.lat_deg", "outside [-90, 90]");
  auto lon = number(o, "lon_deg", "lightning");
  if (!lon) return tl::unexpected(lon.error());
  if (!(*lon >= -180 && *lon <= 180)) return bad("lightning.lon_deg", "outside [-180, 180]");
  req.lat_deg = *lat;
  req.lon_deg = *lon;
  if (o.contains("kind")) {
    const json& k = o.at("kind");
    const auto kind = k.is_string() ? weather::flashKindFromString(k.get<std::string>()) : std::nullopt;
    if (!kind) return bad("lightning.kind", "expected \"cloud-to-ground\" or \"in-cloud\"");
    req.kind = *kind;
  }
  auto energy = optionalNumber(o, "energy_j", "lightning");
  if (!energy) return tl::unexpected(energy.error());
  if (*energy && !(**energy > 0 && **energy <= weather::kMaxFlashEnergy_j))
    return bad("lightning.energy_j", "outside (0, 1e11]");
  req.energy_j = energy->value_or(weather::kTypicalFlashEnergy_j);
  return req;
}

nlohmann::json toJson(const weather::LightningFlash& f) {
  return {{"seed", std::to_string(f.seed)},  // a string: JSON numbers lose 64-bit integers
          {"time_s", f.time_s},
          {"lat_deg", f.lat_deg},
          {"lon_deg", f.lon_deg},
          {"bottom_m", f.bottom_m},
          {"top_m", f.top_m},
          {"kind", weather::toString(f.kind)},
          {"energy_j", f.energy_j}};
}

Result<WeatherChange> changeFromJson(const nlohmann::json& object, const std::string& path) {
  return change(object, path);
}

nlohmann::json toJson(const WeatherChange& c) {
  auto timed = [](json j, const Timing& t) {
    if (t.ramp_s != 0) j["ramp_s"] = t.ramp_s;
    if (t.at_s) j["at_s"] = *t.at_s;
    return j;
  };
  if (const auto* s = std::get_if<SetLayer>(&c)) return timed({{"op", "set_layer"}, {"layer", toJson(s->layer)}}, s->timing);
  if (const auto* r = std::get_if<RemoveLayer>(&c)) return timed({{"op", "remove_layer"}, {"id", r->layerId}}, r->timing);
  if (const auto* s = std::get_if<SetRegion>(&c)) {
    json region = toJson(s->region);
    region.erase("placed_at_clock_s");  // the server places a region when it applies it
    return timed({{"op", "set_region"}, {"region", region}}, s->timing);
  }
  if (const auto* r = std::get_if<RemoveRegion>(&c))
    return timed({{"op", "remove_region"}, {"id", r->regionId}}, r->timing);
  const auto& k = std::get<SetClock>(c);
  json j = {{"op", "set_clock"}};
  if (k.rate) j["rate"] = *k.rate;
  if (k.jumpTo_s) j["jump_to_s"] = *k.jumpTo_s;
  return j;
}

Result<weather::CloudLayer> layerFromJson(const nlohmann::json& object, const std::string& path) {
  return parseLayer(object, path);
}

nlohmann::json toJson(const weather::CloudLayer& l) {
  return {{"id", l.id},
          {"type", std::string(weather::toString(l.type))},
          {"base_m", l.base_m},
          {"thickness_m", l.thickness_m},
          {"transition_band_m", l.transitionBand_m},
          {"coverage", l.coverage},
          {"density", l.density},
          {"wind", {{"speed_mps", l.wind.speed_mps}, {"from_deg", l.wind.fromDirection_deg},
                    {"vertical_mps", l.wind.vertical_mps}}}};
}

Result<weather::Region> regionFromJson(const nlohmann::json& object, const std::string& path, bool withPlacement) {
  return parseRegion(object, path, withPlacement);
}

nlohmann::json toJson(const weather::Region& r) {
  json layers = json::array();
  for (const auto& l : r.layers) layers.push_back(toJson(l));
  return {{"id", r.id},
          {"center_lat_deg", r.centerLat_deg},
          {"center_lon_deg", r.centerLon_deg},
          {"size_x_m", r.sizeX_m},
          {"size_y_m", r.sizeY_m},
          {"corner_radius_m", r.cornerRadius_m},
          {"rotation_deg", r.rotation_deg},
          {"transition_m", r.transition_m},
          {"drifts_with_wind", r.driftsWithWind},
          {"replaces_all_layers", r.replacesAllLayers},
          {"placed_at_clock_s", r.placedAtClock_s},
          {"layers", layers}};
}

nlohmann::json toJson(const WeatherView& v) {
  json layers = json::array();
  for (const auto& l : v.layers) layers.push_back(toJson(l));
  json regions = json::array();
  for (const auto& r : v.regions) regions.push_back(toJson(r));
  json pending = json::array();
  for (const auto& p : v.pending)
    pending.push_back({{"sequence", p.sequence}, {"start_s", p.start_s}, {"end_s", p.end_s}, {"summary", p.summary},
                       {"kind", p.kind}});
  return {{"clock_s", v.clock_s}, {"clock_rate", v.clockRate}, {"sequence", v.lastSequence},
          {"version", v.version}, {"layers", layers}, {"regions", regions}, {"pending", pending}};
}

nlohmann::json toJson(const ChangeEvent& e) {
  return {{"sequence", e.sequence}, {"clock_s", e.clock_s}, {"wall_time_ms", e.wallTime_ms},
          {"author", utf8::sanitise(e.author)}, {"source", utf8::sanitise(e.source)},
          {"summary", utf8::sanitise(e.summary)}};
}

std::string dumpJson(const nlohmann::json& value) {
  return value.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace);
}

std::string errorJson(std::string_view detail) {
  // Long enough for any message of ours with the value it quotes.
  constexpr std::size_t kMaxDetail_bytes = 1024;
  const std::string text = utf8::sanitiseAndCut(detail, kMaxDetail_bytes);
  json j = {{"error", text}};
  // "path: what" -> field = path, for the console to show next to the field.
  if (const auto colon = text.find(": "); colon != std::string::npos) j["field"] = text.substr(0, colon);
  return dumpJson(j);
}

}  // namespace sky::server
