// SQLite persistence of the live weather (see weather_store.hpp).
#include "sky/server/weather_store.hpp"

#include <fcntl.h>
#include <sys/file.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>

#include <sqlite3.h>

namespace sky::server {

namespace {

constexpr int kSchemaVersion = 1;

// A prepared statement, finalised when it goes out of scope.
class Statement {
 public:
  Statement(sqlite3* db, const char* sql) { rc_ = sqlite3_prepare_v2(db, sql, -1, &stmt_, nullptr); }
  ~Statement() { sqlite3_finalize(stmt_); }
  Statement(const Statement&) = delete;
  Statement& operator=(const Statement&) = delete;
  bool ok() const { return rc_ == SQLITE_OK && stmt_; }
  sqlite3_stmt* get() const { return stmt_; }

 private:
  sqlite3_stmt* stmt_ = nullptr;
  int rc_ = SQLITE_ERROR;
};

std::string text(sqlite3_stmt* s, int col) {
  const auto* p = sqlite3_column_text(s, col);
  return p ? reinterpret_cast<const char*>(p) : "";
}

}  // namespace

void WeatherStore::Closer::operator()(sqlite3* db) const { sqlite3_close_v2(db); }

// An open descriptor of <file>.lock holding an exclusive flock. A separate
// file, not the database: closing any descriptor of the database file would
// drop the POSIX locks SQLite holds on it.
class WeatherStore::OwnerLock {
 public:
  explicit OwnerLock(int fd) : fd_(fd) {}
  ~OwnerLock() { ::close(fd_); }
  OwnerLock(const OwnerLock&) = delete;
  OwnerLock& operator=(const OwnerLock&) = delete;

