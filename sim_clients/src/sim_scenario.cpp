// skyshell-scenario files (see sim_scenario.hpp).
#include "sky/sim/sim_scenario.hpp"

#include <algorithm>
#include <fstream>
#include <sstream>

#include "sky/config/toml_fields.hpp"
#include "sky/flight/utf8_text.hpp"

namespace sky::sim {

namespace {

using config::Where;

// TOML value -> JSON, as it stands (dates and times as their TOML text).
nlohmann::json toJson(const toml::node& node) {
  if (const auto* t = node.as_table()) {
    nlohmann::json out = nlohmann::json::object();
    for (auto&& [k, v] : *t) out[std::string(k.str())] = toJson(v);
    return out;
  }
  if (const auto* a = node.as_array()) {
    nlohmann::json out = nlohmann::json::array();
    for (const auto& v : *a) out.push_back(toJson(v));
    return out;
  }
  if (const auto* s = node.as_string()) return s->get();
  if (const auto* i = node.as_integer()) return i->get();
  if (const auto* f = node.as_floating_point()) return f->get();
  if (const auto* b = node.as_boolean()) return b->get();
  std::ostringstream text;
  if (const auto* d = node.as_date()) text << d->get();
  if (const auto* tm = node.as_time()) text << tm->get();
  if (const auto* dt = node.as_date_time()) text << dt->get();
  return text.str();
}

Result<ScenarioAction> parseAction(const toml::table& t, std::size_t index, const Where& where) {
  const std::string prefix = "action[" + std::to_string(index) + "].";
  if (auto r = config::onlyKeys(t, {"at_s", "what", "api", "request"}, prefix, where); !r) return tl::unexpected(r.error());
  ScenarioAction a;
  a.line = t.source().begin.line;
  auto at = config::number(t, "at_s", prefix, where);
  if (!at) return tl::unexpected(at.error());
  if (*at < 0) return where.error(ErrorCode::InvalidArgument, t.get("at_s")->source(), prefix + "at_s", "must be >= 0");
  a.at_s = *at;
  auto what = config::string(t, "what", prefix, where);
  if (!what) return tl::unexpected(what.error());
  a.what = *what;
  if (t.contains("api")) {
    auto api = config::string(t, "api", prefix, where);
    if (!api) return tl::unexpected(api.error());
    if (*api != "changes" && *api != "metar")
      return where.error(ErrorCode::InvalidArgument, t.get("api")->source(), prefix + "api",
                         "must be \"changes\" or \"metar\"");
    a.target = "/api/" + *api;
  }
  auto request = config::table(t, "request", prefix, where);
  if (!request) return tl::unexpected(request.error());
  a.request = toJson(**request);
  return a;
}

}  // namespace

Result<SimScenario> parseSimScenario(std::string_view text, std::string_view sourceName,
                                     const std::filesystem::path& baseDir) {
  const Where where(flight::messageText(sourceName));
  // TOML is UTF-8 (TOML 1.0 "Spec"): ill-formed bytes are refused before the
  // parser sees them, so no message and no JSON body can carry them on.
  if (const auto bad = flight::firstInvalidUtf8(text)) {
    const std::string_view before = text.substr(0, *bad);
    const auto lineStart = before.rfind('\n');
    const std::size_t line = 1 + static_cast<std::size_t>(std::count(before.begin(), before.end(), '\n'));
    const std::size_t column = *bad - (lineStart == std::string_view::npos ? 0 : lineStart + 1) + 1;
    return fail(ErrorCode::Malformed, where.source() + ":" + std::to_string(line) + ":" + std::to_string(column) +
                                          ": not UTF-8");
  }
  auto parsed = config::parseText(text, where);
  if (!parsed) return tl::unexpected(parsed.error());
  const toml::table& root = *parsed;
  if (auto r = config::onlyKeys(root, {"flight", "action"}, "", where); !r) return tl::unexpected(r.error());

  SimScenario s;
  auto flight = config::table(root, "flight", "", where);
  if (!flight) return tl::unexpected(flight.error());
  const toml::table& f = **flight;
  if (auto r = config::onlyKeys(f, {"file", "speed", "start_s", "end_s"}, "flight.", where); !r)
    return tl::unexpected(r.error());
  auto file = config::string(f, "file", "flight.", where);
  if (!file) return tl::unexpected(file.error());
  if (file->empty()) return where.error(ErrorCode::InvalidArgument, f.get("file")->source(), "flight.file", "is empty");
  s.flightFile = std::filesystem::path(*file).is_absolute() ? std::filesystem::path(*file) : baseDir / *file;
  if (f.get("speed")) {
    auto v = config::numberIn(f, "speed", 0.05, 100.0, "flight.", where);
    if (!v) return tl::unexpected(v.error());
    s.speed = *v;
  }
  if (f.get("start_s")) {
    auto v = config::numberIn(f, "start_s", 0.0, 1e9, "flight.", where);
    if (!v) return tl::unexpected(v.error());
    s.start_s = *v;
  }
  if (f.get("end_s")) {
    auto v = config::numberIn(f, "end_s", 0.0, 1e9, "flight.", where);
    if (!v) return tl::unexpected(v.error());
    if (*v <= s.start_s)
      return where.error(ErrorCode::InvalidArgument, f.get("end_s")->source(), "flight.end_s",
                         "must be after start_s (" + std::to_string(s.start_s) + ")");
    s.end_s = *v;
  }

  if (const toml::node* actions = root.get("action")) {
    const toml::array* list = actions->as_array();
    if (!list) return where.error(ErrorCode::Malformed, actions->source(), "action", "must be an array of tables ([[action]])");
    std::size_t i = 0;
    for (const toml::node& n : *list) {
      const toml::table* t = n.as_table();
      if (!t) return where.error(ErrorCode::Malformed, n.source(), "action[" + std::to_string(i) + "]", "must be a table");
      auto a = parseAction(*t, i, where);
      if (!a) return tl::unexpected(a.error());
      if (a->at_s < s.start_s || (s.end_s >= 0 && a->at_s > s.end_s))
        return where.error(ErrorCode::InvalidArgument, t->get("at_s")->source(), "action[" + std::to_string(i) + "].at_s",
                           std::to_string(a->at_s) + " outside the flown part of the flight");
      s.actions.push_back(std::move(*a));
      ++i;
    }
  }
  std::stable_sort(s.actions.begin(), s.actions.end(),
                   [](const ScenarioAction& a, const ScenarioAction& b) { return a.at_s < b.at_s; });
  return s;
}

Result<SimScenario> loadSimScenario(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) return fail(ErrorCode::Io, flight::messageText(path.string()) + ": cannot open for reading");
  std::ostringstream text;
  text << in.rdbuf();
  return parseSimScenario(text.str(), path.string(), path.parent_path());
}

}  // namespace sky::sim
