// libFuzzer target: host datagrams into the weather server's CIGI weather
// input: decode, then map Weather Control / Environmental Region Control onto
// changes. Either may refuse (naming packet and field), never crash, hang or
// read out of bounds; every change mapped passes the model's own validation
// (layers and regions in range). Each input is mapped twice by one mapper,
// as a host resending: the second time must produce nothing.
// Seeds: tests/fuzz/corpus/cigi_weather/.
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <span>

#include "sky/server/cigi_weather.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const auto datagram = sky::cigi::decodeDatagram(std::span<const std::uint8_t>(data, size));
  if (!datagram) return 0;
  sky::server::CigiWeatherMapper mapper;
  const auto changes = mapper.map(*datagram);
  if (!changes) {
    if (changes.error().detail.empty()) std::abort();
    return 0;
  }
  for (const auto& c : *changes) {
    if (const auto* set = std::get_if<sky::server::SetLayer>(&c))
      if (!sky::weather::validate(set->layer)) std::abort();
    if (const auto* region = std::get_if<sky::server::SetRegion>(&c))
      if (!sky::weather::validate(region->region)) std::abort();
  }
  const auto again = mapper.map(*datagram);
  if (!again || !again->empty()) std::abort();
  return 0;
}
