// The weather on a NATS cluster (skyshell-weatherd --nats): several servers
// share one weather. The change log is a JetStream stream (nats_log.hpp)
// whose entries are whole states (nats_entry.hpp), so the weather is the
// fold of the log: the last entry's state, with the events of the entries
// before it. One server leads: it holds the lease (a KV key that expires
// unless renewed), takes changes, runs the clock's timeline, and appends each
// accepted change before acknowledging it. The others follow the log and
// refuse changes, naming the leader. A leader's appends are fenced twice:
// it refuses changes once its lease may have lapsed, and each append expects
// the stream's last sequence to be the one it applied last, so a leader that
// was paused while another took over cannot append after it, and steps down.
// A forecast's GRIB files go to a stream of their own (NatsLog::putFile)
// before the change that loads it; a follower folding that change reads
// them back and decodes the forecast itself.
#pragma once

#include <atomic>
#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <deque>
#include <functional>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <utility>

#include <boost/asio/steady_timer.hpp>

#include "sky/core/result.hpp"
#include "sky/server/cluster_registry.hpp"
#include "sky/server/grib_isolated.hpp"
#include "sky/server/live_weather.hpp"
#include "sky/server/nats_cells.hpp"
#include "sky/server/nats_entry.hpp"
#include "sky/server/nats_log.hpp"

namespace spdlog {
class logger;
}

namespace sky::server {

class Server;

// Entries a starting server reads back for its event log; the last of them
// is its state. The console shows the recent history, a few hundred lines.
inline constexpr std::uint64_t kReplayEntries = 256;
// The most bytes of log entries a follower holds while an entry's forecast
// decodes or its state file is read.
inline constexpr std::size_t kMaxWaitingBytes = 64u << 20;

struct NatsWeatherOptions {
  NatsLogOptions log;
  std::string serverId;  // names this server in the lease and its entries
  // A relay (skyshell-relay): follows the log and serves its weather but
  // never takes part in the election, so it never leads and refuses every
  // change. A standby server is the same without this.
  bool relay = false;
  // A relay that takes the weather by S2 cell (nats_cells.hpp): the global
  // part and the cells its renderers' areas cover, not every whole state of
  // the log. Without it a relay follows the log as a standby server does.
  bool followCells = false;
  // A server that leads publishes the weather by cell for those relays
  // (CellPublisher). Off: relays by cell read whole states from the log.
  bool publishCells = true;
  std::shared_ptr<spdlog::logger> logger;  // null: log nothing
  // Decodes a forecast the leader loaded (its files read back from the
  // files stream) when this server or relay folds it.
  GribDecoder gribDecoder;
};

class NatsWeather {
 public:
  // Connects, folds the stream's newest entries into the server's weather
  // (the scenario's weather stays when the stream is empty), follows the
  // log from there and attaches itself as the weather's committer; every
  // change is refused until this server leads. Call before the server runs
  // (it blocks while it reads). Errors: those of NatsLog::connect, Malformed
  // when the stream's last entry cannot be restored.
  static Result<std::unique_ptr<NatsWeather>> start(Server& server, NatsWeatherOptions options);
  ~NatsWeather();
  NatsWeather(const NatsWeather&) = delete;
  NatsWeather& operator=(const NatsWeather&) = delete;

  // Begins taking part in the election, with this server's HTTP API address
  // ("http://host:port", or empty) for the followers' refusals. A relay
  // only starts watching the log (a stalled subscription is followed anew)
  // and who leads (named in its refusals). Either joins the cluster's
  // registry with both addresses (streamAddress: "host:port" renderers
  // connect to). Call before the server runs.
  void elect(std::string apiUrl, std::string streamAddress);
  // Leaves the election, releasing the lease when held (a follower takes
  // over at its next poll instead of after the lease's time to live), and
  // stops following. Call on the server's io thread, at shutdown.
  void close();

  bool leading() const { return leading_.load(); }
  // GET /api/cluster: every member of the registry as last read
  // (ClusterRegistry::view), this member's id as "self", "nats": true.
  // Any thread.
  nlohmann::json cluster() const;
  // Prometheus text: the role, the term, the applied sequence, entries
  // dropped as malformed, fenced appends, and the weather's state hash
  // (LiveWeather::stateHash, equal on every server and relay that folded
  // the same entry). Call on the io thread.
  std::string metrics() const;

