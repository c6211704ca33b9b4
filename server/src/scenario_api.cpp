// POST /api/scenario bodies and errors (see scenario_api.hpp).
#include "sky/server/scenario_api.hpp"

#include <charconv>

#include "sky/core/utf8.hpp"

namespace sky::server {

namespace {

// Scenario names label errors and events: short, printable.
constexpr std::size_t kMaxNameBytes = 200;

bool printable(const std::string& s) {
  for (unsigned char c : s)
    if (c < 0x20 || c == 0x7f) return false;
  return true;
}

}  // namespace

Result<ScenarioUpload> parseScenarioUpload(std::string_view body) {
  const auto first = body.find_first_not_of(" \t\r\n");
  ScenarioUpload out;
  if (first == std::string_view::npos || body[first] != '{') {
    out.toml = std::string(body);
    return out;
  }
  const nlohmann::json doc = nlohmann::json::parse(body, nullptr, false);
  if (doc.is_discarded() || !doc.is_object()) return fail(ErrorCode::Malformed, "body: not a JSON object");
  for (auto it = doc.begin(); it != doc.end(); ++it) {
    const std::string& key = it.key();
    if (key != "toml" && key != "name" && key != "author")
      return fail(ErrorCode::Malformed, key + ": unknown key (expected one of: toml, name, author)");
    if (!it->is_string()) return fail(ErrorCode::Malformed, key + ": expected a string");
  }
  if (!doc.contains("toml")) return fail(ErrorCode::Malformed, "toml: missing (required)");
  out.toml = doc.at("toml").get<std::string>();
  if (doc.contains("name")) {
    out.name = doc.at("name").get<std::string>();
    if (out.name.empty() || out.name.size() > kMaxNameBytes || !printable(out.name))
      return fail(ErrorCode::InvalidArgument, "name: 1 to 200 printable characters");
  }
  if (doc.contains("author")) out.author = std::string(utf8::cut(doc.at("author").get<std::string>(), kMaxNameBytes));
  return out;
}

nlohmann::json scenarioErrorJson(const std::string& detail, const std::string& name) {
  nlohmann::json j = {{"error", detail}};
  if (detail.rfind(name + ":", 0) != 0) return j;
  // name:line:col: field: what
  const std::string rest = detail.substr(name.size() + 1);
  int line = 0, column = 0;
  const char* p = rest.data();
  const char* end = rest.data() + rest.size();
  auto [afterLine, e1] = std::from_chars(p, end, line);
  if (e1 != std::errc() || afterLine == end || *afterLine != ':') return j;
  auto [afterColumn, e2] = std::from_chars(afterLine + 1, end, column);
  if (e2 != std::errc() || end - afterColumn < 2 || afterColumn[0] != ':' || afterColumn[1] != ' ') return j;
  const std::string tail(afterColumn + 2, end);
  j["file"] = name;
  j["line"] = line;
  j["column"] = column;
  const auto colon = tail.find(": ");
  if (colon != std::string::npos) j["field"] = tail.substr(0, colon);
  return j;
}

}  // namespace sky::server
