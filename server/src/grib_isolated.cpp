// GRIB2 decoded in child processes (grib_isolated.hpp). The pipe carries
// records in this machine's byte order (both ends are this build):
//   'F' u32 n, n bytes of JSON (the field's GribMeta), u64 count, count f32
//   'S' u32 n, n bytes of JSON {message, field, reason}
//   'N' u64 field                  (a field finished, kept or not)
//   'E' u32 n, n bytes of JSON {code, detail}   (a fatal error; the end)
#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <spawn.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <cmath>
#include <cstring>
#include <fstream>
#include <limits>
#include <nlohmann/json.hpp>
#include <vector>

#include "sky/server/forecast.hpp"
#include "sky/server/grib_isolated.hpp"

extern char** environ;

namespace sky::server {

namespace {

// Bytes of one record's JSON: a field's metadata is a few hundred (names
// are read into 256-byte buffers), a skip's reason is cut to kMaxReason.
constexpr std::uint32_t kMaxRecordJson = 4 * 1024;
constexpr std::size_t kMaxReason = 300;
// What a decoder may spend on one file: CPU seconds (its own limit, so a
// decoder looping in ecCodes ends even if the parent is gone).
constexpr rlim_t kDecoderCpu_s = 300;

using json = nlohmann::json;

json metaJson(const GribMeta& m) {
  const GribGrid& g = m.grid;
  return {{"message", m.message},
          {"field", m.field},
          {"shortName", m.shortName},
          {"typeOfLevel", m.typeOfLevel},
          {"units", m.units},
          {"discipline", m.discipline},
          {"category", m.category},
          {"number", m.number},
          {"levelType", m.levelType},
          {"level", std::isnan(m.level) ? json(nullptr) : json(m.level)},
          {"reference_unix", m.reference_unix},
          {"valid_unix", m.valid_unix},
          {"grid",
           {{"lambert", g.projection == GribGrid::Projection::Lambert},
            {"ni", g.ni},
            {"nj", g.nj},
            {"iNegative", g.iNegative},
            {"jPositive", g.jPositive},
            {"jConsecutive", g.jConsecutive},
            {"lat1", g.lat1_deg},
            {"lon1", g.lon1_deg},
            {"lat2", g.lat2_deg},
            {"lon2", g.lon2_deg},
            {"lov", g.lov_deg},
            {"lad", g.lad_deg},
            {"latin1", g.latin1_deg},
            {"latin2", g.latin2_deg},
            {"dx", g.dx_m},
            {"dy", g.dy_m},
            {"radius", g.radius_m},
            {"uvRelativeToGrid", g.uvRelativeToGrid}}}};
}

Result<GribMeta> metaFromJson(const json& j) {
  try {
    GribMeta m;
    m.message = j.at("message").get<std::size_t>();
    m.field = j.at("field").get<std::size_t>();
    m.shortName = j.at("shortName").get<std::string>();
    m.typeOfLevel = j.at("typeOfLevel").get<std::string>();
    m.units = j.at("units").get<std::string>();
    m.discipline = j.at("discipline").get<long>();
    m.category = j.at("category").get<long>();
    m.number = j.at("number").get<long>();
    m.levelType = j.at("levelType").get<long>();
    m.level = j.at("level").is_null() ? std::numeric_limits<double>::quiet_NaN() : j.at("level").get<double>();
    m.reference_unix = j.at("reference_unix").get<std::int64_t>();
    m.valid_unix = j.at("valid_unix").get<std::int64_t>();
    const json& g = j.at("grid");
    GribGrid& grid = m.grid;
    grid.projection = g.at("lambert").get<bool>() ? GribGrid::Projection::Lambert : GribGrid::Projection::LatLon;
    grid.ni = g.at("ni").get<int>();
    grid.nj = g.at("nj").get<int>();
    grid.iNegative = g.at("iNegative").get<bool>();
    grid.jPositive = g.at("jPositive").get<bool>();
    grid.jConsecutive = g.at("jConsecutive").get<bool>();
    grid.lat1_deg = g.at("lat1").get<double>();
    grid.lon1_deg = g.at("lon1").get<double>();
    grid.lat2_deg = g.at("lat2").get<double>();
    grid.lon2_deg = g.at("lon2").get<double>();
    grid.lov_deg = g.at("lov").get<double>();
    grid.lad_deg = g.at("lad").get<double>();
    grid.latin1_deg = g.at("latin1").get<double>();
    grid.latin2_deg = g.at("latin2").get<double>();
    grid.dx_m = g.at("dx").get<double>();
    grid.dy_m = g.at("dy").get<double>();
    grid.radius_m = g.at("radius").get<double>();
    grid.uvRelativeToGrid = g.value("uvRelativeToGrid", false);
    if (auto v = validate(grid); !v) return tl::unexpected(v.error());
    return m;
  } catch (const json::exception& e) {
    return fail(ErrorCode::Malformed, std::string("decoder record: ") + e.what());
  }
}

class Writer {
 public:
  explicit Writer(int fd) : fd_(fd) {}
  bool put(const void* p, std::size_t n) {
    const auto* b = static_cast<const char*>(p);
    while (n > 0) {
      const ssize_t w = ::write(fd_, b, n);
      if (w < 0 && errno == EINTR) continue;
      if (w <= 0) return false;
      b += w;
      n -= static_cast<std::size_t>(w);
    }
    return true;
  }
  bool tagged(char tag, const json& j) {
    const std::string s = j.dump(-1, ' ', false, json::error_handler_t::replace);  // a cut reason stays valid
    const auto n = static_cast<std::uint32_t>(s.size());
    return put(&tag, 1) && put(&n, 4) && put(s.data(), s.size());
  }

