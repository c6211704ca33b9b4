// libFuzzer target: skyshell-conformance's two inputs from outside, a
// replay's frames.jsonl and the weather server's conformance answers, on
// arbitrary bytes (the first byte picks which). Either may be refused, never
// crash, hang or grow without bound; what is accepted keeps its promises:
// fields in range, points in flight-time order, station names safe to put in
// a table. Seeds: tests/fuzz/corpus/conformance_track/.
#include <cctype>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <sstream>
#include <string>

#include "sky/sim/conformance_track.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size == 0) return 0;
  const std::string text(reinterpret_cast<const char*>(data) + 1, size - 1);
  if (data[0] & 1) {
    std::istringstream in(text);
    const auto track = sky::sim::sampleTrack(in, "frames.jsonl", {5.0, 50});
    if (!track) return 0;
    if (track->size() > 50) std::abort();
    for (std::size_t i = 0; i < track->size(); ++i) {
      const auto& p = (*track)[i];
      if (!(std::abs(p.lat_deg) <= 90 && std::abs(p.lon_deg) <= 180 && std::isfinite(p.alt_m) &&
            std::isfinite(p.weatherClock_s)))
        std::abort();
      if (i > 0 && p.flight_s < (*track)[i - 1].flight_s + 5.0) std::abort();
    }
    return 0;
  }
  const sky::sim::TrackPoint at{7, 12.5, 46.1, 13.9, 1500, 5000};
  const auto check = sky::sim::readPointCheck(at, text, 20);
  if (!check) return 0;
  if (check->stations.size() > 20 || check->gridOk > check->gridPoints) std::abort();
  for (const auto& s : check->stations) {
    if (s.name.empty() || s.name.size() > 16 + 10) std::abort();  // "region <id>" may be longer than an ICAO
    for (const char c : s.name)
      if (!(std::isalnum(static_cast<unsigned char>(c)) || c == '-' || c == '?' || c == ' ')) std::abort();
    if (!(s.distance_km >= 0 && s.distance_km <= 20040) || s.oktasOff < 0 || s.oktasOff > 8) std::abort();
  }
  const std::vector<sky::sim::PointCheck> all{*check};
  (void)sky::sim::trackJson(all, {}).dump();
  (void)sky::sim::trackMarkdown(all, {});
  return 0;
}
