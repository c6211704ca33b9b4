// The weather by S2 cell on NATS (see nats_cells.hpp).
#include "sky/server/nats_cells.hpp"

#include <algorithm>
#include <utility>

#include <spdlog/spdlog.h>

#include "sky/server/metrics_text.hpp"

namespace sky::server {

namespace {

// A global part lists at most every level-6 cell.
constexpr std::size_t kMaxListedCells = 6u << (2 * kStateCellLevel);

// A cell holds at most every region there may be (ids are 16 bits), and
// a ramp of each.
constexpr std::size_t kMaxCellItems = 65535;

Result<std::uint64_t> positive(const nlohmann::json& j, const char* key, const char* what) {
  const auto it = j.find(key);
  if (it == j.end() || !it->is_number_unsigned() || it->get<std::uint64_t>() == 0)
    return fail(ErrorCode::Malformed, std::string(what) + ": " + key + ": not a positive integer");
  return it->get<std::uint64_t>();
}

}  // namespace

std::string encodeGlobalPart(const GlobalPart& part) {
  if (part.log || !part.entry) return R"({"sequence":)" + std::to_string(part.sequence) + R"(,"log":true})";
  nlohmann::json cells = nlohmann::json::object();
  for (const auto& [key, sequence] : part.cells) cells[key] = sequence;
  return nlohmann::json{{"sequence", part.sequence}, {"cells", std::move(cells)}, {"entry", encodeLogEntry(*part.entry)}}
      .dump();
}

Result<GlobalPart> decodeGlobalPart(std::string_view bytes) {
  if (bytes.size() > kMaxLogEntry_bytes * 2)
    return fail(ErrorCode::TooLarge, "global part: " + std::to_string(bytes.size()) + " bytes");
  const nlohmann::json j = nlohmann::json::parse(bytes, nullptr, false);
  if (!j.is_object()) return fail(ErrorCode::Malformed, "global part: not a JSON object");
  GlobalPart g;
  auto sequence = positive(j, "sequence", "global part");
  if (!sequence) return tl::unexpected(sequence.error());
  g.sequence = *sequence;
  if (const auto log = j.find("log"); log != j.end()) {
    if (!log->is_boolean() || !log->get<bool>() || j.contains("entry") || j.contains("cells"))
      return fail(ErrorCode::Malformed, "global part: log: not true alone");
    g.log = true;
    return g;
  }
  const auto cells = j.find("cells");
  const auto entry = j.find("entry");
  if (cells == j.end() || !cells->is_object()) return fail(ErrorCode::Malformed, "global part: cells: not an object");
  if (cells->size() > kMaxListedCells)
    return fail(ErrorCode::TooLarge, "global part: cells: " + std::to_string(cells->size()) + " listed");
  for (const auto& [key, s] : cells->items()) {
    if (!s.is_number_unsigned() || s.get<std::uint64_t>() == 0 || s.get<std::uint64_t>() > g.sequence)
      return fail(ErrorCode::Malformed, "global part: cells." + key + ": not a sequence up to the part's");
    g.cells.emplace(key, s.get<std::uint64_t>());
  }
  if (entry == j.end() || !entry->is_string()) return fail(ErrorCode::Malformed, "global part: entry: not a string");
  auto decoded = decodeLogEntry(entry->get_ref<const std::string&>());
  if (!decoded) return fail(decoded.error().code, "global part: " + decoded.error().detail);
  if (decoded->stateFile) return fail(ErrorCode::Malformed, "global part: entry: names a state file");
  g.entry = std::move(*decoded);
  return g;
}

std::string encodeCellPart(std::uint64_t sequence, std::string_view contentJson) {
  return R"({"sequence":)" + std::to_string(sequence) + R"(,"cell":)" + std::string(contentJson) + "}";
}

Result<CellPart> decodeCellPart(std::string_view bytes) {
  if (bytes.size() > kMaxLogEntry_bytes * 2)
    return fail(ErrorCode::TooLarge, "cell: " + std::to_string(bytes.size()) + " bytes");
  nlohmann::json j = nlohmann::json::parse(bytes, nullptr, false);
  if (!j.is_object()) return fail(ErrorCode::Malformed, "cell: not a JSON object");
  CellPart c;
  auto sequence = positive(j, "sequence", "cell");
  if (!sequence) return tl::unexpected(sequence.error());
  c.sequence = *sequence;
  const auto cell = j.find("cell");
  if (cell == j.end()) return fail(ErrorCode::Malformed, "cell: cell: missing");
  if (cell->is_null()) return c;
  if (!cell->is_object() || cell->size() != 2) return fail(ErrorCode::Malformed, "cell: cell: not null or an object of two arrays");
  for (const char* key : {"regions", "region_ramps"}) {
    const auto items = cell->find(key);
    if (items == cell->end() || !items->is_array())
      return fail(ErrorCode::Malformed, std::string("cell: cell.") + key + ": not an array");
    if (items->size() > kMaxCellItems)
      return fail(ErrorCode::TooLarge, std::string("cell: cell.") + key + ": " + std::to_string(items->size()));
  }
  c.content = std::move(*cell);
  return c;
}

// ---------------------------------------------------------------- publisher

CellPublisher::CellPublisher(NatsLog& nats, std::shared_ptr<spdlog::logger> log)
    : nats_(nats), log_(std::move(log)), thread_([this] { run(); }) {}

CellPublisher::~CellPublisher() { stop(); }

void CellPublisher::offer(std::uint64_t sequence, LogEntry entry) {
  {
    std::lock_guard lock(mutex_);
    pending_.emplace(sequence, std::move(entry));
  }
  wake_.notify_one();
}

void CellPublisher::forget() {
  {
    std::lock_guard lock(mutex_);
    pending_.reset();
    forget_ = true;
  }
  wake_.notify_one();
}

void CellPublisher::stop() {
  {
    std::lock_guard lock(mutex_);
    if (stopping_ && !thread_.joinable()) return;
    stopping_ = true;
  }
  wake_.notify_one();
  if (thread_.joinable()) thread_.join();
}

void CellPublisher::run() {
  for (;;) {
    std::optional<std::pair<std::uint64_t, LogEntry>> next;
    {
      std::unique_lock lock(mutex_);
      wake_.wait(lock, [this] { return stopping_ || pending_ || forget_; });
      if (stopping_) return;
      if (std::exchange(forget_, false)) {
        cells_.clear();
        globalRevision_ = 0;
      }
      next = std::exchange(pending_, std::nullopt);
    }
    if (next) publish(next->first, std::move(next->second));
  }
}

bool CellPublisher::put(const std::string& key, const std::string& bytes) {
  std::uint64_t& revision = key == kGlobalAreaKey ? globalRevision_ : cells_[key].revision;
  auto put = nats_.putArea(key, bytes, revision);
  if (!put) {
    log_->warn("event=nats_cells_put_failed key={} detail={:?}", key, describe(put.error()));
    return false;
  }
  if (!*put) {
    ++refused_;
    log_->warn("event=nats_cells_refused key={}: another leader wrote it; every key is written anew with the next "
               "state", key);
    return false;
  }
  revision = **put;
  ++puts_;
  bytes_ += bytes.size();
  return true;
}

void CellPublisher::publish(std::uint64_t sequence, LogEntry entry) {
  StateCells split = splitState(std::move(entry.state), reach_);
  const std::size_t limit = nats_.messageLimit();
  bool ok = true, tooLarge = false;
  for (auto& [key, content] : split.cells) {
    Published& p = cells_[key];
    // Compared as trees, not dumped: most cells are unchanged, and a
    // comparison allocates nothing.
    if (p.revision != 0 && !p.empty && p.content == content) continue;
    const std::string bytes = encodeCellPart(sequence, content.dump());
    if (bytes.size() > limit) {
      tooLarge = true;
      continue;
    }
    if (!put(key, bytes)) {
      ok = false;
      break;
    }
    p.content = std::move(content);
    p.sequence = sequence;
    p.empty = false;
  }
  // Cells emptied since: null, so that a relay holding one drops it.
  for (auto& [key, p] : cells_) {
    if (!ok) break;
    if (p.empty || p.revision == 0 || split.cells.count(key)) continue;
    if (!put(key, encodeCellPart(sequence, "null"))) {
      ok = false;
      break;
    }
    p.empty = true;
    p.content = nullptr;
    p.sequence = sequence;
  }
  if (!ok) {
    cells_.clear();
    globalRevision_ = 0;
    return;
  }
  GlobalPart part;
  part.sequence = sequence;
  for (const auto& [key, p] : cells_)
    if (!p.empty && p.revision != 0 && split.cells.count(key)) part.cells.emplace(key, p.sequence);
  std::string global;
  if (!tooLarge) {
    entry.state = std::move(split.global);
    entry.stateFile.reset();
    part.entry = std::move(entry);
    global = encodeGlobalPart(part);
    if (global.size() > limit) tooLarge = true;
  }
  if (tooLarge) {
    ++toLog_;
    part.log = true;
    global = encodeGlobalPart(part);
  }
  if (!put(kGlobalAreaKey, global)) {
    cells_.clear();
    globalRevision_ = 0;
    return;
  }
  ++states_;
}

std::string CellPublisher::metrics() const {
  std::string m;
  appendMetric(m, "skyshell_nats_cells_states_total", "counter",
             "states this leader published by S2 cell for the relays", states_.load());
  appendMetric(m, "skyshell_nats_cells_puts_total", "counter", "cell and global values put", puts_.load());
  appendMetric(m, "skyshell_nats_cells_put_bytes_total", "counter", "bytes of those values", bytes_.load());
  appendMetric(m, "skyshell_nats_cells_to_log_total", "counter",
             "states with a part too large for a message (relays read them whole from the log)", toLog_.load());
  appendMetric(m, "skyshell_nats_cells_refused_total", "counter",
             "cell writes refused because another leader wrote the key since", refused_.load());
  return m;
}

// ----------------------------------------------------------------- follower

CellFollower::CellFollower(NatsLog& nats, std::shared_ptr<spdlog::logger> log, Deliver deliver, std::uint64_t applied)
    : nats_(nats), log_(std::move(log)), deliver_(std::move(deliver)), delivered_(applied) {
  nats_.onArea([this](const std::string& key, std::string bytes) { onMessage(key, std::move(bytes)); });
  thread_ = std::thread([this] { run(); });
}

CellFollower::~CellFollower() { stop(); }

void CellFollower::stop() {
  {
    std::lock_guard lock(mutex_);
    stopping_ = true;
  }
  wake_.notify_one();
  if (thread_.joinable()) thread_.join();
  nats_.onArea(nullptr);
}

void CellFollower::want(std::vector<std::string> keys, bool whole) {
  {
    std::lock_guard lock(mutex_);
    wanted_ = std::move(keys);
    whole_ = whole;
  }
  wake_.notify_one();
}

void CellFollower::onMessage(const std::string& key, std::string bytes) {
  bytes_ += bytes.size();
  {
    std::lock_guard lock(mutex_);
    arrived_[key] = std::move(bytes);
  }
  wake_.notify_one();
}

void CellFollower::take(const std::string& key, const std::string& bytes) {
  if (bytes.empty()) return;  // a delete or purge marker: nothing this leader writes
  if (key == kGlobalAreaKey) {
    auto g = decodeGlobalPart(bytes);
    if (!g) {
      ++malformed_;
      log_->warn("event=nats_cells_dropped key=global detail={:?}", describe(g.error()));
      return;
    }
    if (!global_ || g->sequence > global_->sequence) global_ = std::move(*g);
    return;
  }
  if (!watched_.count(key)) return;
  auto c = decodeCellPart(bytes);
  if (!c) {
    ++malformed_;
    log_->warn("event=nats_cells_dropped key={} detail={:?}", key, describe(c.error()));
    return;
  }
  Cell& held = cells_[key];
  if (held.sequence > c->sequence) return;
  held = std::move(*c);
}

void CellFollower::readBack(const std::string& key) {
  auto read = nats_.readArea(key);
  if (!read) {
    log_->debug("event=nats_cells_read_failed key={} detail={:?}", key, describe(read.error()));
    return;
  }
  if (!*read) return;
  bytes_ += (*read)->size();
  take(key, **read);
}

void CellFollower::watchWanted(const std::vector<std::string>& keys) {
  const std::set<std::string> want(keys.begin(), keys.end());
  for (auto it = watched_.begin(); it != watched_.end();) {
    if (want.count(*it)) {
      ++it;
      continue;
    }
    nats_.unwatchArea(*it);
    cells_.erase(*it);
    it = watched_.erase(it);
  }
  for (const auto& key : want) {
    if (watched_.count(key)) continue;
    if (auto r = nats_.watchArea(key); !r) {
      log_->warn("event=nats_cells_watch_failed key={} detail={:?}", key, describe(r.error()));
      continue;
    }
    watched_.insert(key);
    readBack(key);
  }
  watching_ = watched_.size();
  dirty_ = true;
}

void CellFollower::deliverWhole(std::uint64_t atLeast) {
  auto range = nats_.range();
  if (!range || range->last < atLeast) return;  // the log has not got there: try at the next turn
  auto bytes = nats_.read(range->last);
  if (!bytes || !*bytes) return;
  auto entry = decodeLogEntry(**bytes);
  if (!entry) {
    ++malformed_;
    return;
  }
  ++wholes_;
  bytes_ += (*bytes)->size();
  if (range->last <= delivered_) entry->event.reset();  // folded before: only the state again
  delivered_ = std::max(delivered_, range->last);
  deliver_(range->last, std::move(*entry));
  dirty_ = false;
  mismatchSince_.reset();
}

void CellFollower::run() {
  if (auto r = nats_.watchArea(kGlobalAreaKey); !r)
    log_->warn("event=nats_cells_watch_failed key=global detail={:?}", describe(r.error()));
  readBack(kGlobalAreaKey);
  auto lastReadBack = std::chrono::steady_clock::now();
  for (;;) {
    std::map<std::string, std::string> arrived;
    std::optional<std::vector<std::string>> wanted;
    {
      std::unique_lock lock(mutex_);
      wake_.wait_for(lock, std::chrono::milliseconds{250},
                     [this] { return stopping_ || !arrived_.empty() || wanted_; });
      if (stopping_) break;
      arrived.swap(arrived_);
      wanted = std::exchange(wanted_, std::nullopt);
      if (wanted) wholeNow_ = whole_;
    }
    if (wanted) watchWanted(wholeNow_ ? std::vector<std::string>{} : *wanted);
    for (const auto& [key, bytes] : arrived) take(key, bytes);
    const auto now = std::chrono::steady_clock::now();
    if (now - lastReadBack >= kReadBack) {
      lastReadBack = now;
      const auto range = nats_.range();
      if (range) logLast_.emplace_back(now, range->last);
      // Read back only when the log is ahead of the part held (a put this
      // watch missed) or none is held: the part lists every non-empty cell,
      // tens of kB for a continent of stations.
      if (!global_ || !range || range->last > global_->sequence) readBack(kGlobalAreaKey);
      // A leader puts a global part only after the log stored its state:
      // one past the log's last sequence (read again, after the part) was
      // put by another client, and held it would hide every real one.
      if (range && global_ && global_->sequence > range->last)
        if (const auto after = nats_.range(); after && global_->sequence > after->last) {
          ++malformed_;
          log_->warn("event=nats_cells_dropped key=global sequence={} log={}: past the log", global_->sequence,
                     after->last);
          global_.reset();
        }
      // The newest sequence the log had at least kCellMismatchWait ago.
      std::uint64_t due = 0;
      while (!logLast_.empty() && now - logLast_.front().first >= kCellMismatchWait) {
        due = logLast_.front().second;
        logLast_.pop_front();
      }
      const std::uint64_t published = global_ ? global_->sequence : 0;
      if (due > published && due > delivered_) {
        log_->info("event=nats_cells_unpublished log={} global={}: reading the whole state from the log", due,
                   published);
        deliverWhole(due);
        continue;
      }
    }
    if (!global_) continue;
    const Global& g = *global_;
    const bool fresh = g.sequence > delivered_;
    if (!fresh && !dirty_) continue;
    if (g.log || wholeNow_) {
      deliverWhole(g.sequence);
      continue;
    }
    // Every watched cell as the global part lists it: at the listed
    // sequence, or (not listed) empty.
    std::vector<std::string> behind;
    std::vector<const nlohmann::json*> parts;
    for (const auto& key : watched_) {
      const auto listed = g.cells.find(key);
      const auto held = cells_.find(key);
      if (listed == g.cells.end()) continue;
      if (held == cells_.end() || held->second.sequence != listed->second) behind.push_back(key);
      else if (!held->second.content.is_null()) parts.push_back(&held->second.content);
    }
    if (!behind.empty()) {
      if (!mismatchSince_) mismatchSince_ = now;
      if (now - *mismatchSince_ >= kCellMismatchWait) {
        log_->info("event=nats_cells_behind cells={} sequence={}: reading the whole state from the log", behind.size(),
                   g.sequence);
        deliverWhole(g.sequence);
      } else {
        for (const auto& key : behind) readBack(key);
      }
      continue;
    }
    mismatchSince_.reset();
    LogEntry entry = *g.entry;
    entry.state = joinState(entry.state, parts);
    if (!fresh) entry.event.reset();
    ++joined_;
    delivered_ = std::max(delivered_, g.sequence);
    dirty_ = false;
    deliver_(g.sequence, std::move(entry));
  }
  nats_.unwatchArea(kGlobalAreaKey);
  for (const auto& key : watched_) nats_.unwatchArea(key);
}

std::string CellFollower::metrics() const {
  std::string m;
  appendMetric(m, "skyshell_nats_cells_watched", "gauge", "S2 cells whose weather this relay watches",
             watching_.load());
  appendMetric(m, "skyshell_nats_cells_received_bytes_total", "counter",
             "bytes of cell and global values and whole log entries this relay received", bytes_.load());
  appendMetric(m, "skyshell_nats_cells_joined_total", "counter", "states joined from cells", joined_.load());
  appendMetric(m, "skyshell_nats_cells_whole_total", "counter",
             "states read whole from the log (areas too large, a part too large, or cells behind)", wholes_.load());
  appendMetric(m, "skyshell_nats_cells_malformed_total", "counter", "cell or global values dropped as malformed",
             malformed_.load());
  return m;
}

}  // namespace sky::server
