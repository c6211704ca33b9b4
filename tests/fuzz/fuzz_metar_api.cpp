// libFuzzer target: the METAR inputs of the weather server's API: a POST
// /api/metar body (JSON) and a station table (CSV, --metar-stations). Each
// may refuse with a reason (naming path or line), never crash, hang or read
// out of bounds; a body that parses is planned against the table that
// parsed (or a fixed one), and every region planned passes validation.
// Seeds: tests/fuzz/corpus/metar_api/.
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <string_view>

#include "sky/server/metar_api.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  auto table = sky::server::parseStationTable(text, "fuzz.csv");
  if (!table && table.error().detail.empty()) std::abort();
  auto request = sky::server::parseMetarRequest(text);
  if (!request) {
    if (request.error().detail.empty()) std::abort();
    return 0;
  }
  const std::vector<sky::server::Station> fixed = {{"LIPQ", 45.8275, 13.4722, 12}, {"LJLJ", 46.2237, 14.4576, 388}};
  const auto& stations = request->stations ? *request->stations : fixed;
  const auto plan = sky::server::planMetar(request->reports, stations, request->options);
  for (const auto& c : plan.changes)
    if (!sky::weather::validate(std::get<sky::server::SetRegion>(c).region)) std::abort();
  return 0;
}
