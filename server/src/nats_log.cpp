// The change log and the lease on JetStream (see nats_log.hpp). Every nats.c
// handle is owned by a unique_ptr with its destroy function; the lease is a
// KV bucket's key written with JetStream's expected-last-subject-sequence
// header directly (not through kvStore_Create/Update), so that a lease held
// by another server and a failed request are told apart by JetStream's
// error code, and a release deletes only the revision this holder wrote.
#include "sky/server/nats_log.hpp"

#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <condition_variable>
#include <mutex>
#include <thread>
#include <utility>

#include <nats/nats.h>

#include "nats_handles.hpp"

namespace sky::server {

namespace {

// How long connect() waits between tries while JetStream is not ready.
constexpr std::chrono::milliseconds kReadyRetry{250};
// Pause between reconnect attempts to a cluster: a lost server is replaced
// by another of the list within this, not nats.c's default 2 s.
constexpr std::int64_t kReconnectWait_ms = 100;
// The longest wait for one publish's acknowledgement before it is sent
// again (with the same message id, so JetStream stores it once): while a
// stream elects a new leader after a server is lost, a publish is dropped by
// the replicas that do not lead and would otherwise wait its whole budget.
constexpr std::chrono::milliseconds kPublishAttemptWait{1000};
constexpr std::chrono::milliseconds kPublishRetryPause{100};
constexpr std::chrono::seconds kFollowHeartbeat{1};

const char* const kExpectedLastSeq = "Nats-Expected-Last-Sequence";
const char* const kExpectedLastSubjectSeq = "Nats-Expected-Last-Subject-Sequence";

}  // namespace

Error natsError(const std::string& what, natsStatus s, jsErrCode jerr) {
  const char* last = nats_GetLastError(nullptr);
  std::string detail = what + ": " + natsStatus_GetText(s);
  if (jerr != 0) detail += " (JetStream error " + std::to_string(static_cast<int>(jerr)) + ")";
  if (last && *last) detail += ": " + std::string(last);
  return Error{s == NATS_TIMEOUT ? ErrorCode::Timeout : ErrorCode::Io, detail};
}

namespace {

void onMessage(natsConnection*, natsSubscription*, natsMsg* raw, void* closure) {
  MsgPtr msg(raw);
  auto* state = static_cast<FollowState*>(closure);
  jsMsgMetaData* rawMeta = nullptr;
  if (natsMsg_GetMetaData(&rawMeta, msg.get()) != NATS_OK) return;  // not a stream message: dropped
  MetaPtr meta(rawMeta);
  const std::string_view bytes(natsMsg_GetData(msg.get()), static_cast<std::size_t>(natsMsg_GetDataLength(msg.get())));
  std::lock_guard lock(state->mutex);
  if (state->onEntry) state->onEntry(meta->Sequence.Stream, bytes);
}

void onFollowComplete(void* closure) {
  auto* state = static_cast<FollowState*>(closure);
  std::lock_guard lock(state->mutex);
  state->complete = true;
  state->done.notify_all();
}

}  // namespace

Result<int> ensureStream(jsCtx* js, jsStreamConfig& config) {
  jsStreamInfo* raw = nullptr;
  jsErrCode jerr = static_cast<jsErrCode>(0);
  natsStatus s = js_GetStreamInfo(&raw, js, config.Name, nullptr, &jerr);
  StreamInfoPtr info(raw);
  if (s == NATS_OK) return static_cast<int>(info->Config->Replicas);
  if (s != NATS_NOT_FOUND) return tl::unexpected(natsError(std::string("stream ") + config.Name + " info", s, jerr));
  raw = nullptr;
  s = js_AddStream(&raw, js, &config, nullptr, &jerr);
  info.reset(raw);
  if (s != NATS_OK && config.Replicas > 1 &&
      (jerr == JSStreamReplicasNotSupportedErr || jerr == JSInsufficientResourcesErr)) {
    config.Replicas = 1;
    raw = nullptr;
    s = js_AddStream(&raw, js, &config, nullptr, &jerr);
    info.reset(raw);
  }
  if (s != NATS_OK) return tl::unexpected(natsError(std::string("stream ") + config.Name + " create", s, jerr));
  return static_cast<int>(info->Config->Replicas);
}

namespace {

// Opens a KV bucket, making it when missing: one value per key (no
// history), each expiring `ttl` after it was put (0: never).
Result<KvPtr> ensureBucket(jsCtx* js, const std::string& bucket, std::chrono::milliseconds ttl, int replicas) {
  kvStore* raw = nullptr;
  natsStatus s = js_KeyValue(&raw, js, bucket.c_str());
  KvPtr kv(raw);
  if (s == NATS_OK) return kv;
  kvConfig config;
  kvConfig_Init(&config);
  config.Bucket = bucket.c_str();
  config.History = 1;
  config.TTL = std::chrono::nanoseconds(ttl).count();  // nats.c takes it in ns, as JetStream does
  config.StorageType = js_FileStorage;
  config.Replicas = replicas;
  raw = nullptr;
  s = js_CreateKeyValue(&raw, js, &config);
  kv.reset(raw);
  if (s != NATS_OK) return tl::unexpected(natsError("KV bucket " + bucket + " create", s));
  return kv;
}

}  // namespace

Result<std::unique_ptr<NatsLog>> NatsLog::connect(const NatsLogOptions& options) {
  if (options.urls.empty()) return fail(ErrorCode::InvalidArgument, "NATS: no server URL");
  auto h = std::make_unique<Handles>();
  h->options = options;
  natsOptions* rawOptions = nullptr;
  if (natsStatus s = natsOptions_Create(&rawOptions); s != NATS_OK)
    return tl::unexpected(natsError("NATS options", s));
  OptionsPtr opts(rawOptions);
  std::vector<const char*> urls;
  for (const auto& u : options.urls) urls.push_back(u.c_str());
  natsOptions_SetServers(opts.get(), urls.data(), static_cast<int>(urls.size()));
  natsOptions_SetName(opts.get(), "skyshell-weatherd");
  natsOptions_SetMaxReconnect(opts.get(), -1);
  natsOptions_SetReconnectWait(opts.get(), kReconnectWait_ms);
  // The operator's order of servers is the order of preference.
  natsOptions_SetNoRandomize(opts.get(), true);
  natsOptions_SetTimeout(opts.get(), options.requestWait.count());
  if (options.sharedDelivery) natsOptions_UseGlobalMessageDelivery(opts.get(), true);
  natsConnection* rawConnection = nullptr;
  if (natsStatus s = natsConnection_Connect(&rawConnection, opts.get()); s != NATS_OK)
    return tl::unexpected(natsError("NATS connect " + options.urls.front(), s));
  h->connection.reset(rawConnection);
  jsOptions jsOpts;
  jsOptions_Init(&jsOpts);
  jsOpts.Wait = options.requestWait.count();
  jsCtx* rawJs = nullptr;
  if (natsStatus s = natsConnection_JetStream(&rawJs, h->connection.get(), &jsOpts); s != NATS_OK)
    return tl::unexpected(natsError("JetStream context", s));
  h->js.reset(rawJs);

  jsStreamConfig config;
  jsStreamConfig_Init(&config);
  config.Name = options.stream.c_str();
  const char* subjects[] = {options.subject.c_str()};
  config.Subjects = subjects;
  config.SubjectsLen = 1;
  config.Storage = js_FileStorage;
  config.Replicas = options.replicas;
  config.MaxMsgs = static_cast<int64_t>(options.maxEntries);
  const auto deadline = std::chrono::steady_clock::now() + options.readyWait;
  for (;;) {
    jsStreamConfig attempt = config;
    auto replicas = ensureStream(h->js.get(), attempt);
    Result<KvPtr> registry = tl::unexpected(replicas ? Error{} : replicas.error());
    if (replicas) {
      auto lease = ensureBucket(h->js.get(), options.leaseBucket, options.leaseTtl, *replicas);
      registry = lease ? ensureBucket(h->js.get(), options.registryBucket, options.registryTtl, *replicas)
                       : Result<KvPtr>(tl::unexpected(lease.error()));
      // The areas' values stand until replaced (no time to live).
      auto areas = registry ? ensureBucket(h->js.get(), options.areasBucket, std::chrono::milliseconds{0}, *replicas)
                            : Result<KvPtr>(tl::unexpected(registry.error()));
      if (areas) h->areas = std::move(*areas);
      else registry = tl::unexpected(areas.error());
      if (registry)
        if (auto files = ensureFilesStream(h->js.get(), options, *replicas); !files)
          registry = tl::unexpected(files.error());
    }
    if (registry) {
      h->areaWatch.subjectPrefix = "$KV." + options.areasBucket + ".";
      h->replicas = *replicas;
      h->registry = std::move(*registry);
      break;
    }
    if (std::chrono::steady_clock::now() >= deadline)
      return fail(ErrorCode::Timeout, "JetStream not ready in " + std::to_string(options.readyWait.count()) +
                                          " ms: " + registry.error().detail);
    std::this_thread::sleep_for(kReadyRetry);
  }
  return std::unique_ptr<NatsLog>(new NatsLog(std::move(h)));
}

NatsLog::NatsLog(std::unique_ptr<Handles> handles) : h_(std::move(handles)) {}
NatsLog::~NatsLog() = default;

int NatsLog::replicas() const { return h_->replicas; }
const NatsLogOptions& NatsLog::options() const { return h_->options; }

std::size_t NatsLog::messageLimit() const {
  // The headers a publish carries (the expected last sequence, the message
  // id) count against max_payload too.
  constexpr std::int64_t kHeaderRoom_bytes = 1024;
  // Read at every call: after a reconnect another server may announce
  // another limit. 0 or less: not connected now; the default then.
  const std::int64_t announced = natsConnection_GetMaxPayload(h_->connection.get());
  const std::int64_t payload = announced > 0 ? announced : std::int64_t(kMaxNatsFileChunk_bytes);
  return std::size_t(std::clamp<std::int64_t>(payload - kHeaderRoom_bytes, 1, std::int64_t(kMaxNatsFileChunk_bytes)));
}

namespace {

// Publishes with one expectation header; stored, fenced (JetStream's wrong
// last sequence) or failed.
// A message id no other publish of any process shares: the process, this
// publish's number in it, and the time it started.
std::string uniqueMessageId() {
  static std::atomic<std::uint64_t> next{0};
  return std::to_string(::getpid()) + "-" + std::to_string(next.fetch_add(1)) + "-" +
         std::to_string(std::chrono::system_clock::now().time_since_epoch().count());
}

// Publishes with one expectation header; stored, fenced (JetStream's wrong
// last sequence) or failed. Sent again under the same message id while
// unanswered and within `wait`: JetStream answers a repeat with the first
// one's sequence (it checks the id before the expectation).
Result<NatsLog::Appended> publishExpecting(jsCtx* js, const std::string& subject, std::string_view bytes,
                                           const char* header, std::uint64_t expected,
                                           std::chrono::milliseconds wait, const char* operation = nullptr) {
  const std::string id = uniqueMessageId();
  const auto deadline = std::chrono::steady_clock::now() + wait;
  for (;;) {
    natsMsg* raw = nullptr;
    if (natsStatus s = natsMsg_Create(&raw, subject.c_str(), nullptr, bytes.data(), static_cast<int>(bytes.size()));
        s != NATS_OK)
      return tl::unexpected(natsError("message", s));
    MsgPtr msg(raw);
    natsMsgHeader_Set(msg.get(), header, std::to_string(expected).c_str());
    if (operation) natsMsgHeader_Set(msg.get(), "KV-Operation", operation);
    const auto left =
        std::chrono::duration_cast<std::chrono::milliseconds>(deadline - std::chrono::steady_clock::now());
    jsPubOptions po;
    jsPubOptions_Init(&po);
    po.MsgId = id.c_str();
    po.MaxWait = std::clamp(left, std::chrono::milliseconds{1}, kPublishAttemptWait).count();
    jsPubAck* rawAck = nullptr;
    jsErrCode jerr = static_cast<jsErrCode>(0);
    const natsStatus s = js_PublishMsg(&rawAck, js, msg.get(), &po, &jerr);
    PubAckPtr ack(rawAck);
    if (s == NATS_OK) return NatsLog::Appended{true, ack->Sequence};
    if (jerr == JSStreamWrongLastSequenceErr) return NatsLog::Appended{false, 0};
    // Refused by JetStream for another reason: sending it again changes
    // nothing. No responders (nats.c reports it as JetStream error 10076
    // too) is a stream without a leader for the moment: worth a retry.
    if ((jerr != 0 && s != NATS_NO_RESPONDERS) || std::chrono::steady_clock::now() + kPublishRetryPause >= deadline)
      return tl::unexpected(natsError("publish " + subject, s, jerr));
    std::this_thread::sleep_for(kPublishRetryPause);
  }
}

}  // namespace

Result<NatsLog::Appended> NatsLog::append(std::string_view bytes, std::uint64_t expectedLast) {
  return publishExpecting(h_->js.get(), h_->options.subject, bytes, kExpectedLastSeq, expectedLast,
                          h_->options.requestWait);
}

Result<NatsLog::Range> NatsLog::range() {
  jsStreamInfo* raw = nullptr;
  jsErrCode jerr = static_cast<jsErrCode>(0);
  const natsStatus s = js_GetStreamInfo(&raw, h_->js.get(), h_->options.stream.c_str(), nullptr, &jerr);
  StreamInfoPtr info(raw);
  if (s != NATS_OK) return tl::unexpected(natsError("stream " + h_->options.stream + " info", s, jerr));
  if (info->State.Msgs == 0) return Range{0, 0};
  return Range{info->State.FirstSeq, info->State.LastSeq};
}

Result<std::string> NatsLog::leaderOf(bool lease) {
  const std::string stream = lease ? "KV_" + h_->options.leaseBucket : h_->options.stream;
  jsStreamInfo* raw = nullptr;
  jsErrCode jerr = static_cast<jsErrCode>(0);
  const natsStatus s = js_GetStreamInfo(&raw, h_->js.get(), stream.c_str(), nullptr, &jerr);
  StreamInfoPtr info(raw);
  if (s != NATS_OK) return tl::unexpected(natsError("stream " + stream + " info", s, jerr));
  if (!info->Cluster || !info->Cluster->Leader) return std::string();
  return std::string(info->Cluster->Leader);
}

Result<std::optional<std::string>> NatsLog::read(std::uint64_t sequence) {
  natsMsg* raw = nullptr;
  jsErrCode jerr = static_cast<jsErrCode>(0);
  const natsStatus s = js_GetMsg(&raw, h_->js.get(), h_->options.stream.c_str(), sequence, nullptr, &jerr);
  MsgPtr msg(raw);
  if (s == NATS_NOT_FOUND || jerr == JSNoMessageFoundErr) return std::optional<std::string>{};
  if (s != NATS_OK) return tl::unexpected(natsError("read sequence " + std::to_string(sequence), s, jerr));
  return std::optional<std::string>(std::string(natsMsg_GetData(msg.get()),
                                                static_cast<std::size_t>(natsMsg_GetDataLength(msg.get()))));
}

Result<void> NatsLog::follow(std::uint64_t fromSequence, EntryHandler onEntry) {
  stopFollowing();
  auto state = std::make_shared<FollowState>();
  state->onEntry = std::move(onEntry);
  jsSubOptions so;
  jsSubOptions_Init(&so);
  so.Stream = h_->options.stream.c_str();
  so.Ordered = true;
  so.Config.DeliverPolicy = js_DeliverByStartSequence;
  so.Config.OptStartSeq = std::max<std::uint64_t>(fromSequence, 1);
  // Missed heartbeats are how the client notices a consumer lost with its
  // server (and makes a new one): every second, not nats.c's 5 s.
  so.Config.Heartbeat = std::chrono::nanoseconds(kFollowHeartbeat).count();
  natsSubscription* raw = nullptr;
  jsErrCode jerr = static_cast<jsErrCode>(0);
  const natsStatus s =
      js_Subscribe(&raw, h_->js.get(), h_->options.subject.c_str(), onMessage, state.get(), nullptr, &so, &jerr);
  if (s != NATS_OK) return tl::unexpected(natsError("follow " + h_->options.subject, s, jerr));
  h_->subscription.reset(raw);
  h_->follow = std::move(state);
  natsSubscription_SetOnCompleteCB(raw, onFollowComplete, h_->follow.get());
  return {};
}

void NatsLog::stopFollowing() { h_->stop(); }

namespace {

std::string leaseSubject(const NatsLogOptions& o) { return "$KV." + o.leaseBucket + "." + o.leaseKey; }
std::string leaseStream(const NatsLogOptions& o) { return "KV_" + o.leaseBucket; }

// The key's last message: its sequence, whether it is a value (not a delete
// or purge marker), and the value.
struct LastLease {
  std::uint64_t sequence = 0;
  bool value = false;
  std::string bytes;
};
Result<std::optional<LastLease>> lastLease(jsCtx* js, const NatsLogOptions& o) {
  natsMsg* raw = nullptr;
  jsErrCode jerr = static_cast<jsErrCode>(0);
  const natsStatus s =
      js_GetLastMsg(&raw, js, leaseStream(o).c_str(), leaseSubject(o).c_str(), nullptr, &jerr);
  MsgPtr msg(raw);
  if (s == NATS_NOT_FOUND || jerr == JSNoMessageFoundErr) return std::optional<LastLease>{};
  if (s != NATS_OK) return tl::unexpected(natsError("lease read", s, jerr));
  LastLease last;
  // A message read from the stream carries its sequence in natsMsg_GetSequence.
  last.sequence = natsMsg_GetSequence(msg.get());
  const char* op = nullptr;
  last.value = natsMsgHeader_Get(msg.get(), "KV-Operation", &op) != NATS_OK || op == nullptr;
  last.bytes.assign(natsMsg_GetData(msg.get()), static_cast<std::size_t>(natsMsg_GetDataLength(msg.get())));
  return std::optional<LastLease>(std::move(last));
}

}  // namespace

Result<std::optional<std::uint64_t>> NatsLog::takeLease(std::string_view value) {
  auto last = lastLease(h_->js.get(), h_->options);
  if (!last) return tl::unexpected(last.error());
  if (*last && (*last)->value) return std::optional<std::uint64_t>{};
  const std::uint64_t expected = *last ? (*last)->sequence : 0;
  auto put = publishExpecting(h_->js.get(), leaseSubject(h_->options), value, kExpectedLastSubjectSeq, expected,
                              h_->options.requestWait);
  if (!put) return tl::unexpected(put.error());
  if (!put->stored) return std::optional<std::uint64_t>{};
  return std::optional<std::uint64_t>(put->sequence);
}

Result<std::optional<std::uint64_t>> NatsLog::renewLease(std::string_view value, std::uint64_t revision) {
  auto put = publishExpecting(h_->js.get(), leaseSubject(h_->options), value, kExpectedLastSubjectSeq, revision,
                              h_->options.requestWait);
  if (!put) return tl::unexpected(put.error());
  if (!put->stored) return std::optional<std::uint64_t>{};
  return std::optional<std::uint64_t>(put->sequence);
}

Result<std::optional<std::uint64_t>> NatsLog::putArea(const std::string& key, std::string_view bytes,
                                                      std::uint64_t lastRevision) {
  if (auto ok = checkAreaKey(key); !ok) return tl::unexpected(ok.error());
  if (lastRevision == 0) {
    std::uint64_t revision = 0;
    if (natsStatus s = kvStore_Put(&revision, h_->areas.get(), key.c_str(), bytes.data(), static_cast<int>(bytes.size()));
        s != NATS_OK)
      return tl::unexpected(natsError("areas put " + key, s));
    return std::optional<std::uint64_t>(revision);
  }
  auto put = publishExpecting(h_->js.get(), "$KV." + h_->options.areasBucket + "." + key, bytes,
                              kExpectedLastSubjectSeq, lastRevision, h_->options.requestWait);
  if (!put) return tl::unexpected(put.error());
  if (!put->stored) return std::optional<std::uint64_t>{};
  return std::optional<std::uint64_t>(put->sequence);
}

Result<std::optional<NatsLog::Lease>> NatsLog::readLease() {
  auto last = lastLease(h_->js.get(), h_->options);
  if (!last) return tl::unexpected(last.error());
  if (!*last || !(*last)->value) return std::optional<Lease>{};
  return std::optional<Lease>(Lease{std::move((*last)->bytes), (*last)->sequence});
}

Result<void> NatsLog::releaseLease(std::uint64_t revision) {
  auto del = publishExpecting(h_->js.get(), leaseSubject(h_->options), "", kExpectedLastSubjectSeq, revision,
                              h_->options.requestWait, "DEL");
  if (!del) return tl::unexpected(del.error());
  return {};
}

namespace {

// A KV key holds only [-/_=.a-zA-Z0-9] and neither starts nor ends with a
// dot; ids hold '@' and ':' (skyshell-weatherd@host:pid).
std::string memberKey(std::string_view id) {
  std::string key;
  for (char c : id) {
    const bool ok = (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '-' ||
                    c == '_' || c == '=' || c == '/';
    key += ok ? c : '_';
  }
  return key.empty() ? "_" : key;
}

}  // namespace

Result<void> NatsLog::putMember(std::string_view id, std::string_view value) {
  std::uint64_t revision = 0;
  const std::string key = memberKey(id);
  if (natsStatus s = kvStore_Put(&revision, h_->registry.get(), key.c_str(), value.data(), static_cast<int>(value.size()));
      s != NATS_OK)
    return tl::unexpected(natsError("registry put " + key, s));
  return {};
}

Result<std::vector<std::string>> NatsLog::members(std::size_t max) {
  kvKeysList keys{};
  natsStatus s = kvStore_Keys(&keys, h_->registry.get(), nullptr);
  if (s == NATS_NOT_FOUND) return std::vector<std::string>{};  // no key yet
  if (s != NATS_OK) return tl::unexpected(natsError("registry keys", s));
  std::vector<std::string> values;
  for (int i = 0; i < keys.Count && values.size() < max; ++i) {
    kvEntry* raw = nullptr;
    if (kvStore_Get(&raw, h_->registry.get(), keys.Keys[i]) != NATS_OK) continue;  // expired meanwhile
    const Owned<kvEntry, kvEntry_Destroy> entry(raw);
    const auto* data = static_cast<const char*>(kvEntry_Value(entry.get()));
    if (data) values.emplace_back(data, static_cast<std::size_t>(kvEntry_ValueLen(entry.get())));
  }
  kvKeysList_Destroy(&keys);
  return values;
}

}  // namespace sky::server