 private:
  int fd_;
};

class Reader {
 public:
  explicit Reader(std::span<const std::byte> b) : b_(b) {}
  bool done() const { return at_ >= b_.size(); }
  template <class T>
  bool get(T& v) {
    if (b_.size() - at_ < sizeof(T)) return false;
    std::memcpy(&v, b_.data() + at_, sizeof(T));
    at_ += sizeof(T);
    return true;
  }
  std::optional<json> getJson() {
    std::uint32_t n = 0;
    if (!get(n) || n > kMaxRecordJson || b_.size() - at_ < n) return std::nullopt;
    const auto* p = reinterpret_cast<const char*>(b_.data() + at_);
    at_ += n;
    json j = json::parse(p, p + n, nullptr, false);
    if (j.is_discarded() || !j.is_object()) return std::nullopt;
    return j;
  }
  std::span<const std::byte> take(std::size_t n) {
    if (b_.size() - at_ < n) return {};
    auto s = b_.subspan(at_, n);
    at_ += n;
    return s;
  }

 private:
  std::span<const std::byte> b_;
  std::size_t at_ = 0;
};

Result<std::vector<std::byte>> readFile(const std::filesystem::path& path, std::string_view name, std::size_t maxBytes) {
  std::error_code ec;
  const auto size = std::filesystem::file_size(path, ec);
  if (ec) return fail(ErrorCode::Io, std::string(name) + ": " + ec.message());
  if (size > maxBytes)
    return fail(ErrorCode::TooLarge,
                std::string(name) + ": " + std::to_string(size) + " bytes, more than " + std::to_string(maxBytes));
  std::ifstream in(path, std::ios::binary);
  std::vector<std::byte> bytes(size);
  if (!in.read(reinterpret_cast<char*>(bytes.data()), static_cast<std::streamsize>(size)))
    return fail(ErrorCode::Io, std::string(name) + ": cannot read");
  return bytes;
}

GribWanted wantedBy(GribSelection s) {
  if (s == GribSelection::Forecast) return forecastWants;
  return [](const GribMeta&) { return true; };
}

// One decoder run: its output, and how it ended.
struct Run {
  std::vector<std::byte> out;
  bool exitedCleanly = false;
  std::string how;  // "killed by signal 11", "exit 1", "timed out"
  bool timedOut = false;
  bool stopped = false;  // GribDecoder::stop was asked: the decoder was killed
};

Run spawnDecoder(const GribDecoder& d, const std::filesystem::path& file, std::size_t index, GribSelection selection, std::chrono::steady_clock::time_point deadline, std::size_t maxOut) {
  Run run;
  int pipefd[2];
  if (::pipe2(pipefd, O_CLOEXEC) != 0) {
    run.how = std::string("pipe: ") + std::strerror(errno);
    return run;
  }
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_adddup2(&actions, pipefd[1], 3);
  posix_spawn_file_actions_addopen(&actions, 0, "/dev/null", O_RDONLY, 0);
  // What ecCodes or a sanitizer prints as it dies is not the server's log.
  posix_spawn_file_actions_addopen(&actions, 2, "/dev/null", O_WRONLY, 0);
  const std::string exe = d.executable.string(), path = file.string(), idx = std::to_string(index),
                    sel = selection == GribSelection::All ? "all" : "forecast";
  std::vector<char*> argv{const_cast<char*>(exe.c_str()), const_cast<char*>(path.c_str()),
                          const_cast<char*>(idx.c_str()), const_cast<char*>(sel.c_str()), nullptr};
  pid_t pid = 0;
  const int e = ::posix_spawn(&pid, exe.c_str(), &actions, nullptr, argv.data(), environ);
  posix_spawn_file_actions_destroy(&actions);
  ::close(pipefd[1]);
  if (e != 0) {
    ::close(pipefd[0]);
    run.how = "cannot start " + exe + ": " + std::strerror(e);
    return run;
  }
  std::byte buf[65536];
  {
    // Killed from the thread that asks to stop, so the read below ends at
    // once. The callback is gone (destroyed, waiting for a running one)
    // before waitpid reaps the child: until then its pid cannot be reused.
    const std::stop_callback killOnStop(d.stop, [pid] { ::kill(pid, SIGKILL); });
    for (;;) {
      const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(deadline - std::chrono::steady_clock::now());
      if (left.count() <= 0) {
        run.timedOut = true;
        break;
      }
      pollfd p{pipefd[0], POLLIN, 0};
      const int r = ::poll(&p, 1, static_cast<int>(std::min<long long>(left.count(), 1000)));
      if (r < 0 && errno == EINTR) continue;
      if (r <= 0) continue;
      const ssize_t n = ::read(pipefd[0], buf, sizeof buf);
      if (n < 0 && errno == EINTR) continue;
      if (n <= 0) break;
      if (run.out.size() + static_cast<std::size_t>(n) > maxOut) {
        run.how = "wrote more than " + std::to_string(maxOut) + " bytes";
        ::kill(pid, SIGKILL);
        break;
      }
      run.out.insert(run.out.end(), buf, buf + n);
    }
  }
  run.stopped = d.stop.stop_requested();
  ::close(pipefd[0]);
  if (run.timedOut) ::kill(pid, SIGKILL);
  int status = 0;
  while (::waitpid(pid, &status, 0) < 0 && errno == EINTR) {
  }
  if (run.timedOut) {
    run.how = "timed out";
  } else if (run.how.empty()) {
    if (WIFEXITED(status)) {
      run.exitedCleanly = WEXITSTATUS(status) == 0;
      run.how = "exit " + std::to_string(WEXITSTATUS(status));
    } else if (WIFSIGNALED(status)) {
      run.how = "killed by signal " + std::to_string(WTERMSIG(status));
    }
  }
  return run;
}

}  // namespace

std::filesystem::path defaultGribDecoder() {
  std::error_code ec;
  const auto self = std::filesystem::read_symlink("/proc/self/exe", ec);
  return (ec ? std::filesystem::path(".") : self.parent_path()) / "skyshell-grib-decode";
}

Result<DecoderOutput> parseDecoderOutput(std::span<const std::byte> bytes, const GribLimits& limits, std::size_t& kept,
                                         GribFile& into) {
  Reader r(bytes);
  DecoderOutput out;
  auto bad = [](const std::string& what) { return fail(ErrorCode::Malformed, "decoder output: " + what); };
  while (!r.done()) {
    char tag = 0;
    r.get(tag);
    if (tag == 'F') {
      auto j = r.getJson();
      if (!j) return bad("a field's metadata");
      auto meta = metaFromJson(*j);
      if (!meta) return bad(meta.error().detail);
      std::uint64_t n = 0;
      const std::size_t points = static_cast<std::size_t>(meta->grid.ni) * meta->grid.nj;
      if (!r.get(n) || n != points || n > limits.maxPointsPerMessage) return bad("a field's value count");
      if (kept + n > limits.maxValuesKept)
        return fail(ErrorCode::TooLarge, "the wanted fields hold more than " + std::to_string(limits.maxValuesKept) +
                                             " values");
      const auto raw = r.take(n * sizeof(float));
      if (raw.size() != n * sizeof(float)) return bad("a field's values cut short");
      GribField f{std::move(*meta), std::vector<float>(n)};
      std::memcpy(f.values.data(), raw.data(), raw.size());
      kept += n;
      into.fields.push_back(std::move(f));
    } else if (tag == 'S') {
      auto j = r.getJson();
      if (!j || !j->contains("reason") || !(*j)["reason"].is_string()) return bad("a skip record");
      into.skipped.push_back({j->value("message", std::size_t{0}), j->value("field", std::size_t{0}),
                              (*j)["reason"].get<std::string>().substr(0, kMaxReason)});
    } else if (tag == 'N') {
      std::uint64_t field = 0;
      if (!r.get(field)) return bad("a field's end");
      ++out.fieldsDone;
    } else if (tag == 'E') {
      auto j = r.getJson();
      if (!j) return bad("an error record");
      const int code = j->value("code", static_cast<int>(ErrorCode::Malformed));
      const bool known = code == static_cast<int>(ErrorCode::TooLarge) || code == static_cast<int>(ErrorCode::Io);
      out.error = Error{known ? static_cast<ErrorCode>(code) : ErrorCode::Malformed,
                        j->value("detail", std::string("decoder error")).substr(0, 1000)};
      break;
    } else {
      return bad("record tag " + std::to_string(static_cast<int>(static_cast<unsigned char>(tag))));
    }
  }
  return out;
}

Result<GribFile> readGribIsolated(const std::filesystem::path& file, std::string_view sourceName, GribSelection selection,
                                  const GribDecoder& decoder, const GribLimits& limits) {
  const std::string name(sourceName);
  auto bytes = readFile(file, name, decoder.maxFileBytes);
  if (!bytes) return tl::unexpected(bytes.error());
  // The split is pure code: done here, it says where each field is, so a
  // decoder that dies on one is followed by another from the next.
  auto split = splitGrib(*bytes, name, limits);
  if (!split) return tl::unexpected(split.error());
  GribFile result;
  result.messages = split->messages;
  result.fieldCount = split->fields.size();
  result.skipped = std::move(split->skipped);
  const auto deadline = std::chrono::steady_clock::now() + decoder.timeout;
  // A decoder writes no more than the values allowed plus a record per field.
  const std::size_t maxOut = limits.maxValuesKept * sizeof(float) + (split->fields.size() + 1) * (kMaxRecordJson + 16);
  std::size_t index = 0, kept = 0, restarts = 0;
  const auto stopped = [&] { return fail(ErrorCode::Io, name + ": decoding stopped (the server is closing)"); };
  while (index < split->fields.size()) {
    if (decoder.stop.stop_requested()) return stopped();
    Run run = spawnDecoder(decoder, file, index, selection, deadline, maxOut);
    if (run.stopped) return stopped();
    auto out = parseDecoderOutput(run.out, limits, kept, result);
    if (!out) return fail(out.error().code, name + ": " + out.error().detail);
    if (out->error) return fail(out->error->code, name + ": " + out->error->detail);
    index += out->fieldsDone;
    if (run.timedOut)
      return fail(ErrorCode::Timeout, name + ": decoding took longer than " +
                                          std::to_string(decoder.timeout.count()) + " ms");
    if (index >= split->fields.size()) break;
    if (run.how.rfind("cannot start", 0) == 0) return fail(ErrorCode::Io, name + ": " + run.how);
    if (run.exitedCleanly) return fail(ErrorCode::Malformed, name + ": the decoder stopped early");
    // The decoder died on field `index`: skip it, go on after it.
    const GribFieldSpan& f = split->fields[index];
    result.skipped.push_back({f.message, f.field, "the decoder died on it (" + run.how + ")"});
    ++index;
    if (++restarts > decoder.maxRestarts)
      return fail(ErrorCode::Malformed, name + ": the decoder died on more than " +
                                            std::to_string(decoder.maxRestarts) + " fields");
  }
  std::sort(result.skipped.begin(), result.skipped.end(), [](const GribSkip& a, const GribSkip& b) {
    return std::tie(a.message, a.field) < std::tie(b.message, b.field);
  });
  return result;
}

int runGribDecoder(const std::filesystem::path& file, std::size_t firstFieldIndex, GribSelection selection, int fd) {
  // A decoder that loops in ecCodes ends by itself.
  rlimit cpu{kDecoderCpu_s, kDecoderCpu_s};
  ::setrlimit(RLIMIT_CPU, &cpu);
  Writer w(fd);
  auto fatal = [&](const Error& e) {
    return w.tagged('E', {{"code", static_cast<int>(e.code)}, {"detail", e.detail}}) ? 1 : 2;
  };
  auto bytes = readFile(file, file.string(), GribDecoder{}.maxFileBytes);
  const GribLimits limits;
  if (!bytes) return fatal(bytes.error());
  auto split = splitGrib(*bytes, file.string(), limits);
  if (!split) return fatal(split.error());
  const GribWanted wanted = wantedBy(selection);
  std::size_t kept = 0;
  for (std::size_t k = firstFieldIndex; k < split->fields.size(); ++k) {
    const GribFieldSpan& span = split->fields[k];
    auto r = decodeGribField(*bytes, span, wanted, limits, kept);
    bool ok = true;
    if (!r && r.error().code == ErrorCode::TooLarge) return fatal(r.error());
    if (!r) {
      ok = w.tagged('S', {{"message", span.message}, {"field", span.field},
                          {"reason", r.error().detail.substr(0, kMaxReason)}});
    } else if (*r) {
      const GribField& f = **r;
      const std::string s = metaJson(f.meta).dump(-1, ' ', false, json::error_handler_t::replace);
      const auto len = static_cast<std::uint32_t>(s.size());
      const std::uint64_t count = f.values.size();
      ok = w.put("F", 1) && w.put(&len, 4) && w.put(s.data(), s.size()) && w.put(&count, 8) &&
           w.put(f.values.data(), f.values.size() * sizeof(float));
    }
    const std::uint64_t field = span.field;
    if (!ok || !w.put("N", 1) || !w.put(&field, 8)) return 2;  // the parent is gone
  }
  return 0;
}

}  // namespace sky::server
