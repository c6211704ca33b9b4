// libFuzzer target: entries of the weather's NATS change log as a follower
// reads them back from JetStream (server/src/nats_entry.cpp), then their state
// folded into a live weather (LiveWeather::restore), as nats_weather.cpp does.
// The decoder may refuse (with a reason), never crash, hang or read out of
// bounds; what it accepts re-encodes to an entry that decodes the same; a
// state it passes on is restored or refused, never thrown.
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <string_view>

#include "sky/server/live_weather.hpp"
#include "sky/server/nats_entry.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view bytes(reinterpret_cast<const char*>(data), size);
  auto entry = sky::server::decodeLogEntry(bytes);
  if (!entry) {
    if (entry.error().detail.empty()) std::abort();
    return 0;
  }
  auto again = sky::server::decodeLogEntry(sky::server::encodeLogEntry(*entry));
  if (!again || again->term != entry->term || again->kind != entry->kind || again->state != entry->state ||
      again->event.has_value() != entry->event.has_value())
    std::abort();
  const sky::server::WallClock::time_point t0{std::chrono::hours(1000)};
  sky::server::LiveWeather weather(sky::server::Scenario{}, t0, [t0] { return t0; },
                                   [] { return std::int64_t{1700000000000}; });
  std::vector<sky::server::ChangeEvent> events;
  if (entry->event) events.push_back(*entry->event);
  auto restored = weather.restore(entry->state, std::move(events));
  if (!restored && restored.error().detail.empty()) std::abort();
  return 0;
}
