// Scenario TOML parsing (see scenario.hpp). toml++ gives every node its source
// position, so each error can point at the line that caused it.
#include "sky/weather/scenario.hpp"

#include <cmath>
#include <set>
#include <string>

#include "scenario_parts.hpp"
#include "sky/config/toml_fields.hpp"

namespace sky::weather {

namespace {

// The strict field readers every TOML input shares (protocol/config).
// (number: TOML integers are accepted where a float is expected, base_m = 1500.)
using config::number;
using config::onlyKeys;
using config::required;
using config::table;
using config::Where;

std::string singleQuoted(std::string_view s) { return "'" + std::string(s) + "'"; }

Result<ClockSettings> parseClock(const toml::table& root, const Where& where) {
  auto clock = table(root, "clock", "", where);
  if (!clock) return tl::unexpected(clock.error());
  const toml::table& t = **clock;
  if (auto r = onlyKeys(t, {"start_s", "rate"}, "clock.", where); !r)
    return tl::unexpected(r.error());
  ClockSettings out;
  auto start = number(t, "start_s", "clock.", where);
  if (!start) return tl::unexpected(start.error());
  auto rate = number(t, "rate", "clock.", where);
  if (!rate) return tl::unexpected(rate.error());
  // Same range as Hello.clock_rate on the stream: 0 freezes the weather, 3600
  // plays an hour per second.
  if (*rate < 0 || *rate > 3600)
    return where.error(ErrorCode::InvalidArgument, t.get("rate")->source(), "clock.rate",
                       std::to_string(*rate) + " outside [0, 3600]");
  out.start_s = *start;
  out.rate = *rate;
  return out;
}

}  // namespace

namespace detail {

// The field validate() blames: its detail reads "layer <id>: <field> <value> ...".
std::string blamedField(const std::string& detail) {
  const auto colon = detail.find(": ");
  if (colon == std::string::npos) return {};
  const auto begin = colon + 2;
  const auto end = detail.find(' ', begin);
  return detail.substr(begin, end == std::string::npos ? std::string::npos : end - begin);
}

Result<CloudLayer> parseLayer(const toml::table& t, const std::string& prefix, const Where& where) {
  if (auto r = onlyKeys(t,
                        {"id", "type", "base_m", "thickness_m", "transition_band_m", "coverage",
                         "density", "wind"},
                        prefix, where);
      !r)
    return tl::unexpected(r.error());

  CloudLayer layer;

  auto idNode = required(t, "id", prefix, where);
  if (!idNode) return tl::unexpected(idNode.error());
  const auto* id = (*idNode)->as_integer();
  if (!id || id->get() < 0 || id->get() > std::int64_t{UINT32_MAX})
    return where.error(ErrorCode::InvalidArgument, (*idNode)->source(), prefix + "id",
                       "must be an integer in [0, 4294967295]");
  layer.id = static_cast<std::uint32_t>(id->get());

  auto typeNode = required(t, "type", prefix, where);
  if (!typeNode) return tl::unexpected(typeNode.error());
  const auto* typeName = (*typeNode)->as_string();
  std::optional<CloudType> type;
  if (typeName) type = cloudTypeFromString(typeName->get());
  if (!type) {
    std::string names;
    for (std::uint8_t i = 0; i <= kMaxCloudType; ++i)
      names += (i ? ", " : "") + std::string(toString(static_cast<CloudType>(i)));
    return where.error(ErrorCode::InvalidArgument, (*typeNode)->source(), prefix + "type",
                       (typeName ? singleQuoted(typeName->get()) : std::string("value")) +
                           " is not a cloud type (one of: " + names + ")");
  }
  layer.type = *type;

  struct Field {
    std::string_view key;
    double* out;
  };
  for (const Field& f : {Field{"base_m", &layer.base_m}, Field{"thickness_m", &layer.thickness_m},
                         Field{"transition_band_m", &layer.transitionBand_m},
                         Field{"coverage", &layer.coverage}, Field{"density", &layer.density}}) {
    auto v = number(t, f.key, prefix, where);
    if (!v) return tl::unexpected(v.error());
    *f.out = *v;
  }

  auto wind = table(t, "wind", prefix, where);
  if (!wind) return tl::unexpected(wind.error());
  const std::string windPrefix = prefix + "wind.";
  if (auto r = onlyKeys(**wind, {"speed_mps", "from_deg", "vertical_mps"}, windPrefix, where); !r)
    return tl::unexpected(r.error());
  for (const Field& f : {Field{"speed_mps", &layer.wind.speed_mps},
                         Field{"from_deg", &layer.wind.fromDirection_deg},
                         Field{"vertical_mps", &layer.wind.vertical_mps}}) {
    auto v = number(**wind, f.key, windPrefix, where);
    if (!v) return tl::unexpected(v.error());
    *f.out = *v;
  }

  if (auto r = validate(layer); !r) {
    // Point at the value validate() blames; fall back to the layer's header.
    const std::string field = blamedField(r.error().detail);
    const toml::node* blamed = field.empty() ? nullptr : t.at_path(field).node();
    return where.error(ErrorCode::InvalidArgument, blamed ? blamed->source() : t.source(),
                       prefix + (field.empty() ? std::string("?") : field), r.error().detail);
  }
  return layer;
}

}  // namespace detail

Result<Scenario> parseScenario(std::string_view text, std::string_view sourceName) {
  const Where where(sourceName);
  auto parsed = config::parseText(text, where);
  if (!parsed) return tl::unexpected(parsed.error());
  const toml::table& root = *parsed;
  if (auto r = onlyKeys(root, {"clock", "layer", "timeline"}, "", where); !r) return tl::unexpected(r.error());

  Scenario scenario;
  auto clock = parseClock(root, where);
  if (!clock) return tl::unexpected(clock.error());
  scenario.clock = *clock;

  // No [[layer]] at all is a clear sky.
  if (const toml::node* layersNode = root.get("layer")) {
    const toml::array* layers = layersNode->as_array();
    if (!layers || !layers->is_array_of_tables())
      return where.error(ErrorCode::Malformed, layersNode->source(), "layer",
                         "must be an array of tables ([[layer]])");
    if (layers->size() > kMaxScenarioLayers)
      return where.error(ErrorCode::InvalidArgument, layersNode->source(), "layer",
                         std::to_string(layers->size()) + " layers, at most " +
                             std::to_string(kMaxScenarioLayers));
    std::set<std::uint32_t> ids;
    for (std::size_t i = 0; i < layers->size(); ++i) {
      const toml::table& t = *(*layers)[i].as_table();
      auto layer = detail::parseLayer(t, "layer[" + std::to_string(i) + "].", where);
      if (!layer) return tl::unexpected(layer.error());
      if (!ids.insert(layer->id).second)
        return where.error(ErrorCode::InvalidArgument, t.get("id")->source(),
                           "layer[" + std::to_string(i) + "].id",
                           "id " + std::to_string(layer->id) + " used by an earlier layer");
      scenario.layers.push_back(*layer);
    }
  }
  auto timeline = detail::parseTimeline(root.get("timeline"), scenario.clock.start_s, where);
  if (!timeline) return tl::unexpected(timeline.error());
  scenario.timeline = std::move(*timeline);
  return scenario;
}

}  // namespace sky::weather
