// libFuzzer target: an X-Plane .fdr file through the reader dispatch,
// checked by flight_reader_check.hpp. Seeds: tests/fuzz/corpus/flight_fdr/.
#include <cstddef>
#include <cstdint>
#include <string_view>

#include "flight_reader_check.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  sky::fuzz::checkFlightParse(sky::flight::parseFlight(text, "fuzz.fdr"));
  return 0;
}
