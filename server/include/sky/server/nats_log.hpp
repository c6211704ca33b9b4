// The weather's change log and leader lease on a NATS cluster (JetStream):
// one stream with one subject, replicated on three servers when the cluster
// has them, appended to only at an expected last sequence (so a writer that
// missed an entry is refused), read back by sequence or followed in order;
// one key in a KV bucket whose values expire, the lease of the leading
// server; and a second such bucket, the registry of the cluster's members. A thin owner of the nats.c handles (src/nats_handles.hpp): no
// policy here, that is nats_weather.hpp's.
#pragma once

#include <chrono>
#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "sky/core/result.hpp"

namespace sky::server {

struct NatsLogOptions {
  std::vector<std::string> urls;  // nats://host:port, one or more servers of the cluster
  std::string stream = "SKY_WEATHER";
  std::string subject = "sky.weather.log";
  std::string leaseBucket = "sky_weather_leader";
  std::string leaseKey = "leader";
  std::chrono::milliseconds leaseTtl{3000};  // a lease not renewed for this long is gone
  // The cluster's registry (cluster_registry.hpp): a member not put again
  // for this long is gone from it. Set by the process that makes the bucket.
  std::string registryBucket = "sky_weather_members";
  std::chrono::milliseconds registryTtl{5000};
  // A loaded forecast's GRIB files (nats_files.cpp), by the key the state
  // names each by: chunks of a stream of their own, one message per subject.
  std::string filesStream = "SKY_WEATHER_FILES";
  std::string filesSubject = "sky.weather.file";
  // The weather cut by S2 cell for the relays (state_cells.hpp,
  // nats_cells.hpp): a KV bucket of the newest value of each cell and of the
  // global part; a relay watches the keys of its renderers' areas.
  std::string areasBucket = "sky_weather_areas";
  // Deliver every subscription's messages from nats.c's shared pool of
  // threads instead of one thread per subscription: a relay watches a
  // hundred or more keys.
  bool sharedDelivery = false;
  int replicas = 3;                           // the stream's and the bucket's; 1 on a single server
  std::uint64_t maxEntries = 10000;           // the stream keeps the newest this many
  // How long a publish, a read or a lease operation waits for its answer.
  std::chrono::milliseconds requestWait{5000};
  // How long connect() retries while JetStream is not ready (a cluster that
  // has just started elects its meta leader first).
  std::chrono::milliseconds readyWait{30000};
};

// A file's manifest on the files stream, written after its chunks: the
// file's size and the size of every chunk but the last.
struct NatsFileManifest {
  std::uint64_t bytes = 0;
  std::uint64_t chunkBytes = 0;
  std::uint64_t chunks() const { return bytes == 0 ? 0 : (bytes + chunkBytes - 1) / chunkBytes; }
};
inline constexpr std::uint64_t kMaxNatsFileChunk_bytes = std::uint64_t{1} << 20;  // NATS's default max payload
std::string encodeFileManifest(const NatsFileManifest& m);
// "<bytes> <chunk bytes>" in decimal; Malformed for anything else or a
// chunk size outside [1, kMaxNatsFileChunk_bytes], TooLarge past maxBytes.
Result<NatsFileManifest> parseFileManifest(std::string_view text, std::uint64_t maxBytes);

class NatsLog {
 public:
  // Connects (reconnecting for ever afterwards), and makes the stream and the
  // lease bucket when they are missing. With replicas 3 on a server that is
  // not clustered the stream is made with 1 (`replicas()` says which).
  // Errors: Io (no server answers), Timeout (JetStream not ready in readyWait).
  static Result<std::unique_ptr<NatsLog>> connect(const NatsLogOptions& options);
  ~NatsLog();
  NatsLog(const NatsLog&) = delete;
  NatsLog& operator=(const NatsLog&) = delete;

  int replicas() const;
  const NatsLogOptions& options() const;
  // The most bytes a message this log publishes may carry: the max_payload
  // the NATS server it is connected to announces (1 MiB by default; a
  // deployment may set less), less room for the message's headers, and at
  // most kMaxNatsFileChunk_bytes. Entries over it go to the files stream,
  // and files are chunked to it.
  std::size_t messageLimit() const;

