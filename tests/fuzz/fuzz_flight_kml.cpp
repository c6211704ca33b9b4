// libFuzzer target: the same bytes as a .kml (expat, track choice) and as a
// .kmz (zip directory, bounded inflate, then the KML reader), and as a .kml
// with a track picked by name, each checked by flight_reader_check.hpp.
// Seeds: tests/fuzz/corpus/flight_kml/ (KML documents and KMZ archives).
#include <cstddef>
#include <cstdint>
#include <string_view>

#include "flight_reader_check.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view bytes(reinterpret_cast<const char*>(data), size);
  sky::fuzz::checkFlightParse(sky::flight::parseFlight(bytes, "fuzz.kml"));
  sky::fuzz::checkFlightParse(sky::flight::parseFlight(bytes, "fuzz.kmz"));
  sky::flight::ReadOptions pick;
  pick.track = "DLH400";
  sky::fuzz::checkFlightParse(sky::flight::parseKml(bytes, "fuzz.kml", pick));
  return 0;
}