 private:
  int fd_;
};

void WeatherStore::OwnerLockDeleter::operator()(OwnerLock* lock) const { delete lock; }

WeatherStore::WeatherStore(std::filesystem::path path, std::unique_ptr<OwnerLock, OwnerLockDeleter> owner,
                           std::unique_ptr<sqlite3, Closer> db)
    : path_(std::move(path)), owner_(std::move(owner)), db_(std::move(db)) {}
WeatherStore::WeatherStore(WeatherStore&&) noexcept = default;
WeatherStore& WeatherStore::operator=(WeatherStore&&) noexcept = default;
WeatherStore::~WeatherStore() = default;

Result<void> WeatherStore::exec(const char* sql) const {
  char* err = nullptr;
  if (sqlite3_exec(db_.get(), sql, nullptr, nullptr, &err) != SQLITE_OK) {
    const std::string detail = path_.string() + ": " + (err ? err : sqlite3_errmsg(db_.get()));
    sqlite3_free(err);
    return fail(ErrorCode::Io, detail);
  }
  return {};
}

Result<WeatherStore> WeatherStore::open(const std::filesystem::path& path, std::chrono::milliseconds lockWait) {
  const std::string lockPath = path.string() + ".lock";
  const int fd = ::open(lockPath.c_str(), O_RDWR | O_CREAT | O_CLOEXEC, 0600);
  if (fd < 0) return fail(ErrorCode::Io, lockPath + ": cannot open: " + std::strerror(errno));
  std::unique_ptr<OwnerLock, OwnerLockDeleter> owner(new OwnerLock(fd));
  if (::flock(fd, LOCK_EX | LOCK_NB) != 0) {
    const int err = errno;
    return fail(ErrorCode::Io, path.string() + ": " +
                                   (err == EWOULDBLOCK ? "another process holds " + lockPath +
                                                             " (is a second server using this database? one server "
                                                             "per file)"
                                                       : lockPath + ": cannot lock: " + std::strerror(err)));
  }
  sqlite3* raw = nullptr;
  const int rc = sqlite3_open_v2(path.c_str(), &raw, SQLITE_OPEN_READWRITE | SQLITE_OPEN_CREATE, nullptr);
  std::unique_ptr<sqlite3, Closer> db(raw);
  if (rc != SQLITE_OK)
    return fail(ErrorCode::Io, path.string() + ": cannot open: " + (raw ? sqlite3_errmsg(raw) : "out of memory"));
  // Another connection's lock (a second server on the same file) is waited
  // for this long, then reported: better a clear error at start than a
  // server that fails every commit later.
  sqlite3_busy_timeout(raw, static_cast<int>(lockWait.count()));
  WeatherStore store(path, std::move(owner), std::move(db));
  // Says what went wrong in words an operator acts on: garbage bytes are
  // "not a database" (Malformed), a lock is "locked" (Io).
  auto explain = [&store](const Error& e) {
    const int code = sqlite3_errcode(store.db_.get()) & 0xff;
    if (code == SQLITE_NOTADB || code == SQLITE_CORRUPT)
      return fail(ErrorCode::Malformed, e.detail + " (the file is corrupt or not a Skyshell weather database)");
    if (code == SQLITE_BUSY || code == SQLITE_LOCKED)
      return fail(ErrorCode::Io, e.detail + " (another process holds a lock on it: is a second server running?)");
    return tl::unexpected(e);
  };
  // WAL: a crash never leaves a half-written state; FULL: a commit survives
  // the machine losing power, not only the process dying.
  if (auto r = store.exec("PRAGMA journal_mode=WAL; PRAGMA synchronous=FULL;"); !r) return explain(r.error());
  if (auto r = store.exec("CREATE TABLE IF NOT EXISTS meta (key TEXT PRIMARY KEY, value TEXT NOT NULL);"
                          "CREATE TABLE IF NOT EXISTS events (sequence INTEGER PRIMARY KEY, clock_s REAL NOT NULL,"
                          " wall_ms INTEGER NOT NULL, author TEXT NOT NULL, source TEXT NOT NULL, summary TEXT NOT NULL);"
                          "CREATE TABLE IF NOT EXISTS files (key TEXT PRIMARY KEY, name TEXT NOT NULL, bytes BLOB NOT NULL);");
      !r)
    return explain(r.error());
  // The first change must not be the first to find out the file cannot be
  // written: take the write lock once now.
  if (auto r = store.exec("BEGIN IMMEDIATE;"); !r) return explain(r.error());
  if (auto r = store.exec("COMMIT;"); !r) return explain(r.error());
  Statement version(store.db_.get(), "SELECT value FROM meta WHERE key = 'schema'");
  if (!version.ok()) return explain(Error{ErrorCode::Io, path.string() + ": " + sqlite3_errmsg(store.db_.get())});
  if (sqlite3_step(version.get()) == SQLITE_ROW) {
    if (text(version.get(), 0) != std::to_string(kSchemaVersion))
      return fail(ErrorCode::Unsupported, path.string() + ": schema version " + text(version.get(), 0) +
                                              ", this server knows " + std::to_string(kSchemaVersion));
  } else if (auto r = store.exec("INSERT INTO meta (key, value) VALUES ('schema', '1');"); !r) {
    return explain(r.error());
  }
  return store;
}

Result<std::optional<WeatherStore::Saved>> WeatherStore::load() const {
  Statement st(db_.get(), "SELECT value FROM meta WHERE key = 'state'");
  if (!st.ok()) return fail(ErrorCode::Io, path_.string() + ": " + sqlite3_errmsg(db_.get()));
  if (sqlite3_step(st.get()) != SQLITE_ROW) return std::optional<Saved>{};
  Saved saved;
  saved.state = nlohmann::json::parse(text(st.get(), 0), nullptr, false);
  if (saved.state.is_discarded() || !saved.state.is_object())
    return fail(ErrorCode::Malformed, path_.string() + ": the saved state is not a JSON object");
  // The newest kMaxStoredEvents only: a file from before the bound (or
  // written by hand) must not make a restore load unbounded history.
  Statement ev(db_.get(), "SELECT sequence, clock_s, wall_ms, author, source, summary FROM "
                          "(SELECT * FROM events ORDER BY sequence DESC LIMIT ?1) ORDER BY sequence");
  if (ev.ok()) sqlite3_bind_int64(ev.get(), 1, static_cast<sqlite3_int64>(kMaxStoredEvents));
  if (!ev.ok()) return fail(ErrorCode::Io, path_.string() + ": " + sqlite3_errmsg(db_.get()));
  while (sqlite3_step(ev.get()) == SQLITE_ROW)
    saved.events.push_back({static_cast<std::uint64_t>(sqlite3_column_int64(ev.get(), 0)),
                            sqlite3_column_double(ev.get(), 1), sqlite3_column_int64(ev.get(), 2),
                            text(ev.get(), 3), text(ev.get(), 4), text(ev.get(), 5)});
  return std::optional<Saved>(std::move(saved));
}

Result<void> WeatherStore::save(const nlohmann::json& state, const ChangeEvent* event) {
  return event ? save(state, std::span<const ChangeEvent>(event, 1)) : save(state, std::span<const ChangeEvent>());
}

Result<void> WeatherStore::save(const nlohmann::json& state, std::span<const ChangeEvent> events) {
  if (auto r = exec("BEGIN IMMEDIATE;"); !r) return r;
  auto rollback = [this](const std::string& what) {
    const std::string detail = path_.string() + ": " + what + ": " + sqlite3_errmsg(db_.get());
    (void)exec("ROLLBACK;");
    return fail(ErrorCode::Io, detail);
  };
  {
    Statement st(db_.get(), "INSERT INTO meta (key, value) VALUES ('state', ?1) "
                            "ON CONFLICT(key) DO UPDATE SET value = excluded.value");
    const std::string json = state.dump();
    if (!st.ok() || sqlite3_bind_text(st.get(), 1, json.c_str(), int(json.size()), SQLITE_TRANSIENT) != SQLITE_OK ||
        sqlite3_step(st.get()) != SQLITE_DONE)
      return rollback("saving the state");
  }
  if (!events.empty()) {
    Statement st(db_.get(), "INSERT INTO events (sequence, clock_s, wall_ms, author, source, summary) "
                            "VALUES (?1, ?2, ?3, ?4, ?5, ?6)");
    if (!st.ok()) return rollback("saving the events");
    for (const ChangeEvent& event : events) {
      sqlite3_reset(st.get());
      if (sqlite3_bind_int64(st.get(), 1, static_cast<sqlite3_int64>(event.sequence)) != SQLITE_OK ||
          sqlite3_bind_double(st.get(), 2, event.clock_s) != SQLITE_OK ||
          sqlite3_bind_int64(st.get(), 3, event.wallTime_ms) != SQLITE_OK ||
          sqlite3_bind_text(st.get(), 4, event.author.c_str(), -1, SQLITE_TRANSIENT) != SQLITE_OK ||
          sqlite3_bind_text(st.get(), 5, event.source.c_str(), -1, SQLITE_TRANSIENT) != SQLITE_OK ||
          sqlite3_bind_text(st.get(), 6, event.summary.c_str(), -1, SQLITE_TRANSIENT) != SQLITE_OK ||
          sqlite3_step(st.get()) != SQLITE_DONE)
        return rollback("saving event " + std::to_string(event.sequence));
    }
    // Retention: sequences grow by one per event, so everything at or below
    // newest - kMaxStoredEvents is older than the newest kMaxStoredEvents.
    // One range delete on the primary key, no scan of what is kept.
    Statement prune(db_.get(), "DELETE FROM events WHERE sequence <= ?1");
    const auto newest = static_cast<sqlite3_int64>(events.back().sequence);
    if (!prune.ok() ||
        sqlite3_bind_int64(prune.get(), 1, newest - static_cast<sqlite3_int64>(kMaxStoredEvents)) != SQLITE_OK ||
        sqlite3_step(prune.get()) != SQLITE_DONE)
      return rollback("pruning the event log");
  }
  if (auto r = exec("COMMIT;"); !r) {
    (void)exec("ROLLBACK;");
    return r;
  }
  return {};
}

Result<std::size_t> WeatherStore::storedEvents() const {
  Statement st(db_.get(), "SELECT COUNT(*) FROM events");
  if (!st.ok() || sqlite3_step(st.get()) != SQLITE_ROW)
    return fail(ErrorCode::Io, path_.string() + ": " + sqlite3_errmsg(db_.get()));
  return static_cast<std::size_t>(sqlite3_column_int64(st.get(), 0));
}

Result<void> WeatherStore::putFile(const std::string& key, const std::string& name, std::span<const std::byte> bytes) {
  Statement st(db_.get(), "INSERT INTO files (key, name, bytes) VALUES (?1, ?2, ?3) "
                          "ON CONFLICT(key) DO UPDATE SET name = excluded.name");
  if (!st.ok() || sqlite3_bind_text(st.get(), 1, key.c_str(), -1, SQLITE_TRANSIENT) != SQLITE_OK ||
      sqlite3_bind_text(st.get(), 2, name.c_str(), -1, SQLITE_TRANSIENT) != SQLITE_OK ||
      sqlite3_bind_blob64(st.get(), 3, bytes.data(), bytes.size(), SQLITE_STATIC) != SQLITE_OK ||
      sqlite3_step(st.get()) != SQLITE_DONE)
    return fail(ErrorCode::Io, path_.string() + ": saving file " + name + ": " + sqlite3_errmsg(db_.get()));
  return {};
}

Result<std::vector<std::byte>> WeatherStore::getFile(const std::string& key) const {
  Statement st(db_.get(), "SELECT bytes FROM files WHERE key = ?1");
  if (!st.ok() || sqlite3_bind_text(st.get(), 1, key.c_str(), -1, SQLITE_TRANSIENT) != SQLITE_OK)
    return fail(ErrorCode::Io, path_.string() + ": " + sqlite3_errmsg(db_.get()));
  if (sqlite3_step(st.get()) != SQLITE_ROW) return fail(ErrorCode::Malformed, path_.string() + ": no file " + key);
  const auto* p = static_cast<const std::byte*>(sqlite3_column_blob(st.get(), 0));
  const auto n = static_cast<std::size_t>(sqlite3_column_bytes(st.get(), 0));
  return std::vector<std::byte>(p, p + n);
}

Result<void> WeatherStore::keepFiles(const std::set<std::string>& keys) {
  std::vector<std::string> gone;
  {
    Statement st(db_.get(), "SELECT key FROM files");
    if (!st.ok()) return fail(ErrorCode::Io, path_.string() + ": " + sqlite3_errmsg(db_.get()));
    while (sqlite3_step(st.get()) == SQLITE_ROW)
      if (!keys.count(text(st.get(), 0))) gone.push_back(text(st.get(), 0));
  }
  for (const std::string& key : gone) {
    Statement del(db_.get(), "DELETE FROM files WHERE key = ?1");
    if (!del.ok() || sqlite3_bind_text(del.get(), 1, key.c_str(), -1, SQLITE_TRANSIENT) != SQLITE_OK ||
        sqlite3_step(del.get()) != SQLITE_DONE)
      return fail(ErrorCode::Io, path_.string() + ": removing file " + key + ": " + sqlite3_errmsg(db_.get()));
  }
  return {};
}

}  // namespace sky::server
