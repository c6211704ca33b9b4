// A scenario's [[timeline]]: timed changes in the server API's vocabulary
// (see scenario.hpp). Every entry is checked here as far as it can be on its
// own (fields, ranges, a valid layer or region); whether it applies to the
// weather of its moment is the server's to check when it loads the scenario.
#include <algorithm>
#include <cmath>
#include <string>

#include "scenario_parts.hpp"

namespace sky::weather::detail {

namespace {

using config::number;
using config::onlyKeys;
using config::required;
using config::Where;

std::string position(const Where& where, const toml::source_region& at) {
  return where.source() + ":" + std::to_string(at.begin.line) + ":" + std::to_string(at.begin.column);
}

Result<double> rampOf(const toml::table& t, const std::string& prefix, const Where& where) {
  if (!t.get("ramp_s")) return 0.0;
  auto v = config::numberIn(t, "ramp_s", 0, kMaxRamp_s, prefix, where);
  if (!v) return tl::unexpected(v.error());
  return *v;
}

Result<std::uint32_t> idOf(const toml::table& t, const std::string& prefix, std::int64_t lo, const Where& where) {
  auto node = required(t, "id", prefix, where);
  if (!node) return tl::unexpected(node.error());
  const auto* i = (*node)->as_integer();
  if (!i || i->get() < lo || i->get() > 65535)
    return where.error(ErrorCode::InvalidArgument, (*node)->source(), prefix + "id",
                       "must be an integer in [" + std::to_string(lo) + ", 65535]");
  return static_cast<std::uint32_t>(i->get());
}

Result<Region> parseRegion(const toml::table& t, const std::string& prefix, const Where& where) {
  if (auto r = onlyKeys(t,
                        {"id", "center_lat_deg", "center_lon_deg", "size_x_m", "size_y_m", "corner_radius_m",
                         "rotation_deg", "transition_m", "drifts_with_wind", "layers"},
                        prefix, where);
      !r)
    return tl::unexpected(r.error());
  Region g;
  auto id = idOf(t, prefix, 1, where);
  if (!id) return tl::unexpected(id.error());
  g.id = *id;
  struct Field {
    std::string_view key;
    double* out;
    bool required;
  };
  for (const Field& f : {Field{"center_lat_deg", &g.centerLat_deg, true}, Field{"center_lon_deg", &g.centerLon_deg, true},
                         Field{"size_x_m", &g.sizeX_m, true}, Field{"size_y_m", &g.sizeY_m, true},
                         Field{"corner_radius_m", &g.cornerRadius_m, false},
                         Field{"rotation_deg", &g.rotation_deg, false}, Field{"transition_m", &g.transition_m, false}}) {
    if (!f.required && !t.get(f.key)) continue;
    auto v = number(t, f.key, prefix, where);
    if (!v) return tl::unexpected(v.error());
    *f.out = *v;
  }
  if (const toml::node* drift = t.get("drifts_with_wind")) {
    const auto* b = drift->as_boolean();
    if (!b) return where.error(ErrorCode::Malformed, drift->source(), prefix + "drifts_with_wind", "must be true or false");
    g.driftsWithWind = b->get();
  }
  auto layersNode = required(t, "layers", prefix, where);
  if (!layersNode) return tl::unexpected(layersNode.error());
  const toml::array* layers = (*layersNode)->as_array();
  if (!layers || (!layers->empty() && !layers->is_array_of_tables()))
    return where.error(ErrorCode::Malformed, (*layersNode)->source(), prefix + "layers",
                       "must be an array of layer tables");
  if (layers->size() > kMaxRegionLayers)
    return where.error(ErrorCode::InvalidArgument, (*layersNode)->source(), prefix + "layers",
                       std::to_string(layers->size()) + " layers, at most " + std::to_string(kMaxRegionLayers));
  for (std::size_t i = 0; i < layers->size(); ++i) {
    auto layer = parseLayer(*(*layers)[i].as_table(), prefix + "layers[" + std::to_string(i) + "].", where);
    if (!layer) return tl::unexpected(layer.error());
    g.layers.push_back(*layer);
  }
  if (auto r = validate(g); !r) {
    const std::string field = blamedField(r.error().detail);
    const toml::node* blamed = field.empty() ? nullptr : t.get(field);
    return where.error(ErrorCode::InvalidArgument, blamed ? blamed->source() : t.source(),
                       prefix + (blamed ? field : std::string("?")), r.error().detail);
  }
  return g;
}

Result<TimelineEntry> parseEntry(const toml::table& t, const std::string& prefix, double start_s,
                                 const Where& where) {
  TimelineEntry e;
  e.where = position(where, t.source()) + ": " + prefix.substr(0, prefix.size() - 1);
  auto at = number(t, "at_s", prefix, where);
  if (!at) return tl::unexpected(at.error());
  if (*at < start_s)
    return where.error(ErrorCode::InvalidArgument, t.get("at_s")->source(), prefix + "at_s",
                       std::to_string(*at) + " is before clock.start_s " + std::to_string(start_s));
  e.at_s = *at;
  auto opNode = required(t, "op", prefix, where);
  if (!opNode) return tl::unexpected(opNode.error());
  const auto* opName = (*opNode)->as_string();
  const std::string op = opName ? opName->get() : std::string();
  auto keys = [&](std::initializer_list<std::string_view> allowed) { return onlyKeys(t, allowed, prefix, where); };
  if (op == "set_layer") {
    if (auto r = keys({"at_s", "op", "ramp_s", "layer"}); !r) return tl::unexpected(r.error());
    e.op = TimelineEntry::Op::SetLayer;
    auto layer = config::table(t, "layer", prefix, where);
    if (!layer) return tl::unexpected(layer.error());
    auto l = parseLayer(**layer, prefix + "layer.", where);
    if (!l) return tl::unexpected(l.error());
    e.layer = *l;
  } else if (op == "remove_layer" || op == "remove_region") {
    if (auto r = keys({"at_s", "op", "ramp_s", "id"}); !r) return tl::unexpected(r.error());
    e.op = op == "remove_layer" ? TimelineEntry::Op::RemoveLayer : TimelineEntry::Op::RemoveRegion;
    auto id = idOf(t, prefix, op == "remove_layer" ? 0 : 1, where);
    if (!id) return tl::unexpected(id.error());
    e.id = *id;
  } else if (op == "set_region") {
    if (auto r = keys({"at_s", "op", "ramp_s", "region"}); !r) return tl::unexpected(r.error());
    e.op = TimelineEntry::Op::SetRegion;
    auto region = config::table(t, "region", prefix, where);
    if (!region) return tl::unexpected(region.error());
    auto g = parseRegion(**region, prefix + "region.", where);
    if (!g) return tl::unexpected(g.error());
    e.region = *g;
  } else if (op == "set_clock") {
    if (auto r = keys({"at_s", "op", "rate", "jump_to_s"}); !r) return tl::unexpected(r.error());
    e.op = TimelineEntry::Op::SetClock;
    if (t.get("rate")) {
      auto rate = config::numberIn(t, "rate", 0, 3600, prefix, where);
      if (!rate) return tl::unexpected(rate.error());
      e.rate = *rate;
    }
    if (t.get("jump_to_s")) {
      auto jump = number(t, "jump_to_s", prefix, where);
      if (!jump) return tl::unexpected(jump.error());
      e.jumpTo_s = *jump;
    }
    if (!e.rate && !e.jumpTo_s)
      return where.error(ErrorCode::Malformed, t.source(), prefix + "rate", "set_clock needs rate or jump_to_s");
    return e;
  } else {
    return where.error(ErrorCode::Malformed, (*opNode)->source(), prefix + "op",
                       (opName ? "'" + op + "'" : std::string("value")) +
                           " is not one of set_layer, remove_layer, set_region, remove_region, set_clock");
  }
  auto ramp = rampOf(t, prefix, where);
  if (!ramp) return tl::unexpected(ramp.error());
  e.ramp_s = *ramp;
  return e;
}

}  // namespace

Result<std::vector<TimelineEntry>> parseTimeline(const toml::node* node, double start_s, const Where& where) {
  std::vector<TimelineEntry> out;
  if (!node) return out;
  const toml::array* entries = node->as_array();
  if (!entries || !entries->is_array_of_tables())
    return where.error(ErrorCode::Malformed, node->source(), "timeline", "must be an array of tables ([[timeline]])");
  if (entries->size() > kMaxTimelineEntries)
    return where.error(ErrorCode::InvalidArgument, node->source(), "timeline",
                       std::to_string(entries->size()) + " entries, at most " + std::to_string(kMaxTimelineEntries));
  for (std::size_t i = 0; i < entries->size(); ++i) {
    auto e = parseEntry(*(*entries)[i].as_table(), "timeline[" + std::to_string(i) + "].", start_s, where);
    if (!e) return tl::unexpected(e.error());
    out.push_back(std::move(*e));
  }
  std::stable_sort(out.begin(), out.end(), [](const TimelineEntry& a, const TimelineEntry& b) { return a.at_s < b.at_s; });
  return out;
}

}  // namespace sky::weather::detail
