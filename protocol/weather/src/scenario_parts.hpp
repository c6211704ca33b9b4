// Pieces of the scenario parser shared by its two files (scenario.cpp:
// clock and layers; scenario_timeline.cpp: the timeline). Private to
// protocol/weather.
#pragma once

#include <string>

#include <toml++/toml.h>

#include "sky/config/toml_fields.hpp"
#include "sky/weather/scenario.hpp"

namespace sky::weather::detail {

// A layer table; errors name `prefix` + the field ("layer[0].coverage").
Result<CloudLayer> parseLayer(const toml::table& t, const std::string& prefix, const config::Where& where);

// The optional [[timeline]] array; entries ordered by at_s.
Result<std::vector<TimelineEntry>> parseTimeline(const toml::node* node, double start_s, const config::Where& where);

// The field a validate() detail blames: "layer 3: coverage 1.4 ..." -> "coverage".
std::string blamedField(const std::string& detail);

}  // namespace sky::weather::detail
