// Durable weather: a SQLite file in WAL mode holding the server's whole live
// state (layers, ramps in progress, the clock anchor, the sequence) and the
// event log. Every accepted change is one transaction (synchronous = FULL),
// committed before the change is acknowledged; a restart restores exactly the
// state committed last. SQLite handles are owned by RAII types.
#pragma once

#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "sky/core/result.hpp"
#include "sky/server/change.hpp"

struct sqlite3;

namespace sky::server {

class WeatherStore {
 public:
  // Opens or creates the file. Io (cannot open, not a database, locked),
  // Unsupported (a schema version we do not know), naming the file.
  static Result<WeatherStore> open(const std::filesystem::path& path);
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

  const std::filesystem::path& path() const { return path_; }

 private:
  struct Closer {
    void operator()(sqlite3* db) const;
  };
  WeatherStore(std::filesystem::path path, std::unique_ptr<sqlite3, Closer> db);
  Result<void> exec(const char* sql) const;

  std::filesystem::path path_;
  std::unique_ptr<sqlite3, Closer> db_;
};

}  // namespace sky::server
