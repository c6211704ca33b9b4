// libFuzzer target: the IGC flight reader on arbitrary bytes. It must return
// a flight or an error, never crash, hang or read out of bounds; a flight it
// returns keeps the documented invariants (two or more fixes, increasing time).
// Seeds: tests/fuzz/corpus/flight_igc/.
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <string_view>

#include "sky/flight/flight.hpp"
#include "sky/flight/utf8_text.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  const auto flight = sky::flight::parseIgc(text, "fuzz.igc");
  // Nothing from the input reaches a message raw (issue 18): every error and
  // warning is well-formed UTF-8.
  if (!flight && sky::flight::firstInvalidUtf8(flight.error().detail)) std::abort();
  if (flight) {
    for (const auto& w : flight->warnings)
      if (sky::flight::firstInvalidUtf8(w)) std::abort();
    if (flight->fixes.size() < 2) std::abort();
    for (std::size_t i = 1; i < flight->fixes.size(); ++i)
      if (!(flight->fixes[i].time_s > flight->fixes[i - 1].time_s)) std::abort();
  }
  return 0;
}
