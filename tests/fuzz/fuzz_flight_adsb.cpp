// libFuzzer target: a .csv flight file through the reader dispatch (an ADS-B
// header goes to the ADS-B CSV reader), and the same bytes through the ADS-B
// reader with one aircraft picked and feet chosen, each checked by
// flight_reader_check.hpp. Seeds: tests/fuzz/corpus/flight_adsb/.
#include <cstddef>
#include <cstdint>
#include <string_view>

#include "flight_reader_check.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  sky::fuzz::checkFlightParse(sky::flight::parseFlight(text, "fuzz.csv"));
  sky::flight::ReadOptions pick;
  pick.icao24 = "3c6444";
  pick.altitudeUnit = sky::flight::AltitudeUnit::Feet;
  sky::fuzz::checkFlightParse(sky::flight::parseAdsbCsv(text, "fuzz.csv", pick));
  return 0;
}
