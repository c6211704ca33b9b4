// libFuzzer target: skyshell-scenario files (TOML) on arbitrary bytes. The
// parser may refuse, never crash, hang or read out of bounds; what it accepts
// keeps its promises: speed in range, actions sorted and inside the flown part,
// every request a JSON object. Seeds: tests/fuzz/corpus/sim_scenario/.
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <string_view>

#include "sky/flight/utf8_text.hpp"
#include "sky/sim/sim_scenario.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  const auto s = sky::sim::parseSimScenario(text, "fuzz.toml", "/base");
  // Refusals never echo ill-formed UTF-8 (issue 18).
  if (!s) {
    if (sky::flight::firstInvalidUtf8(s.error().detail)) std::abort();
    return 0;
  }
  // Accepted text is well-formed: it goes into log lines and JSON bodies.
  for (const auto& a : s->actions)
    if (sky::flight::firstInvalidUtf8(a.what)) std::abort();
  if (s->speed < 0.05 || s->speed > 100) std::abort();
  for (std::size_t i = 0; i < s->actions.size(); ++i) {
    const auto& a = s->actions[i];
    if (i > 0 && a.at_s < s->actions[i - 1].at_s) std::abort();
    if (a.at_s < s->start_s || (s->end_s >= 0 && a.at_s > s->end_s)) std::abort();
    if (!a.request.is_object()) std::abort();
    (void)a.request.dump();
  }
  return 0;
}
