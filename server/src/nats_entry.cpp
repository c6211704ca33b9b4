// The change log's entries as bytes (see nats_entry.hpp).
#include "sky/server/nats_entry.hpp"

#include <cmath>
#include <span>
#include <utility>

#include "sky/server/forecast_files.hpp"

namespace sky::server {

namespace {

// Bumped when an entry's fields change meaning; a reader refuses others.
constexpr int kLogEntryFormat = 1;

Result<std::string> text(const nlohmann::json& j, const char* key) {
  const auto it = j.find(key);
  if (it == j.end() || !it->is_string()) return fail(ErrorCode::Malformed, std::string("log entry: ") + key + ": not a string");
  const auto& s = it->get_ref<const std::string&>();
  if (s.size() > kMaxLogEntryText)
    return fail(ErrorCode::TooLarge, std::string("log entry: ") + key + ": " + std::to_string(s.size()) + " bytes");
  return s;
}

Result<std::uint64_t> count(const nlohmann::json& j, const char* key) {
  const auto it = j.find(key);
  if (it == j.end() || !it->is_number_unsigned())
    return fail(ErrorCode::Malformed, std::string("log entry: ") + key + ": not an unsigned integer");
  return it->get<std::uint64_t>();
}

}  // namespace

std::string stateFileKey(std::string_view json) {
  return "state-" + fileKey(std::as_bytes(std::span(json.data(), json.size())));
}

namespace {

// The entry without its state: every field but "state".
nlohmann::json entryFields(const LogEntry& entry) {
  nlohmann::json j{{"format", kLogEntryFormat},
                   {"kind", entry.kind == LogEntry::Kind::Change ? "change" : "term"},
                   {"term", entry.term},
                   {"leader", entry.leaderId},
                   {"leader_api", entry.leaderApi}};
  if (entry.stateFile) j["state_file"] = {{"key", entry.stateFile->key}, {"bytes", entry.stateFile->bytes}};
  if (entry.event) {
    const ChangeEvent& e = *entry.event;
    j["event"] = {{"sequence", e.sequence}, {"clock_s", e.clock_s}, {"wall_ms", e.wallTime_ms},
                  {"author", e.author},     {"source", e.source},   {"summary", e.summary}};
  }
  return j;
}

}  // namespace

std::string encodeLogEntry(const LogEntry& entry) {
  return entry.stateFile ? entryFields(entry).dump() : encodeLogEntry(entry, entry.state.dump());
}

std::string encodeLogEntry(const LogEntry& entry, std::string_view stateJson) {
  // The fields' object with the state spliced in as its last member: a
  // state of thousands of regions is dumped once, not once to measure it
  // and again for the entry.
  std::string bytes = entryFields(entry).dump();
  bytes.pop_back();  // the closing brace
  bytes += ",\"state\":";
  bytes += stateJson;
  bytes += '}';
  return bytes;
}

Result<LogEntry> decodeLogEntry(std::string_view bytes) {
  if (bytes.size() > kMaxLogEntry_bytes)
    return fail(ErrorCode::TooLarge, "log entry: " + std::to_string(bytes.size()) + " bytes, at most " +
                                         std::to_string(kMaxLogEntry_bytes));
  nlohmann::json j = nlohmann::json::parse(bytes, nullptr, false);
  if (j.is_discarded() || !j.is_object()) return fail(ErrorCode::Malformed, "log entry: not a JSON object");
  const auto format = j.find("format");
  if (format == j.end() || !format->is_number_integer() || format->get<std::int64_t>() != kLogEntryFormat)
    return fail(ErrorCode::Unsupported, "log entry: format: not " + std::to_string(kLogEntryFormat));
  LogEntry e;
  auto kind = text(j, "kind");
  if (!kind) return tl::unexpected(kind.error());
  if (*kind == "change") e.kind = LogEntry::Kind::Change;
  else if (*kind == "term") e.kind = LogEntry::Kind::Term;
  else return fail(ErrorCode::Malformed, "log entry: kind: neither change nor term");
  auto term = count(j, "term");
  if (!term) return tl::unexpected(term.error());
  if (*term == 0) return fail(ErrorCode::Malformed, "log entry: term: 0");
  e.term = *term;
  auto leader = text(j, "leader");
  if (!leader) return tl::unexpected(leader.error());
  e.leaderId = std::move(*leader);
  auto api = text(j, "leader_api");
  if (!api) return tl::unexpected(api.error());
  e.leaderApi = std::move(*api);
  const auto state = j.find("state");
  const auto file = j.find("state_file");
  if (file != j.end() && state == j.end()) {
    if (!file->is_object()) return fail(ErrorCode::Malformed, "log entry: state_file: not an object");
    auto key = text(*file, "key");
    if (!key) return tl::unexpected(key.error());
    if (key->rfind("state-", 0) != 0 || key->find_first_of(". *>\t\r\n") != std::string::npos)
      return fail(ErrorCode::Malformed, "log entry: state_file.key: not a state file's key");
    auto bytes = count(*file, "bytes");
    if (!bytes) return tl::unexpected(bytes.error());
    if (*bytes > kMaxStateFile_bytes)
      return fail(ErrorCode::TooLarge, "log entry: state_file.bytes: " + std::to_string(*bytes) + ", at most " +
                                           std::to_string(kMaxStateFile_bytes));
    e.stateFile = LogEntry::StateFile{std::move(*key), *bytes};
  } else {
    if (state == j.end() || !state->is_object()) return fail(ErrorCode::Malformed, "log entry: state: not an object");
    if (file != j.end()) return fail(ErrorCode::Malformed, "log entry: both a state and a state_file");
    e.state = std::move(*state);
  }
  const auto event = j.find("event");
  if (e.kind == LogEntry::Kind::Term) {
    if (event != j.end()) return fail(ErrorCode::Malformed, "log entry: a term entry with an event");
    return e;
  }
  if (event == j.end() || !event->is_object()) return fail(ErrorCode::Malformed, "log entry: event: not an object");
  ChangeEvent ce;
  auto sequence = count(*event, "sequence");
  if (!sequence) return tl::unexpected(sequence.error());
  ce.sequence = *sequence;
  const auto clock = event->find("clock_s");
  if (clock == event->end() || !clock->is_number() || !std::isfinite(clock->get<double>()))
    return fail(ErrorCode::Malformed, "log entry: event.clock_s: not a finite number");
  ce.clock_s = clock->get<double>();
  const auto wall = event->find("wall_ms");
  if (wall == event->end() || !wall->is_number_integer())
    return fail(ErrorCode::Malformed, "log entry: event.wall_ms: not an integer");
  ce.wallTime_ms = wall->get<std::int64_t>();
  for (auto [key, out] : {std::pair{"author", &ce.author}, {"source", &ce.source}, {"summary", &ce.summary}}) {
    auto t = text(*event, key);
    if (!t) return tl::unexpected(t.error());
    *out = std::move(*t);
  }
  e.event = std::move(ce);
  return e;
}

}  // namespace sky::server
