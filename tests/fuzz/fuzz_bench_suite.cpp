// libFuzzer target: skyshell-bench scene suites (TOML, renderer/bench) on
// arbitrary bytes. The parser may refuse, never crash, hang or read out of
// bounds; what it accepts keeps its promises: names valid and unique, a still
// has one camera key, a path 2+ keys with increasing times and a frame count
// in range, and every frame's pose is finite. Seeds: corpus/bench_suite/.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <set>
#include <string_view>

#include "sky/bench/suite.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  const auto suite = sky::bench::parseSuite(text, "fuzz.toml");
  if (!suite) return 0;
  if (suite->scenes.empty() || suite->scenes.size() > sky::bench::kMaxScenes) std::abort();
  std::set<std::string> names;
  for (const auto& s : suite->scenes) {
    if (s.name.empty() || !names.insert(s.name).second) std::abort();
    if (!(s.verticalFov_deg > 0 && s.verticalFov_deg < 179)) std::abort();
    if (s.keys.empty() || (s.keys.size() == 1) != (s.frames == 1)) std::abort();
    if (s.frames > sky::bench::kMaxPathFrames) std::abort();
    for (std::size_t i = 1; i < s.keys.size(); ++i)
      if (!(s.keys[i].t_s > s.keys[i - 1].t_s)) std::abort();
    for (std::uint32_t f = 0; f < s.frames; f += 1 + s.frames / 8) {
      const auto p = sky::bench::poseAt(s, sky::bench::frameTime_s(s, f));
      if (!std::isfinite(p.position.lat_deg) || !std::isfinite(p.position.lon_deg) ||
          !std::isfinite(p.position.alt_m) || !std::isfinite(p.yaw_deg) || !std::isfinite(p.pitch_deg) ||
          !std::isfinite(p.roll_deg))
        std::abort();
    }
  }
  return 0;
}
