// Durable weather: a SQLite file in WAL mode holding the server's whole live
// state (layers, ramps in progress, the clock anchor, the sequence) and the
// event log. Every accepted change is one transaction (synchronous = FULL),
// committed before the change is acknowledged; a restart restores exactly the
// state committed last. The event log keeps the newest kMaxStoredEvents
// events (older ones are pruned in the commit that passes the bound), so
// neither the file nor a restore grows without end. SQLite handles are
// owned by RAII types.
#pragma once

#include <chrono>
#include <filesystem>
#include <memory>
#include <optional>
#include <set>
#include <span>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "sky/core/result.hpp"
#include "sky/server/change.hpp"

struct sqlite3;

namespace sky::server {

// Events the store keeps (and a restore loads): the newest this many. The
// console shows the recent history; at a change a second for a whole
// exercise day that is the last few hours, and the file stays a few MB.
inline constexpr std::size_t kMaxStoredEvents = 10000;

class WeatherStore {
 public:
  // Opens or creates the file and checks that this process can write it.
  // One store per file: it holds an exclusive flock on `<file>.lock` for its
  // life (SQLite locks the file only while a commit runs, so it alone would
  // let a second server open the file and both write it; the kernel drops
  // the flock when the process dies, so a crash leaves nothing to clean up).
  // Io (cannot open; another store holds the lock file), Malformed (not a
  // database: garbage bytes, a truncated file), Busy-like Io when another
  // connection holds a lock on it for longer than lockWait; Unsupported (a
  // schema version we do not know). Every error names the file.
  static Result<WeatherStore> open(const std::filesystem::path& path,
                                   std::chrono::milliseconds lockWait = std::chrono::milliseconds{2000});
  WeatherStore(WeatherStore&&) noexcept;
  WeatherStore& operator=(WeatherStore&&) noexcept;
  ~WeatherStore();

  struct Saved {
    nlohmann::json state;
    std::vector<ChangeEvent> events;  // oldest first
  };
  // The state committed last, or nullopt for a new file.
  Result<std::optional<Saved>> load() const;
  // Commits the state and, when given, its event, atomically.
  Result<void> save(const nlohmann::json& state, const ChangeEvent* event);
  // Commits the state and its events (oldest first) atomically, pruning the
  // log to the newest kMaxStoredEvents in the same transaction.
  Result<void> save(const nlohmann::json& state, std::span<const ChangeEvent> events);
  // Files the state refers to by key (a loaded forecast's GRIB files), kept
  // beside it so that a restart decodes them again. putFile stores (or
  // keeps) a file, getFile reads it back, keepFiles removes every file not
  // named (called after the commit of a state that names only those).
  Result<void> putFile(const std::string& key, const std::string& name, std::span<const std::byte> bytes);
  Result<std::vector<std::byte>> getFile(const std::string& key) const;
  Result<void> keepFiles(const std::set<std::string>& keys);

  // Events in the file (for tests of the retention bound).
  Result<std::size_t> storedEvents() const;

  const std::filesystem::path& path() const { return path_; }

 private:
  struct Closer {
    void operator()(sqlite3* db) const;
  };
  class OwnerLock;  // the flock on <file>.lock (weather_store.cpp)
  struct OwnerLockDeleter {
    void operator()(OwnerLock* lock) const;
  };
  WeatherStore(std::filesystem::path path, std::unique_ptr<OwnerLock, OwnerLockDeleter> owner,
               std::unique_ptr<sqlite3, Closer> db);
  Result<void> exec(const char* sql) const;

  std::filesystem::path path_;
  std::unique_ptr<OwnerLock, OwnerLockDeleter> owner_;  // released after the database is closed
  std::unique_ptr<sqlite3, Closer> db_;
};

}  // namespace sky::server