 private:
  NatsWeather(Server& server, NatsWeatherOptions options, std::unique_ptr<NatsLog> log);
  Result<void> replay();
  // Follows the log from the entry after the last one folded; replaces the
  // subscription (the election thread's, once started).
  Result<void> follow();
  // On the io thread: a state a CellFollower joined (or read whole), folded
  // as an entry of the log is, after a decode under way.
  void onCellState(std::uint64_t sequence, LogEntry entry);
  // The io thread's, every kAreasPoll on a relay by cell: the cells its
  // subscribers' areas cover, to the CellFollower when they changed.
  void pollAreas();
  // On the io thread: one entry of the log, as the follower sees it. An
  // entry naming a forecast not held is decoded off the io thread
  // (decodeThenFold); the entries after it wait for it.
  void onEntry(std::uint64_t sequence, const std::string& bytes);
  // An entry whose state is in hand: decodes its forecast first when it
  // names one not held (decodeThenFold), else folds it.
  void foldOrDecode(std::uint64_t sequence, LogEntry entry);
  // Folds one entry (or counts it dropped) with `loader` for its forecast.
  void fold(std::uint64_t sequence, Result<LogEntry> entry, const LiveWeather::ForecastLoader& loader);
  // Reads and decodes the forecast `entry` names on decodeThread_, then
  // folds the entry and the ones that waited for it on the io thread.
  void decodeThenFold(std::uint64_t sequence, LogEntry entry);
  // Reads the state `entry` names in the files stream on decodeThread_,
  // then goes on with it as foldOrDecode on the io thread.
  void readStateThenFold(std::uint64_t sequence, LogEntry entry);
  // Runs `work` on decodeThread_ while the entries after wait; then, on the
  // io thread, what it returned, and the entries that waited, in order.
  void offIoThread(std::function<std::function<void()>()> work);
  // The entry's bytes for the log; a state too large for an entry is put
  // in the files stream first, and the entry names it.
  Result<std::string> entryBytes(LogEntry& entry);
  // After an entry was appended or folded: the state file it named (or
  // none). A leader purges the one before once a newer entry stands.
  void stateFileStands(const std::optional<LogEntry::StateFile>& file);
  // After JetStream refused an entry for a stale sequence: purges the state
  // file put for it (an entry not acknowledged in time may still be stored,
  // and keeps its file).
  void dropRefusedStateFile(const LogEntry& entry);
  // Purges a file from the files stream; false (logged) when NATS refused.
  bool dropFile(const std::string& key);
  Result<void> commit(const nlohmann::json& state, const ChangeEvent& event);
  // Decodes a forecast an entry names from the files stream.
  LiveWeather::ForecastLoader forecastLoader() const;
  // After an append: purges the files of the forecast held before it that
  // the appended state no longer names.
  void dropUnusedFiles(const nlohmann::json& state);
  // On the io thread, after the lease was taken at `term`: catches up with
  // the log, then appends the term entry that makes this server the leader.
  void claim(std::uint64_t term, int attempt);
  void stepDown(const std::string& why);
  void electionLoop();
  // The election thread's: takes the lease when free and starts the claim
  // on the io thread; the lease's revision, or 0 when another holds it.
  std::uint64_t tryTakeLease();
  // The election thread's, after a renewal was refused at revision `held`:
  // true (and `held` moved on) when the key's newer revision holds this
  // server's own value, i.e. a renewal of ours whose answer was lost
  // landed; false when another server holds the lease or it is gone.
  bool adoptOwnRenewal(std::uint64_t& held);
  // The election thread's, while not holding the lease: follows the log
  // anew when its subscription stalled (`lagging`: since when, at which
  // applied sequence), and reads who leads.
  void watchLog(std::optional<std::pair<std::chrono::steady_clock::time_point, std::uint64_t>>& lagging);
  std::string refusal() const;
  std::string leaseValue() const;
  // This server's record for the registry; on the io thread.
  ClusterMember describeSelf() const;

  Server& server_;
  NatsWeatherOptions options_;
  std::shared_ptr<spdlog::logger> log_;
  std::unique_ptr<NatsLog> natsLog_;
  std::unique_ptr<ClusterRegistry> registry_;  // after natsLog_, which it uses; made by elect()
  boost::asio::steady_timer claimRetry_;
  boost::asio::steady_timer areasPoll_;
  std::optional<std::size_t> areasFingerprint_;  // of the areas last handed to cellFollower_
  CellReach areaCoverings_;                      // the io thread's, for pollAreas

  // The leader's cells for the relays (not on a relay), and a relay's by
  // cell; both after natsLog_, which they use.
  std::unique_ptr<CellPublisher> publisher_;
  std::unique_ptr<CellFollower> cellFollower_;
  // A state a CellFollower handed over while a decode was under way: the
  // newest, folded after it.
  std::optional<std::pair<std::uint64_t, LogEntry>> cellWaiting_;

  // The io thread's: the last stream sequence folded into the weather (by
  // following or by this server's own append).
  // Atomic only so that metrics() may read them from another thread.
  std::atomic<std::uint64_t> applied_{0};
  std::atomic<std::uint64_t> term_{0};  // the term this server leads in, while leading
  std::atomic<bool> leading_{false};
  bool closed_ = false;
  std::chrono::steady_clock::time_point claimStarted_{};
  // A forecast being decoded for an entry (seconds for a large GRIB file),
  // or its state file read, off the io thread so that the weather stream
  // and the HTTP API go on serving the weather folded so far; the entries
  // that arrive meanwhile wait, in order, up to kMaxWaitingBytes (each
  // holds the whole state: one dropped loses only its event from the
  // history). decoding_ is atomic for the election thread, which does not
  // count a decode as a stalled subscription. alive_ is false once closed: a
  // decode that finishes after close() leaves this object alone.
  std::atomic<bool> decoding_{false};
  std::deque<std::pair<std::uint64_t, std::string>> waiting_;
  std::size_t waitingBytes_ = 0;
  std::thread decodeThread_;
  // The io thread's: the newest entry's state file, which a leader's next
  // append makes unused.
  std::optional<std::string> stateFile_;
  std::shared_ptr<std::atomic<bool>> alive_ = std::make_shared<std::atomic<bool>>(true);

  // Shared between the io thread and the election thread.
  mutable std::mutex mutex_;
  std::condition_variable wake_;
  bool stopping_ = false;
  bool leaseLost_ = false;  // set by stepDown: the election thread stops renewing
  std::string apiUrl_, streamAddress_;
  std::string leaderId_, leaderApi_;  // who leads, as last seen
  std::atomic<std::int64_t> leaseRenewedAt_ns_{0};  // steady clock of the last renewal
  std::atomic<std::uint64_t> dropped_{0}, fenced_{0}, appended_{0}, followed_{0};
  std::thread election_;
};

}  // namespace sky::server
