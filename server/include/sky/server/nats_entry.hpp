// One entry of the weather's change log on JetStream (nats_weather.hpp): the
// whole state a leader made, with the change's event, or with no event when a
// server takes the lead. Entries are read back from the stream by every
// server, so decodeLogEntry treats them as hostile bytes.
#pragma once

#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>

#include <nlohmann/json.hpp>

#include "sky/core/result.hpp"
#include "sky/server/change.hpp"

namespace sky::server {

// The largest entry written or read: NATS's default max_payload (1 MiB);
// a leader writes at most what the server it is connected to takes
// (NatsLog::messageLimit: a deployment may set max_payload lower). A
// cockpit's weather is a few KiB; a state past this (a continent of METAR
// stations' regions: 4.2 MB for 4745) goes to the files stream, and the
// entry names it (LogEntry::stateFile).
inline constexpr std::size_t kMaxLogEntry_bytes = 1024 * 1024;
// The largest state an entry may name in the files stream.
inline constexpr std::size_t kMaxStateFile_bytes = 256u << 20;
// Longest leader id, API address, author, source or summary in an entry:
// the HTTP API bounds what it takes far below this.
inline constexpr std::size_t kMaxLogEntryText = 4096;
static_assert(kMaxEventSummary_bytes <= kMaxLogEntryText, "a leader's event summary must be an entry's text");

struct LogEntry {
  enum class Kind { Change, Term };
  Kind kind = Kind::Change;
  // The lease's revision when the writer took the lead: grows with every
  // new leader, so an entry names the term it was written in.
  std::uint64_t term = 0;
  std::string leaderId;   // the writer's server id
  std::string leaderApi;  // the writer's HTTP API ("http://host:port"), or empty
  nlohmann::json state;   // LiveWeather::toJson() after the change: an object
  std::optional<ChangeEvent> event;  // present for Kind::Change only
  // Instead of `state` (then null): the state's JSON in the files stream
  // under `key` (NatsLog::putFile), `bytes` long; its key is
  // stateFileKey(its bytes).
  struct StateFile {
    std::string key;
    std::uint64_t bytes = 0;
  };
  std::optional<StateFile> stateFile;
};

// The files stream's key for a state's JSON bytes: "state-" and their
// content key (forecast_files.hpp's fileKey).
std::string stateFileKey(std::string_view json);

// The entry as bytes (JSON, one object).
std::string encodeLogEntry(const LogEntry& entry);
// The same for an entry whose state (inline, no state file) is already
// dumped as `stateJson` (a JSON object).
std::string encodeLogEntry(const LogEntry& entry, std::string_view stateJson);
// Malformed (not JSON, a field missing or of the wrong type, an unknown
// kind or format), TooLarge (over kMaxLogEntry_bytes or a text over
// kMaxLogEntryText, a state file's key over it or its size over
// kMaxStateFile_bytes). The state is only checked to be an object (or a
// state file named) here; its contents are LiveWeather::restore's to check.
Result<LogEntry> decodeLogEntry(std::string_view bytes);

}  // namespace sky::server
