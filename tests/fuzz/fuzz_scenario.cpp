// libFuzzer target: scenario files (protocol/weather, read by the server and the headless renderer) (TOML) on arbitrary
// bytes. The parser may refuse, never crash, hang or read out of bounds; every
// scenario it accepts has a clock rate in range and layers that pass
// weather::validate with unique ids. Seeds: tests/fuzz/corpus/scenario/.
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <set>
#include <string_view>

#include "sky/weather/scenario.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  const auto s = sky::weather::parseScenario(text, "fuzz.toml");
  if (!s) return 0;
  if (s->clock.rate < 0 || s->clock.rate > 3600) std::abort();
  std::set<std::uint32_t> ids;
  for (const auto& layer : s->layers) {
    if (!sky::weather::validate(layer)) std::abort();
    if (!ids.insert(layer.id).second) std::abort();
  }
  return 0;
}
