// A loaded forecast's GRIB files on JetStream (see nats_log.hpp): the
// servers and relays of a cluster have no SQLite store to keep them in, so
// the leader puts each file in a stream of its own before it appends the
// change that names it, and every follower reads it back from there by
// its key to decode the forecast itself.
#include <charconv>
#include <cstring>

#include "nats_handles.hpp"

namespace sky::server {

namespace {

// Under NATS's default max payload (1 MiB) with room for the headers.
constexpr std::uint64_t kChunk_bytes = 256 * 1024;

bool validKey(std::string_view key) {
  if (key.empty() || key.size() > 64) return false;
  for (char c : key)
    if (!((c >= '0' && c <= '9') || (c >= 'a' && c <= 'z') || c == '-')) return false;
  return true;
}

std::string chunkSubject(const NatsLogOptions& o, std::string_view key, std::uint64_t k) {
  return o.filesSubject + "." + std::string(key) + "." + std::to_string(k);
}
std::string manifestSubject(const NatsLogOptions& o, std::string_view key) {
  return o.filesSubject + "." + std::string(key) + ".manifest";
}

Result<std::optional<std::string>> lastOn(jsCtx* js, const NatsLogOptions& o, const std::string& subject) {
  natsMsg* raw = nullptr;
  jsErrCode jerr = static_cast<jsErrCode>(0);
  const natsStatus s = js_GetLastMsg(&raw, js, o.filesStream.c_str(), subject.c_str(), nullptr, &jerr);
  MsgPtr msg(raw);
  if (s == NATS_NOT_FOUND || jerr == JSNoMessageFoundErr) return std::optional<std::string>{};
  if (s != NATS_OK) return tl::unexpected(natsError("read " + subject, s, jerr));
  return std::optional<std::string>(
      std::string(natsMsg_GetData(msg.get()), static_cast<std::size_t>(natsMsg_GetDataLength(msg.get()))));
}

Result<void> publish(jsCtx* js, const std::string& subject, const void* data, std::size_t size) {
  jsPubAck* raw = nullptr;
  jsErrCode jerr = static_cast<jsErrCode>(0);
  const natsStatus s = js_Publish(&raw, js, subject.c_str(), data, static_cast<int>(size), nullptr, &jerr);
  PubAckPtr ack(raw);
  if (s != NATS_OK) return tl::unexpected(natsError("publish " + subject, s, jerr));
  return {};
}

}  // namespace

std::string encodeFileManifest(const NatsFileManifest& m) {
  return std::to_string(m.bytes) + " " + std::to_string(m.chunkBytes);
}

Result<NatsFileManifest> parseFileManifest(std::string_view text, std::uint64_t maxBytes) {
  NatsFileManifest m;
  const char* p = text.data();
  const char* end = text.data() + text.size();
  auto number = [&](std::uint64_t& v) {
    if (p == end || *p < '0' || *p > '9') return false;
    if (*p == '0' && p + 1 != end && p[1] >= '0' && p[1] <= '9') return false;  // one spelling per number
    auto [next, ec] = std::from_chars(p, end, v);
    if (ec != std::errc()) return false;
    p = next;
    return true;
  };
  if (!number(m.bytes) || p == end || *p++ != ' ' || !number(m.chunkBytes) || p != end)
    return fail(ErrorCode::Malformed, "file manifest: not '<bytes> <chunk bytes>'");
  if (m.chunkBytes == 0 || m.chunkBytes > kMaxNatsFileChunk_bytes)
    return fail(ErrorCode::Malformed, "file manifest: chunk size " + std::to_string(m.chunkBytes) + " outside [1, " +
                                          std::to_string(kMaxNatsFileChunk_bytes) + "]");
  if (m.bytes > maxBytes)
    return fail(ErrorCode::TooLarge, "file manifest: " + std::to_string(m.bytes) + " bytes, more than the " +
                                         std::to_string(maxBytes) + " a file may have");
  return m;
}

Result<void> ensureFilesStream(jsCtx* js, const NatsLogOptions& options, int replicas) {
  jsStreamConfig config;
  jsStreamConfig_Init(&config);
  config.Name = options.filesStream.c_str();
  const std::string subjects = options.filesSubject + ".>";
  const char* list[] = {subjects.c_str()};
  config.Subjects = list;
  config.SubjectsLen = 1;
  config.Storage = js_FileStorage;
  config.Replicas = replicas;
  config.MaxMsgsPerSubject = 1;  // a key put again replaces its chunks
  // No byte limit: JetStream reserves a clustered stream's MaxBytes on
  // every replica's disk at creation. A file whose change was then refused
  // (fenced, or not acknowledged) stays unnamed until a purge
  // (docs/weather-server-scaling.md).
  auto made = ensureStream(js, config);
  if (!made) return tl::unexpected(made.error());
  return {};
}

Result<void> NatsLog::putFile(std::string_view key, std::span<const std::byte> bytes) {
  if (!validKey(key)) return fail(ErrorCode::InvalidArgument, "file key '" + std::string(key) + "'");
  // Chunks no larger than a message of the server connected to may be.
  const std::uint64_t chunk = std::min<std::uint64_t>(kChunk_bytes, messageLimit());
  const NatsFileManifest m{bytes.size(), chunk};
  for (std::uint64_t k = 0; k < m.chunks(); ++k) {
    const std::size_t begin = k * chunk;
    const std::size_t size = std::min<std::size_t>(chunk, bytes.size() - begin);
    if (auto ok = publish(h_->js.get(), chunkSubject(h_->options, key, k), bytes.data() + begin, size); !ok) return ok;
  }
  const std::string manifest = encodeFileManifest(m);
  return publish(h_->js.get(), manifestSubject(h_->options, key), manifest.data(), manifest.size());
}

Result<std::vector<std::byte>> NatsLog::getFile(std::string_view key, std::size_t maxBytes) {
  if (!validKey(key)) return fail(ErrorCode::InvalidArgument, "file key '" + std::string(key) + "'");
  auto text = lastOn(h_->js.get(), h_->options, manifestSubject(h_->options, key));
  if (!text) return tl::unexpected(text.error());
  if (!*text) return fail(ErrorCode::Io, "file " + std::string(key) + ": not in stream " + h_->options.filesStream);
  auto m = parseFileManifest(**text, maxBytes);
  if (!m) return fail(m.error().code, "file " + std::string(key) + ": " + m.error().detail);
  // Grown chunk by chunk, not reserved from the manifest: a forged manifest
  // of 13 bytes must not cost its claimed size in memory.
  std::vector<std::byte> bytes;
  for (std::uint64_t k = 0; k < m->chunks(); ++k) {
    auto chunk = lastOn(h_->js.get(), h_->options, chunkSubject(h_->options, key, k));
    if (!chunk) return tl::unexpected(chunk.error());
    const std::uint64_t expected = std::min(m->chunkBytes, m->bytes - bytes.size());
    if (!*chunk || (*chunk)->size() != expected)
      return fail(ErrorCode::Malformed, "file " + std::string(key) + ": chunk " + std::to_string(k) + " is " +
                                            (*chunk ? std::to_string((*chunk)->size()) + " bytes" : "missing") +
                                            ", the manifest says " + std::to_string(expected));
    const auto* data = reinterpret_cast<const std::byte*>((*chunk)->data());
    bytes.insert(bytes.end(), data, data + (*chunk)->size());
  }
  return bytes;
}

Result<void> NatsLog::dropFile(std::string_view key) {
  if (!validKey(key)) return fail(ErrorCode::InvalidArgument, "file key '" + std::string(key) + "'");
  const std::string subject = h_->options.filesSubject + "." + std::string(key) + ".>";
  jsOptions o;
  jsOptions_Init(&o);
  o.Stream.Purge.Subject = subject.c_str();
  jsErrCode jerr = static_cast<jsErrCode>(0);
  if (natsStatus s = js_PurgeStream(h_->js.get(), h_->options.filesStream.c_str(), &o, &jerr); s != NATS_OK)
    return tl::unexpected(natsError("purge " + subject, s, jerr));
  return {};
}

}  // namespace sky::server
