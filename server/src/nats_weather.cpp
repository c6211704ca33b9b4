// The weather on a NATS cluster: the fold of the log, the lease, the
// leader's fenced appends (see nats_weather.hpp).
#include "sky/server/nats_weather.hpp"

#include <algorithm>
#include <span>
#include <utility>
#include <vector>

#include <boost/asio/post.hpp>
#include <spdlog/spdlog.h>

#include "sky/server/forecast_files.hpp"
#include "sky/server/metrics_text.hpp"
#include "sky/server/server.hpp"
#include "sky/server/state_cells.hpp"

namespace sky::server {

namespace {

// How often a follower tries to take the lease, and a leader renews it, as
// fractions of its time to live: a follower notices an expired lease within
// a sixth of it; a leader renews four times per lifetime, so one or two lost
// renewals do not cost the lead.
constexpr int kPollsPerTtl = 6;
constexpr int kRenewalsPerTtl = 4;
// A leader takes changes only while its last renewal (counted from before
// it was sent) is younger than this fraction of the time to live: the key
// expires a whole time to live after the renewal was stored, so the leader
// stops well before another server can take the lead, even with the
// renewal's own latency and clocks running at slightly different rates.
constexpr double kLeaseTrustFraction = 0.5;
// While taking the lead: how often, and how many times, it checks that it
// has folded the whole log before appending its term entry (5 s in all, far
// above the time a follower lags its leader on a loopback or LAN link).
constexpr std::chrono::milliseconds kClaimRetry{20};
constexpr int kClaimAttempts = 250;
// A follower whose log subscription has folded nothing for this long while
// the stream holds newer entries follows anew from its last entry. The
// client's ordered consumer lives on one NATS server; when that server is
// lost, the client notices only after missed heartbeats (seconds), and a
// follower that lags serves old weather. Healthy, it folds an entry within
// milliseconds of its append.
constexpr std::chrono::seconds kFollowStall{1};
// The longest leader id or API address read from another server's lease.
constexpr std::size_t kMaxLeaseText = 512;
// How often a relay by cell looks at its subscribers' areas: a renderer
// subscribes anew when it has moved 30 km (area_of_interest.hpp), so the
// cells it needs are known well before it gets there.
constexpr std::chrono::milliseconds kAreasPoll{250};

// The state an entry names in the files stream: its bytes must have the
// entry's key and size, and be a JSON object.
Result<nlohmann::json> readStateFile(NatsLog& nats, const LogEntry::StateFile& file) {
  auto bytes = nats.getFile(file.key, kMaxStateFile_bytes);
  if (!bytes) return fail(bytes.error().code, "state file " + file.key + ": " + bytes.error().detail);
  const std::string_view json(reinterpret_cast<const char*>(bytes->data()), bytes->size());
  if (json.size() != file.bytes || stateFileKey(json) != file.key)
    return fail(ErrorCode::Malformed, "state file " + file.key + ": " + std::to_string(json.size()) +
                                          " bytes that do not have its key");
  nlohmann::json state = nlohmann::json::parse(json, nullptr, false);
  if (state.is_discarded() || !state.is_object())
    return fail(ErrorCode::Malformed, "state file " + file.key + ": not a JSON object");
  return state;
}

std::int64_t steadyNs() {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(std::chrono::steady_clock::now().time_since_epoch())
      .count();
}

}  // namespace

Result<std::unique_ptr<NatsWeather>> NatsWeather::start(Server& server, NatsWeatherOptions options) {
  auto connected = NatsLog::connect(options.log);
  if (!connected) return tl::unexpected(connected.error());
  std::unique_ptr<NatsWeather> w(new NatsWeather(server, std::move(options), std::move(*connected)));
  if (auto r = w->replay(); !r) return tl::unexpected(r.error());
  LiveWeather& weather = server.weather();
  weather.holdTimeline(true);
  weather.attachCommitter(
      [self = w.get()](const nlohmann::json& state, const ChangeEvent& event) { return self->commit(state, event); });
  // A forecast's files go to the files stream before its change is
  // appended, so a follower that folds the change finds them there.
  weather.attachFileKeeper([self = w.get()](const std::string& key, std::span<const std::byte> bytes) -> Result<void> {
    if (!self->leading_) return fail(ErrorCode::Io, self->refusal());
    return self->natsLog_->putFile(key, bytes);
  });
  if (!w->options_.relay && w->options_.publishCells)
    w->publisher_ = std::make_unique<CellPublisher>(*w->natsLog_, w->log_);
  if (w->options_.relay && w->options_.followCells) return w;  // by cell, from elect()
  auto followed = w->follow();
  if (!followed) return tl::unexpected(followed.error());
  return w;
}

Result<void> NatsWeather::follow() {
  return natsLog_->follow(applied_ + 1, [this](std::uint64_t sequence, std::string_view bytes) {
    boost::asio::post(server_.io(), [this, sequence, b = std::string(bytes)] { onEntry(sequence, b); });
  });
}

NatsWeather::NatsWeather(Server& server, NatsWeatherOptions options, std::unique_ptr<NatsLog> log)
    : server_(server),
      options_(std::move(options)),
      log_(options_.logger ? options_.logger : std::make_shared<spdlog::logger>("sky_nats")),
      natsLog_(std::move(log)),
      claimRetry_(server.io()),
      areasPoll_(server.io()) {}

NatsWeather::~NatsWeather() { close(); }

Result<void> NatsWeather::replay() {
  auto range = natsLog_->range();
  if (!range) return tl::unexpected(range.error());
  LiveWeather& weather = server_.weather();
  if (range->last == 0) {
    log_->info("event=nats_log_empty stream={} replicas={}: the scenario's weather stands until a leader writes it",
               options_.log.stream, natsLog_->replicas());
    return {};
  }
  const std::uint64_t from = std::max(range->first, range->last >= kReplayEntries ? range->last - kReplayEntries + 1 : 1);
  std::vector<ChangeEvent> events;
  std::optional<LogEntry> newest;
  std::uint64_t bad = 0;
  for (std::uint64_t seq = from; seq <= range->last; ++seq) {
    auto bytes = natsLog_->read(seq);
    if (!bytes) return tl::unexpected(bytes.error());
    if (!*bytes) continue;  // discarded by the stream's limit meanwhile
    auto entry = decodeLogEntry(**bytes);
    if (!entry) {
      ++bad;
      log_->warn("event=nats_entry_dropped sequence={} detail={:?}", seq, describe(entry.error()));
      continue;
    }
    if (entry->event) events.push_back(*entry->event);
    newest = std::move(*entry);
  }
  dropped_ += bad;
  if (!newest) return fail(ErrorCode::Malformed, "NATS stream " + options_.log.stream + ": no readable entry in " +
                                                     std::to_string(from) + ".." + std::to_string(range->last));
  // An entry this server cannot fold (its forecast's files unreadable or
  // undecodable here) does not stop it: it keeps the scenario's weather,
  // as a follower keeps its last after such an entry (onEntry), and
  // follows from there. So does a state file it cannot read.
  Result<void> r;
  if (newest->stateFile) {
    auto state = readStateFile(*natsLog_, *newest->stateFile);
    if (state) newest->state = std::move(*state);
    else r = tl::unexpected(state.error());
    stateFile_ = newest->stateFile->key;
  }
  if (r) r = weather.restore(newest->state, std::move(events), forecastLoader());
  if (!r) {
    ++dropped_;
    log_->error("event=nats_entry_dropped sequence={} detail={:?}: the scenario's weather stands until an entry "
                "this server can fold", range->last, describe(r.error()));
  }
  applied_ = range->last;
  {
    std::lock_guard lock(mutex_);
    leaderId_ = newest->leaderId;
    leaderApi_ = newest->leaderApi;
  }
  log_->info("event=nats_replayed stream={} replicas={} entries={}..{} dropped={} sequence={} state_hash={:016x}",
             options_.log.stream, natsLog_->replicas(), from, range->last, bad, weather.view().lastSequence,
             weather.stateHash());
  return {};
}

void NatsWeather::onEntry(std::uint64_t sequence, const std::string& bytes) {
  if (sequence <= applied_) return;  // this server's own append, or one folded already
  if (decoding_) {
    waitingBytes_ += bytes.size();
    waiting_.emplace_back(sequence, bytes);
    while (waitingBytes_ > kMaxWaitingBytes && waiting_.size() > 1) {
      ++dropped_;
      log_->warn("event=nats_entry_dropped sequence={} detail=\"{} bytes of entries waited for a forecast's "
                 "decode or a state file; a later entry holds the whole state\"",
                 waiting_.front().first, waitingBytes_);
      waitingBytes_ -= waiting_.front().second.size();
      waiting_.pop_front();
    }
    return;
  }
  ++followed_;
  if (leading_) stepDown("the log moved to sequence " + std::to_string(sequence) + " past this leader's " +
                         std::to_string(applied_.load()));
  auto entry = decodeLogEntry(bytes);
  if (!entry) return fold(sequence, std::move(entry), {});
  if (entry->stateFile) return readStateThenFold(sequence, std::move(*entry));
  foldOrDecode(sequence, std::move(*entry));
}

void NatsWeather::onCellState(std::uint64_t sequence, LogEntry entry) {
  if (decoding_) {
    cellWaiting_.emplace(sequence, std::move(entry));
    return;
  }
  // A state joined again for other areas comes at the sequence folded.
  if (sequence < applied_) return;
  ++followed_;
  if (entry.stateFile) return readStateThenFold(sequence, std::move(entry));
  foldOrDecode(sequence, std::move(entry));
}

void NatsWeather::pollAreas() {
  const std::vector<weather::SphericalCap> areas = server_.subscribedAreas();
  std::size_t fingerprint = areas.size();
  for (const auto& a : areas)
    for (double v : {a.centerLat_deg, a.centerLon_deg, a.radius_m})
      fingerprint = fingerprint * 1000003u ^ std::hash<double>{}(v);
  if (fingerprint != areasFingerprint_) {
    areasFingerprint_ = fingerprint;
    bool tooMany = false;
    auto keys = cellsForAreas(areas, areaCoverings_, tooMany);
    cellFollower_->want(std::move(keys), tooMany);
  }
  areasPoll_.expires_after(kAreasPoll);
  areasPoll_.async_wait([this](const boost::system::error_code& ec) {
    if (!ec && !closed_) pollAreas();
  });
}

void NatsWeather::foldOrDecode(std::uint64_t sequence, LogEntry entry) {
  if (entry.state.is_object() && entry.state.contains("forecast") && !entry.state["forecast"].is_null() &&
      !server_.weather().holdsForecast(entry.state["forecast"]))
    return decodeThenFold(sequence, std::move(entry));
  fold(sequence, std::move(entry), {});
}

void NatsWeather::offIoThread(std::function<std::function<void()>()> work) {
  decoding_ = true;
  if (decodeThread_.joinable()) decodeThread_.join();  // the last one, which posted its result already
  decodeThread_ = std::thread([this, work = std::move(work), alive = alive_] {
    std::function<void()> then = work();
    if (!*alive) return;
    boost::asio::post(server_.io(), [this, then = std::move(then), alive] {
      if (!*alive) return;
      decoding_ = false;
      then();
      // The entries that arrived meanwhile, in order; `then` or one of them
      // may go off the io thread again, and the rest then wait for it.
      auto waiting = std::exchange(waiting_, {});
      waitingBytes_ = 0;
      for (auto& [next, bytes] : waiting) onEntry(next, bytes);
      if (auto cell = std::exchange(cellWaiting_, std::nullopt)) onCellState(cell->first, std::move(cell->second));
    });
  });
}

void NatsWeather::decodeThenFold(std::uint64_t sequence, LogEntry entry) {
  nlohmann::json saved = entry.state["forecast"];
  offIoThread([this, load = forecastLoader(), saved = std::move(saved), sequence,
               entry = std::move(entry)]() -> std::function<void()> {
    auto decoded = std::make_shared<Result<LoadedForecast>>(load(saved));
    return [this, sequence, entry, decoded] {
      fold(sequence, entry,
           [decoded](const nlohmann::json&) -> Result<LoadedForecast> { return std::move(*decoded); });
    };
  });
}

void NatsWeather::readStateThenFold(std::uint64_t sequence, LogEntry entry) {
  offIoThread([this, sequence, entry = std::move(entry)]() -> std::function<void()> {
    auto state = std::make_shared<Result<nlohmann::json>>(readStateFile(*natsLog_, *entry.stateFile));
    return [this, sequence, entry, state]() mutable {
      if (!*state) return fold(sequence, tl::unexpected(state->error()), {});
      entry.state = std::move(**state);
      stateFileStands(entry.stateFile);
      entry.stateFile.reset();
      foldOrDecode(sequence, std::move(entry));
    };
  });
}

Result<std::string> NatsWeather::entryBytes(LogEntry& entry) {
  // An entry is at most what a message of the NATS server may be (its
  // max_payload, 1 MiB by default) and what a follower reads. The state,
  // dumped once, says whether the entry may fit: around it an entry has its
  // kind, term, two texts and an event of three more, each text at most
  // kMaxLogEntryText bytes. JSON escapes can grow a text (a control
  // character takes six bytes), so an entry that may fit is measured before
  // it goes inline.
  constexpr std::size_t kAroundState_bytes = 6 * kMaxLogEntryText + 1024;
  const std::size_t limit = std::min(kMaxLogEntry_bytes, natsLog_->messageLimit());
  std::string json = entry.state.dump();
  if (json.size() + kAroundState_bytes <= limit)
    if (std::string bytes = encodeLogEntry(entry, json); bytes.size() <= limit) return bytes;
  if (json.size() > kMaxStateFile_bytes)
    return fail(ErrorCode::TooLarge, "the weather's state is " + std::to_string(json.size()) +
                                         " bytes, more than the NATS log holds (" +
                                         std::to_string(kMaxStateFile_bytes) + ")");
  LogEntry::StateFile file{stateFileKey(json), json.size()};
  if (auto put = natsLog_->putFile(file.key, std::as_bytes(std::span(json.data(), json.size()))); !put)
    return fail(put.error().code, "the weather's state (" + std::to_string(json.size()) +
                                      " bytes) not stored in the files stream: " + put.error().detail);
  entry.stateFile = std::move(file);
  return encodeLogEntry(entry);
}

void NatsWeather::dropRefusedStateFile(const LogEntry& entry) {
  // JetStream refused the entry (not stored): no entry names its state
  // file, unless it is the newest entry's own (the same state).
  if (entry.stateFile && entry.stateFile->key != stateFile_) dropFile(entry.stateFile->key);
}

void NatsWeather::stateFileStands(const std::optional<LogEntry::StateFile>& file) {
  const std::optional<std::string> key = file ? std::optional(file->key) : std::nullopt;
  // A follower still folding the entry before fails to read it and folds
  // this one, which holds the whole state.
  if (stateFile_ && stateFile_ != key && leading_) dropFile(*stateFile_);
  stateFile_ = key;
}

bool NatsWeather::dropFile(const std::string& key) {
  if (auto dropped = natsLog_->dropFile(key); !dropped) {
    log_->warn("event=nats_file_kept key={} detail={:?}", key, describe(dropped.error()));
    return false;
  }
  return true;
}

void NatsWeather::fold(std::uint64_t sequence, Result<LogEntry> entry, const LiveWeather::ForecastLoader& loader) {
  LiveWeather& weather = server_.weather();
  if (entry) {
    std::vector<ChangeEvent> events = weather.events(kReplayEntries);
    if (entry->event) events.push_back(*entry->event);
    if (auto r = weather.restore(entry->state, std::move(events), loader); !r) entry = tl::unexpected(r.error());
  }
  applied_ = sequence;
  if (!entry) {
    ++dropped_;
    log_->warn("event=nats_entry_dropped sequence={} detail={:?}", sequence, describe(entry.error()));
    return;
  }
  {
    std::lock_guard lock(mutex_);
    leaderId_ = entry->leaderId;
    leaderApi_ = entry->leaderApi;
  }
  log_->debug("event=nats_entry_applied sequence={} term={} leader={:?}", sequence, entry->term, entry->leaderId);
  // A change reaches this server's subscribers and consoles as one made
  // here would; a term entry changes nothing they see but the version.
  if (entry->event) weather.announce(*entry->event);
  else server_.weatherReplaced();
}

Result<void> NatsWeather::commit(const nlohmann::json& state, const ChangeEvent& event) {
  if (!leading_) return fail(ErrorCode::Io, refusal());
  const double age_s = double(steadyNs() - leaseRenewedAt_ns_.load()) * 1e-9;
  const double trust_s = kLeaseTrustFraction * std::chrono::duration<double>(options_.log.leaseTtl).count();
  if (age_s >= trust_s) {
    stepDown("lease last renewed " + std::to_string(static_cast<int>(age_s * 1000)) + " ms ago");
    return fail(ErrorCode::Io, refusal());
  }
  LogEntry entry;
  entry.kind = LogEntry::Kind::Change;
  entry.term = term_;
  entry.leaderId = options_.serverId;
  {
    std::lock_guard lock(mutex_);
    entry.leaderApi = apiUrl_;
  }
  entry.state = state;
  entry.event = event;
  auto bytes = entryBytes(entry);
  if (!bytes) return tl::unexpected(bytes.error());
  auto appended = natsLog_->append(*bytes, applied_);
  if (!appended)
    return fail(appended.error().code, "change not acknowledged by JetStream (it may still be stored; the "
                                       "weather shows it if so): " + appended.error().detail);
  if (!appended->stored) {
    ++fenced_;
    dropRefusedStateFile(entry);
    stepDown("fenced: the stream moved past sequence " + std::to_string(applied_.load()) +
             " (another server appended)");
    return fail(ErrorCode::Io, refusal());
  }
  applied_ = appended->sequence;
  ++appended_;
  dropUnusedFiles(state);
  stateFileStands(entry.stateFile);
  if (publisher_) publisher_->offer(applied_, std::move(entry));
  return {};
}

LiveWeather::ForecastLoader NatsWeather::forecastLoader() const {
  const std::size_t maxBytes = options_.gribDecoder.maxFileBytes;
  auto load = sky::server::forecastLoader(
      [nats = natsLog_.get(), maxBytes](const std::string& key) { return nats->getFile(key, maxBytes); },
      options_.gribDecoder);
  // Once per forecast loaded (restore keeps a forecast it holds already):
  // at start on the io thread, before the server serves; while following,
  // on decodeThenFold's thread.
  return [load = std::move(load), log = log_](const nlohmann::json& saved) -> Result<LoadedForecast> {
    const std::int64_t t0 = steadyNs();
    auto loaded = load(saved);
    if (loaded)
      log->info("event=nats_forecast_decoded name={:?} files={} ms={:.0f}", saved.value("name", std::string()),
                loaded->files.size(), double(steadyNs() - t0) * 1e-6);
    return loaded;
  };
}

void NatsWeather::dropUnusedFiles(const nlohmann::json& state) {
  // The weather still holds the state before this change.
  const auto held = server_.weather().forecast();
  if (!held) return;
  std::vector<std::string> kept;
  if (state.contains("forecast") && !state.at("forecast").is_null())
    if (auto files = forecastFilesFromJson(state.at("forecast")))
      for (const auto& f : *files) kept.push_back(f.key);
  for (const auto& f : held->files) {
    if (std::find(kept.begin(), kept.end(), f.key) != kept.end()) continue;
    // A follower still folding an older entry that names the file fails to
    // decode it and folds the next entry, which holds the whole state.
    if (dropFile(f.key)) log_->info("event=nats_file_dropped key={} name={:?}", f.key, f.name);
  }
}

void NatsWeather::elect(std::string apiUrl, std::string streamAddress) {
  {
    std::lock_guard lock(mutex_);
    apiUrl_ = std::move(apiUrl);
    streamAddress_ = std::move(streamAddress);
  }
  if (options_.relay && options_.followCells) {
    cellFollower_ = std::make_unique<CellFollower>(
        *natsLog_, log_,
        [this, alive = alive_](std::uint64_t sequence, LogEntry entry) {
          boost::asio::post(server_.io(), [this, alive, sequence, entry = std::move(entry)]() mutable {
            if (*alive) onCellState(sequence, std::move(entry));
          });
        },
        applied_.load());
    pollAreas();
  }
  election_ = std::thread([this] { electionLoop(); });
  registry_ = std::make_unique<ClusterRegistry>(*natsLog_, server_.io(), [this] { return describeSelf(); }, log_);
  registry_->start();
}

void NatsWeather::electionLoop() {
  const auto ttl = options_.log.leaseTtl;
  const auto poll = ttl / kPollsPerTtl, renewEvery = ttl / kRenewalsPerTtl;
  std::uint64_t held = 0;  // the lease's revision this server wrote last (0: none; revisions start at 1)
  std::int64_t renewedAt_ns = 0;
  // A follower lagging the stream: since when, at which applied sequence.
  std::optional<std::pair<std::chrono::steady_clock::time_point, std::uint64_t>> lagging;
  for (;;) {
    bool lost = false;
    {
      std::unique_lock lock(mutex_);
      // A holder wakes when its renewal is due; a follower every poll.
      const auto wait = held != 0 ? std::chrono::duration_cast<std::chrono::nanoseconds>(renewEvery) -
                                   std::chrono::nanoseconds(steadyNs() - renewedAt_ns)
                             : std::chrono::duration_cast<std::chrono::nanoseconds>(poll);
      wake_.wait_for(lock, std::max(wait, std::chrono::nanoseconds{0}), [this] { return stopping_ || leaseLost_; });
      if (stopping_) break;
      lost = std::exchange(leaseLost_, false);
    }
    if (lost && held != 0) {
      // Stepped down while the lease is still this server's: free it for
      // the others now rather than when it expires.
      (void)natsLog_->releaseLease(held);
      held = 0;
      continue;
    }
    if (held == 0) {
      // A relay never asks for the lease: it only watches the log.
      if (!options_.relay && (held = tryTakeLease()) != 0) {
        renewedAt_ns = leaseRenewedAt_ns_.load();
        continue;
      }
      watchLog(lagging);
      continue;
    }
    if (std::chrono::nanoseconds(steadyNs() - renewedAt_ns) < renewEvery) continue;
    const std::int64_t sentAt_ns = steadyNs();
    auto renewed = natsLog_->renewLease(leaseValue(), held);
    if (renewed && *renewed) {
      held = **renewed;
      renewedAt_ns = sentAt_ns;
      leaseRenewedAt_ns_ = sentAt_ns;
    } else if (renewed && adoptOwnRenewal(held)) {
      // The key's revision is past ours and the value there is ours: a
      // renewal whose answer timed out had landed. The lease is still this
      // server's; the next turn renews it at the revision adopted. Not
      // counted as renewed (leaseRenewedAt_ns_ stays): when it landed is
      // not known, so commit() goes on trusting the lease only from the
      // renewal this server saw.
      continue;
    } else if (renewed) {
      held = 0;
      boost::asio::post(server_.io(), [this] { stepDown("lease lost: another server holds it"); });
    }
    // A failed request (a server of the cluster gone, a timeout) is tried
    // again; meanwhile the leader refuses changes once the lease may lapse.
  }
  if (held != 0) (void)natsLog_->releaseLease(held);
}

bool NatsWeather::adoptOwnRenewal(std::uint64_t& held) {
  auto lease = natsLog_->readLease();
  if (!lease || !*lease || (*lease)->revision <= held || (*lease)->value != leaseValue()) return false;
  log_->info("event=nats_lease_adopted revision={} was={} (a renewal whose answer was lost had landed)",
             (*lease)->revision, held);
  held = (*lease)->revision;
  return true;
}

std::uint64_t NatsWeather::tryTakeLease() {
  const std::int64_t sentAt_ns = steadyNs();
  auto taken = natsLog_->takeLease(leaseValue());
  if (!taken || !*taken) return 0;
  leaseRenewedAt_ns_ = sentAt_ns;
  const std::uint64_t term = **taken;
  boost::asio::post(server_.io(), [this, term] {
    claimStarted_ = std::chrono::steady_clock::now();
    claim(term, 0);
  });
  return term;
}

void NatsWeather::watchLog(std::optional<std::pair<std::chrono::steady_clock::time_point, std::uint64_t>>& lagging) {
  // A relay by cell follows no log subscription (its CellFollower reads
  // back what it missed).
  if (auto range = cellFollower_ ? Result<NatsLog::Range>(tl::unexpected(Error{})) : natsLog_->range(); range) {
    const std::uint64_t applied = applied_.load();
    const auto now = std::chrono::steady_clock::now();
    // An entry read or decoded off the io thread holds the fold, not the
    // subscription.
    if (range->last <= applied || decoding_ || (lagging && lagging->second != applied)) {
      lagging.reset();
    } else if (!lagging) {
      lagging.emplace(now, applied);
    } else if (now - lagging->first >= kFollowStall) {
      log_->warn("event=nats_follow_again applied={} stream_last={} (no entry folded for {} ms)", applied,
                 range->last, std::chrono::duration_cast<std::chrono::milliseconds>(now - lagging->first).count());
      if (auto r = follow(); !r) log_->warn("event=nats_follow_failed detail={:?}", describe(r.error()));
      lagging.reset();
    }
  }
  auto lease = natsLog_->readLease();
  if (lease && *lease) {
    const auto j = nlohmann::json::parse((*lease)->value, nullptr, false);
    if (j.is_object() && j.contains("id") && j["id"].is_string() && j.contains("api") && j["api"].is_string() &&
        j["id"].get_ref<const std::string&>().size() <= kMaxLeaseText &&
        j["api"].get_ref<const std::string&>().size() <= kMaxLeaseText) {
      std::lock_guard lock(mutex_);
      leaderId_ = j["id"].get<std::string>();
      leaderApi_ = j["api"].get<std::string>();
    }
  }
}

void NatsWeather::claim(std::uint64_t term, int attempt) {
  if (leading_ || closed_) return;
  {
    std::lock_guard lock(mutex_);
    if (leaseLost_) return;
  }
  auto retry = [this, term, attempt](const std::string& why) {
    if (attempt + 1 >= kClaimAttempts) {
      stepDown("could not take the lead: " + why);
      return;
    }
    claimRetry_.expires_after(kClaimRetry);
    claimRetry_.async_wait([this, term, attempt](const boost::system::error_code& ec) {
      if (!ec) claim(term, attempt + 1);
    });
  };
  auto range = natsLog_->range();
  if (!range) return retry(describe(range.error()));
  if (applied_ < range->last)
    return retry("the log is at " + std::to_string(range->last) + ", folded to " + std::to_string(applied_.load()));
  LogEntry entry;
  entry.kind = LogEntry::Kind::Term;
  entry.term = term;
  entry.leaderId = options_.serverId;
  {
    std::lock_guard lock(mutex_);
    entry.leaderApi = apiUrl_;
  }
  entry.state = server_.weather().toJson();
  auto bytes = entryBytes(entry);
  if (!bytes) return retry(describe(bytes.error()));
  auto appended = natsLog_->append(*bytes, applied_);
  if (!appended) return retry(describe(appended.error()));
  if (!appended->stored) {
    dropRefusedStateFile(entry);
    return retry("another server appended meanwhile");
  }
  applied_ = appended->sequence;
  term_ = term;
  leading_ = true;
  stateFileStands(entry.stateFile);
  {
    std::lock_guard lock(mutex_);
    leaderId_ = entry.leaderId;
    leaderApi_ = entry.leaderApi;
  }
  if (publisher_) publisher_->offer(applied_, entry);
  server_.weather().holdTimeline(false);
  server_.weatherReplaced();
  const auto took_ms =
      std::chrono::duration_cast<std::chrono::milliseconds>(std::chrono::steady_clock::now() - claimStarted_).count();
  log_->info("event=nats_leading term={} sequence={} claim_ms={} state_hash={:016x}", term, applied_.load(), took_ms,
             server_.weather().stateHash());
}

void NatsWeather::stepDown(const std::string& why) {
  claimRetry_.cancel();
  if (leading_) log_->warn("event=nats_step_down term={} why={:?}", term_.load(), why);
  else log_->info("event=nats_not_leading why={:?}", why);
  leading_ = false;
  term_ = 0;
  if (publisher_) publisher_->forget();
  {
    std::lock_guard lock(mutex_);
    leaseLost_ = true;
  }
  wake_.notify_all();
  server_.weather().holdTimeline(true);
  server_.weatherReplaced();
}

void NatsWeather::close() {
  if (closed_) return;
  closed_ = true;
  *alive_ = false;
  if (decodeThread_.joinable()) decodeThread_.join();
  claimRetry_.cancel();
  leading_ = false;
  {
    std::lock_guard lock(mutex_);
    stopping_ = true;
  }
  wake_.notify_all();
  if (election_.joinable()) election_.join();
  if (registry_) registry_->stop();
  areasPoll_.cancel();
  if (cellFollower_) cellFollower_->stop();
  if (publisher_) publisher_->stop();
  natsLog_->stopFollowing();
}

std::string NatsWeather::refusal() const {
  std::lock_guard lock(mutex_);
  if (options_.relay)
    return "a relay serves the weather read-only" +
           (leaderId_.empty() ? std::string("; no server leads yet") :
                                "; " + leaderId_ + " leads" + (leaderApi_.empty() ? "" : " (" + leaderApi_ + ")") +
                                    ", send changes there");
  if (leaderId_.empty() || leaderId_ == options_.serverId)
    return "not the leader: this server follows the NATS log and no other server leads yet (an election "
           "takes up to the lease's time to live); try again";
  return "not the leader: " + leaderId_ + " leads" + (leaderApi_.empty() ? "" : " (" + leaderApi_ + ")") +
         "; send changes there";
}

std::string NatsWeather::leaseValue() const {
  std::lock_guard lock(mutex_);
  return nlohmann::json{{"id", options_.serverId}, {"api", apiUrl_}}.dump();
}

ClusterMember NatsWeather::describeSelf() const {
  ClusterMember m;
  m.id = options_.serverId;
  m.role = options_.relay ? ClusterMember::Role::Relay
           : leading_     ? ClusterMember::Role::Leader
                          : ClusterMember::Role::Follower;
  {
    std::lock_guard lock(mutex_);
    m.stream = streamAddress_;
    m.api = apiUrl_;
  }
  m.subscribers = server_.subscribers();
  m.appliedSequence = applied_;
  m.term = term_;
  m.stateHash = fmt::format("{:016x}", server_.weather().stateHash());
  m.updated_unixMs =
      std::chrono::duration_cast<std::chrono::milliseconds>(std::chrono::system_clock::now().time_since_epoch()).count();
  return m;
}

nlohmann::json NatsWeather::cluster() const {
  nlohmann::json j = registry_ ? registry_->view()
                               : nlohmann::json{{"members", nlohmann::json::array()}, {"read_age_ms", nullptr},
                                                {"malformed_records", 0}};
  j["nats"] = true;
  j["self"] = options_.serverId;
  return j;
}

std::string NatsWeather::metrics() const {
  std::string m;
  auto line = [&m](const char* name, const char* type, const char* help, std::uint64_t v) {
    appendMetric(m, name, type, help, v);
  };
  line("skyshell_nats_leader", "gauge", "1 while this server leads the weather on NATS", leading_ ? 1 : 0);
  line("skyshell_nats_relay", "gauge", "1 for a relay (follows the log, never leads)", options_.relay ? 1 : 0);
  line("skyshell_nats_term", "gauge", "the lease revision this server leads in (0: following)", term_.load());
  line("skyshell_nats_applied_sequence", "gauge", "the last NATS log sequence folded into the weather",
       applied_.load());
  line("skyshell_nats_appended_total", "counter", "changes this server appended to the NATS log", appended_.load());
  line("skyshell_nats_followed_total", "counter", "log entries of other servers folded in", followed_.load());
  line("skyshell_nats_decoding", "gauge",
       "1 while an entry's forecast is decoded or its state file read (the entries after it wait)",
       decoding_ ? 1 : 0);
  line("skyshell_nats_waiting_entries", "gauge", "log entries waiting for that", waiting_.size());
  line("skyshell_nats_entries_dropped_total", "counter", "log entries dropped: malformed, or not foldable here (a forecast whose files cannot be read or decoded)", dropped_.load());
  line("skyshell_nats_fenced_total", "counter", "appends refused by JetStream for a stale last sequence",
       fenced_.load());
  if (publisher_) m += publisher_->metrics();
  if (cellFollower_) m += cellFollower_->metrics();
  // A 64-bit hash does not fit a Prometheus value (a double): it is the
  // label of an info metric, compared as text.
  m += fmt::format("# HELP skyshell_state_hash_info the weather's state hash (FNV-1a of the canonical state "
                   "without the clock's position)\n# TYPE skyshell_state_hash_info gauge\nskyshell_state_hash_info{{hash=\"{:016x}\"}} 1\n",
                   server_.weather().stateHash());
  return m;
}

}  // namespace sky::server
