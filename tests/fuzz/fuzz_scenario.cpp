// libFuzzer target: scenario files (protocol/weather, read by the server and
// the headless renderer) (TOML) on arbitrary bytes. The parser may refuse,
// never crash, hang or read out of bounds; every scenario it accepts has a
// clock rate in range, layers that pass weather::validate with unique ids,
// and a timeline ordered by at_s, none before the start, each entry with a
// ramp in range, a valid layer or region, a set_clock with a rate in range
// or a jump, and the place it came from. Seeds: tests/fuzz/corpus/scenario/.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <set>
#include <string_view>

#include "sky/weather/scenario.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using Op = sky::weather::TimelineEntry::Op;
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  const auto s = sky::weather::parseScenario(text, "fuzz.toml");
  if (!s) return 0;
  if (s->clock.rate < 0 || s->clock.rate > 3600) std::abort();
  std::set<std::uint32_t> ids;
  for (const auto& layer : s->layers) {
    if (!sky::weather::validate(layer)) std::abort();
    if (!ids.insert(layer.id).second) std::abort();
  }
  if (s->timeline.size() > sky::weather::kMaxTimelineEntries) std::abort();
  double previous = -INFINITY;
  for (const auto& e : s->timeline) {
    if (!std::isfinite(e.at_s) || e.at_s < s->clock.start_s || e.at_s < previous) std::abort();
    previous = e.at_s;
    if (e.where.rfind("fuzz.toml:", 0) != 0) std::abort();
    if (!(e.ramp_s >= 0 && e.ramp_s <= sky::weather::kMaxRamp_s)) std::abort();
    switch (e.op) {
      case Op::SetLayer:
        if (!sky::weather::validate(e.layer)) std::abort();
        break;
      case Op::SetRegion:
        if (!sky::weather::validate(e.region)) std::abort();
        break;
      case Op::RemoveLayer:
      case Op::RemoveRegion:
        if (e.id > 65535) std::abort();
        break;
      case Op::SetClock:
        if (!e.rate && !e.jumpTo_s) std::abort();
        if (e.rate && !(*e.rate >= 0 && *e.rate <= 3600)) std::abort();
        if (e.jumpTo_s && !std::isfinite(*e.jumpTo_s)) std::abort();
        if (e.ramp_s != 0) std::abort();
        break;
    }
  }
  return 0;
}
