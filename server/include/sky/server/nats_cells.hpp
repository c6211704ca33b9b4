// The weather by S2 cell on NATS, for the relays: the leader publishes each
// state it appended to the log cut by cell (state_cells.hpp) into the areas
// bucket (NatsLog::putArea), and a relay takes only the cells its renderers'
// areas cover plus the global part, instead of every whole state. A change
// to one METAR station then costs a relay far away the global part (a few
// kB), not the continent's state (megabytes).
//
// Keys: "global" holds {"sequence": N, "cells": {key: S, ...}, "entry":
// "<a log entry (nats_entry.hpp) whose state is the global part>"}, where S is
// the sequence at which that cell's content last changed; or {"sequence":
// N, "log": true} when a part was too large for a message, and a relay reads
// the whole state from the log. "c.<S2 token>" holds {"sequence": S, "cell":
// {"regions": [...], "region_ramps": [...]}} (null once emptied). Cells are
// written before the global part that lists them, so a relay that holds a
// global part finds its cells at the listed sequences, or newer ones whose
// global part follows.
//
// Fencing: each key is written at the revision this leader wrote last (the
// first write of a term at any revision), so the writes of a leader paused
// while another took over are refused; it then forgets what it published and
// writes every key anew with its next state (a leader that was superseded
// steps down before it has one).
#pragma once

#include <atomic>
#include <chrono>
#include <condition_variable>
#include <deque>
#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <set>
#include <string>
#include <string_view>
#include <thread>
#include <vector>

#include <nlohmann/json.hpp>

#include "sky/core/result.hpp"
#include "sky/server/nats_entry.hpp"
#include "sky/server/nats_log.hpp"
#include "sky/server/state_cells.hpp"

namespace spdlog {
class logger;
}

namespace sky::server {

inline constexpr const char* kGlobalAreaKey = "global";

// The values as bytes. A global part: its sequence, and either `log` (read
// the log's entry) or the sequence of each listed cell and the entry whose
// state is the global part. A cell: the sequence it last changed at and its
// content ({"regions": [...], "region_ramps": [...]}, or null once emptied).
// Decoding refuses (Malformed, TooLarge) anything else: the bucket is
// writable by any client of the cluster.
struct GlobalPart {
  std::uint64_t sequence = 0;
  bool log = false;
  std::map<std::string, std::uint64_t> cells;
  std::optional<LogEntry> entry;  // with its state inline (no state file)
};
struct CellPart {
  std::uint64_t sequence = 0;
  nlohmann::json content;
};
std::string encodeGlobalPart(const GlobalPart& part);
Result<GlobalPart> decodeGlobalPart(std::string_view bytes);
std::string encodeCellPart(std::uint64_t sequence, std::string_view contentJson);
Result<CellPart> decodeCellPart(std::string_view bytes);

// Leader side: publishes on a thread of its own, off the change's path (the
// change was acknowledged once the log stored it); offers that arrive while
// it publishes are coalesced to the newest.
class CellPublisher {
 public:
  CellPublisher(NatsLog& nats, std::shared_ptr<spdlog::logger> log);
  ~CellPublisher();
  CellPublisher(const CellPublisher&) = delete;
  CellPublisher& operator=(const CellPublisher&) = delete;

  // After the log stored `entry` (with its state inline) at `sequence`.
  void offer(std::uint64_t sequence, LogEntry entry);
  // This server stopped leading: a pending offer is dropped, and what was
  // published is forgotten (the next lead writes every key anew).
  void forget();
  void stop();

  // Prometheus lines: states published, cell values put, bytes put, states
  // sent to the log (a part too large), refused writes.
  std::string metrics() const;

 private:
  void run();
  void publish(std::uint64_t sequence, LogEntry entry);
  // Puts one key at the revision last written (or any); false when refused
  // or failed (logged).
  bool put(const std::string& key, const std::string& bytes);

  NatsLog& nats_;
  std::shared_ptr<spdlog::logger> log_;
  std::mutex mutex_;
  std::condition_variable wake_;
  std::optional<std::pair<std::uint64_t, LogEntry>> pending_;
  bool stopping_ = false, forget_ = false;
  std::thread thread_;

  // The publisher thread's.
  struct Published {
    nlohmann::json content;     // as last put
    std::uint64_t sequence = 0;  // at which it last changed
    std::uint64_t revision = 0;  // the key's revision this leader wrote
    bool empty = false;
  };
  CellReach reach_;
  std::map<std::string, Published> cells_;
  std::uint64_t globalRevision_ = 0;
  std::atomic<std::uint64_t> states_{0}, puts_{0}, bytes_{0}, toLog_{0}, refused_{0};
};

// Relay side: watches the global key and the keys of the cells it wants,
// and hands the io thread the state they join to (or the log's whole newest
// entry, when the areas need too many cells, a part went to the log, or the
// cells held do not match the global part for kCellMismatchWait).
class CellFollower {
 public:
  // On the io thread: fold this entry as the state at `sequence` (a state
  // joined from cells carries its event only the first time a sequence is
  // handed over; a state joined again for other areas has none).
  using Deliver = std::function<void(std::uint64_t sequence, LogEntry entry)>;
  CellFollower(NatsLog& nats, std::shared_ptr<spdlog::logger> log, Deliver deliver, std::uint64_t applied);
  ~CellFollower();
  CellFollower(const CellFollower&) = delete;
  CellFollower& operator=(const CellFollower&) = delete;

  // The cells the renderers' areas cover now (sorted keys), or `whole`:
  // more than a relay should watch. Any thread.
  void want(std::vector<std::string> keys, bool whole);
  void stop();
  std::string metrics() const;

  // Longer than a leader takes to write a state's cells and global part.
  static constexpr std::chrono::milliseconds kCellMismatchWait{2000};
  // How often the log's last sequence is read, and the global part read
  // back when the log is ahead of it (a watch misses what is put while the
  // connection is down):
  // a global part that has not reached the sequence the log had
  // kCellMismatchWait ago (no leader publishing: one started with
  // --nats-cells off, or whose writes fail) makes the relay read the log's
  // newest entry instead.
  static constexpr std::chrono::milliseconds kReadBack{1000};

 private:
  using Global = GlobalPart;
  using Cell = CellPart;
  void run();
  void onMessage(const std::string& key, std::string bytes);  // a NATS thread
  // The follower thread's.
  void take(const std::string& key, const std::string& bytes);
  void readBack(const std::string& key);
  void watchWanted(const std::vector<std::string>& keys);
  void deliverWhole(std::uint64_t atLeast);

  NatsLog& nats_;
  std::shared_ptr<spdlog::logger> log_;
  Deliver deliver_;
  mutable std::mutex mutex_;
  std::condition_variable wake_;
  bool stopping_ = false;
  std::map<std::string, std::string> arrived_;  // by key, the newest bytes each
  std::optional<std::vector<std::string>> wanted_;
  bool whole_ = false;
  std::thread thread_;

  // The follower thread's.
  std::optional<Global> global_;
  std::map<std::string, Cell> cells_;  // held, of the watched keys
  std::set<std::string> watched_;
  bool wholeNow_ = false, dirty_ = false;
  std::uint64_t delivered_ = 0;  // the newest sequence handed over
  std::optional<std::chrono::steady_clock::time_point> mismatchSince_;
  // The log's last sequence as read at each read-back, oldest first.
  std::deque<std::pair<std::chrono::steady_clock::time_point, std::uint64_t>> logLast_;
  std::atomic<std::uint64_t> bytes_{0}, joined_{0}, wholes_{0}, watching_{0}, malformed_{0};
};

}  // namespace sky::server
