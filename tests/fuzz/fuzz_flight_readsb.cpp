// libFuzzer target: a readsb / tar1090 trace (.json, plain or gzip'd)
// through the reader dispatch, and the same bytes with an aircraft picked,
// each checked by flight_reader_check.hpp. Seeds: tests/fuzz/corpus/flight_readsb/.
#include <cstddef>
#include <cstdint>
#include <string_view>

#include "flight_reader_check.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view bytes(reinterpret_cast<const char*>(data), size);
  sky::fuzz::checkFlightParse(sky::flight::parseFlight(bytes, "fuzz.json"));
  sky::flight::ReadOptions pick;
  pick.icao24 = "3c6444";
  sky::fuzz::checkFlightParse(sky::flight::parseReadsbTrace(bytes, "fuzz.json", pick));
  return 0;
}