  struct Appended {
    bool stored = false;        // false: the stream's last sequence was not expectedLast (fenced)
    std::uint64_t sequence = 0;  // the entry's stream sequence when stored
  };
  // Appends once JetStream has stored it on a majority of the stream's
  // replicas, if the stream's last sequence is expectedLast (0: empty).
  // Errors: Timeout (no acknowledgement in requestWait: it may or may not
  // be stored), Io.
  Result<Appended> append(std::string_view bytes, std::uint64_t expectedLast);
  // The stream's first and last sequence (0 and 0 when empty).
  struct Range {
    std::uint64_t first = 0, last = 0;
  };
  Result<Range> range();
  // The name of the NATS server that leads a stream's replicas ("" when none
  // does, e.g. during an election): this log's stream, or the lease's
  // bucket with `lease` true.
  Result<std::string> leaderOf(bool lease = false);
  // The entry at a sequence (nullopt: none there, e.g. discarded).
  Result<std::optional<std::string>> read(std::uint64_t sequence);

  // Calls `onEntry(sequence, bytes)` for every entry from `fromSequence` on,
  // in order, on a thread of the NATS client (an ordered consumer: gaps and
  // lost servers are recovered by the client). Replaces an earlier follow.
  using EntryHandler = std::function<void(std::uint64_t sequence, std::string_view bytes)>;
  Result<void> follow(std::uint64_t fromSequence, EntryHandler onEntry);
  void stopFollowing();

  // The lease: create-if-absent (nullopt when held by another), renew at the
  // revision this holder last wrote (nullopt when that is no longer the
  // key's revision: the lease was lost), read, and release (only the
  // revision this holder wrote: a lease another took since is left alone).
  Result<std::optional<std::uint64_t>> takeLease(std::string_view value);
  Result<std::optional<std::uint64_t>> renewLease(std::string_view value, std::uint64_t revision);
  struct Lease {
    std::string value;
    std::uint64_t revision = 0;
  };
  Result<std::optional<Lease>> readLease();
  Result<void> releaseLease(std::uint64_t revision);

  // The registry: puts a member's record under a key made from its id
  // (characters a KV key does not allow become '_'), and reads every
  // record there (at most `max`; keys that expire meanwhile are left out).
  // Errors: Io, Timeout.
  Result<void> putMember(std::string_view id, std::string_view value);
  Result<std::vector<std::string>> members(std::size_t max);

  // A forecast's files (nats_files.cpp), each under its key (a key holds
  // only [0-9a-z-], at most 64 of them: InvalidArgument otherwise).
  // putFile stores the bytes in chunks, then their manifest, so a reader
  // that finds the manifest finds every chunk; putting a key again
  // replaces it. getFile reads a file back: Io when its manifest is not
  // there, TooLarge past maxBytes, Malformed when the manifest or a chunk
  // does not add up. dropFile purges a key's messages (a file no state
  // names any more). Errors: Io, Timeout.
  Result<void> putFile(std::string_view key, std::span<const std::byte> bytes);
  Result<std::vector<std::byte>> getFile(std::string_view key, std::size_t maxBytes);
  Result<void> dropFile(std::string_view key);

  // The areas bucket (nats_areas.cpp): putArea stores a key's newest value
  // if the key's revision is still `lastRevision` (the one this writer put
  // last), or whatever it is with lastRevision 0, and returns the new
  // revision (nullopt: another writer's put came between, nothing stored);
  // readArea reads the newest value (nullopt: none). watchArea
  // subscribes to the key's puts and deletes (core NATS, on the KV's subject:
  // no consumer per key), calling the handler set by onArea with the key and
  // the value (empty: deleted) on a NATS client thread; a watch misses what
  // is put while the connection is down, so a watcher reads back what it
  // holds now and then. Errors: Io, Timeout; InvalidArgument for a key that
  // is not [-_=.a-zA-Z0-9].
  Result<std::optional<std::uint64_t>> putArea(const std::string& key, std::string_view bytes,
                                               std::uint64_t lastRevision);
  Result<std::optional<std::string>> readArea(const std::string& key);
  using AreaHandler = std::function<void(const std::string& key, std::string bytes)>;
  void onArea(AreaHandler handler);  // before the first watch; null: stop calling
  Result<void> watchArea(const std::string& key);
  void unwatchArea(const std::string& key);

 private:
  struct Handles;
  explicit NatsLog(std::unique_ptr<Handles> handles);
  std::unique_ptr<Handles> h_;
};

}  // namespace sky::server
