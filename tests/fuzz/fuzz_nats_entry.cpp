// libFuzzer target: what a server or relay reads from NATS. Entries of the
// weather's change log as a follower reads them back from JetStream
// (server/src/nats_entry.cpp), then their state folded into a live weather
// (LiveWeather::restore), as nats_weather.cpp does (or, for a state too
// large for an entry, the name of its file on the files stream); and the same bytes as a
// record of the cluster's registry bucket (cluster_member.cpp), which any
// publisher could have put there; and as the manifest of a forecast file on
// the files stream (nats_files.cpp: "<bytes> <chunk bytes>"); and as the
// global part or a cell of the weather by S2 cell that a relay watches
// (nats_cells.cpp), joined with the cell into a state a relay restores. One
// target for all of them (not one each): the inputs are text of the same origin, and each target costs deploy/test its
// fuzzing time. The decoders may refuse (with a reason), never crash, hang
// or read out of bounds; what they accept re-encodes to the same; a state
// passed on is restored or refused, never thrown.
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <string_view>

#include "sky/server/cluster_member.hpp"
#include "sky/server/live_weather.hpp"
#include "sky/server/nats_cells.hpp"
#include "sky/server/nats_entry.hpp"
#include "sky/server/nats_log.hpp"

namespace {

void checkClusterMember(std::string_view bytes) {
  auto member = sky::server::decodeClusterMember(bytes);
  if (!member) {
    if (member.error().detail.empty()) std::abort();
    return;
  }
  auto again = sky::server::decodeClusterMember(sky::server::clusterMemberJson(*member).dump());
  if (!again || sky::server::clusterMemberJson(*again) != sky::server::clusterMemberJson(*member)) std::abort();
}

// A manifest is accepted only within its bounds, and re-encodes to the
// same text.
void checkFileManifest(std::string_view bytes) {
  constexpr std::uint64_t kMax = std::uint64_t{1} << 30;
  auto m = sky::server::parseFileManifest(bytes, kMax);
  if (!m) {
    if (m.error().detail.empty()) std::abort();
    return;
  }
  if (m->bytes > kMax || m->chunkBytes == 0 || m->chunkBytes > sky::server::kMaxNatsFileChunk_bytes) std::abort();
  if (sky::server::encodeFileManifest(*m) != bytes) std::abort();
}

// The weather by cell: the parts decode or are refused with a reason; what
// decodes re-encodes to the same; a global part joined with the bytes as a
// cell is restored or refused.
void checkCells(std::string_view bytes) {
  auto cell = sky::server::decodeCellPart(bytes);
  if (!cell && cell.error().detail.empty()) std::abort();
  if (cell) {
    auto again = sky::server::decodeCellPart(sky::server::encodeCellPart(cell->sequence, cell->content.dump()));
    if (!again || again->sequence != cell->sequence || again->content != cell->content) std::abort();
  }
  auto global = sky::server::decodeGlobalPart(bytes);
  if (!global) {
    if (global.error().detail.empty()) std::abort();
    return;
  }
  auto again = sky::server::decodeGlobalPart(sky::server::encodeGlobalPart(*global));
  if (!again || again->sequence != global->sequence || again->log != global->log || again->cells != global->cells ||
      again->entry.has_value() != global->entry.has_value() || (global->entry && again->entry->state != global->entry->state))
    std::abort();
  if (!global->entry) return;
  std::vector<const nlohmann::json*> parts;
  if (cell && !cell->content.is_null()) parts.push_back(&cell->content);
  const sky::server::WallClock::time_point t0{std::chrono::hours(1000)};
  sky::server::LiveWeather weather(sky::server::Scenario{}, t0, [t0] { return t0; },
                                   [] { return std::int64_t{1700000000000}; });
  auto restored = weather.restore(sky::server::joinState(global->entry->state, parts), {});
  if (!restored && restored.error().detail.empty()) std::abort();
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view bytes(reinterpret_cast<const char*>(data), size);
  checkClusterMember(bytes);
  checkFileManifest(bytes);
  checkCells(bytes);
  auto entry = sky::server::decodeLogEntry(bytes);
  if (!entry) {
    if (entry.error().detail.empty()) std::abort();
    return 0;
  }
  auto again = sky::server::decodeLogEntry(sky::server::encodeLogEntry(*entry));
  if (!again || again->term != entry->term || again->kind != entry->kind || again->state != entry->state ||
      again->event.has_value() != entry->event.has_value() ||
      again->stateFile.has_value() != entry->stateFile.has_value() ||
      (entry->stateFile && (again->stateFile->key != entry->stateFile->key ||
                            again->stateFile->bytes != entry->stateFile->bytes)))
    std::abort();
  // A state in the files stream: only its name and size are in the entry.
  if (entry->stateFile) {
    if (entry->stateFile->bytes > sky::server::kMaxStateFile_bytes || !entry->state.is_null()) std::abort();
    return 0;
  }
  const sky::server::WallClock::time_point t0{std::chrono::hours(1000)};
  sky::server::LiveWeather weather(sky::server::Scenario{}, t0, [t0] { return t0; },
                                   [] { return std::int64_t{1700000000000}; });
  std::vector<sky::server::ChangeEvent> events;
  if (entry->event) events.push_back(*entry->event);
  auto restored = weather.restore(entry->state, std::move(events));
  if (!restored && restored.error().detail.empty()) std::abort();
  return 0;
}
