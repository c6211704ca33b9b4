// A path-traced frame's sums (sky/render/path_tracer.hpp): the image they
// make, and their file. The file is read back from an output folder to
// resume a run, so its decoder takes any bytes: it checks every size
// against the file's length before it allocates (tests/fuzz's
// fuzz_path_trace_state).
#include "sky/render/path_tracer.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>

namespace sky::render {

namespace {

constexpr char kStateMagic[8] = {'S', 'K', 'Y', 'P', 'T', 'S', '1', '\n'};
constexpr std::uint32_t kMaxStateEdge = 8192;
constexpr std::uint64_t kMaxKeyLength = 4096;

template <class T>
void put(std::vector<std::uint8_t>& out, const T* p, std::size_t count) {
  const std::size_t at = out.size(), n = count * sizeof(T);
  out.resize(at + n);
  if (n > 0) std::memcpy(out.data() + at, static_cast<const void*>(p), n);
}

class Reader {
 public:
  explicit Reader(std::span<const std::uint8_t> bytes) : bytes_(bytes) {}
  template <class T>
  bool get(T* p, std::size_t count) {
    const std::size_t n = count * sizeof(T);
    if (n > bytes_.size() - at_) return false;
    std::memcpy(static_cast<void*>(p), bytes_.data() + at_, n);
    at_ += n;
    return true;
  }
  std::size_t left() const { return bytes_.size() - at_; }

 private:
  std::span<const std::uint8_t> bytes_;
  std::size_t at_ = 0;
};

}  // namespace

Image PathTraceState::mean() const {
  Image image;
  image.width = width;
  image.height = height;
  const std::size_t n = std::size_t(width) * height;
  image.rgba.assign(n * 4, 0.0f);
  image.cloudDepth_m.assign(n, 0.0f);
  if (samples == 0) return image;
  for (std::size_t i = 0; i < n; ++i) {
    for (int c = 0; c < 4; ++c) image.rgba[i * 4 + c] = float(sum[i * 4 + c] / double(samples));
    if (depthCount[i] > 0) image.cloudDepth_m[i] = float(depthSum[i] / depthCount[i]);
  }
  return image;
}

std::vector<float> PathTraceState::standardError() const {
  const std::size_t n = std::size_t(width) * height;
  std::vector<float> error(n, 0.0f);
  if (samples < 2) return error;
  const double k = double(samples);
  for (std::size_t i = 0; i < n; ++i) {
    double variance = 0.0;
    for (int c = 0; c < 3; ++c) {
      const double m = sum[i * 4 + c] / k;
      variance += std::max(0.0, sumSquares[i * 3 + c] / k - m * m);
    }
    // The channels move together (a path's light is nearly grey), so the
    // rgb mean's variance is about their mean variance.
    error[i] = float(std::sqrt(variance / 3.0 / (k - 1.0)));
  }
  return error;
}

std::vector<std::uint8_t> PathTraceState::encode() const {
  std::vector<std::uint8_t> out;
  const std::uint64_t keyLength = key.size();
  put(out, kStateMagic, sizeof kStateMagic);
  put(out, &width, 1);
  put(out, &height, 1);
  put(out, &samples, 1);
  put(out, &violations, 1);
  put(out, &lookups, 1);
  put(out, &keyLength, 1);
  put(out, key.data(), key.size());
  put(out, sum.data(), sum.size());
  put(out, sumSquares.data(), sumSquares.size());
  put(out, depthSum.data(), depthSum.size());
  put(out, depthCount.data(), depthCount.size());
  return out;
}

Result<PathTraceState> PathTraceState::decode(std::span<const std::uint8_t> bytes, const std::string& key) {
  Reader in(bytes);
  char magic[sizeof kStateMagic];
  PathTraceState s;
  std::uint64_t keyLength = 0;
  if (!in.get(magic, sizeof magic) || std::memcmp(magic, kStateMagic, sizeof magic) != 0)
    return fail(ErrorCode::InvalidArgument, "not a path tracer's state");
  if (!in.get(&s.width, 1) || !in.get(&s.height, 1) || !in.get(&s.samples, 1) || !in.get(&s.violations, 1) ||
      !in.get(&s.lookups, 1) || !in.get(&keyLength, 1))
    return fail(ErrorCode::InvalidArgument, "truncated header");
  if (s.width == 0 || s.height == 0 || s.width > kMaxStateEdge || s.height > kMaxStateEdge)
    return fail(ErrorCode::InvalidArgument, "image size " + std::to_string(s.width) + "x" +
                                                std::to_string(s.height) + " out of range");
  if (keyLength > kMaxKeyLength || keyLength > in.left()) return fail(ErrorCode::InvalidArgument, "bad key length");
  s.key.resize(keyLength);
  in.get(s.key.data(), keyLength);
  if (s.key != key)
    return fail(ErrorCode::InvalidArgument, "holds samples of '" + s.key + "', not of '" + key + "'");
  const std::size_t n = std::size_t(s.width) * s.height;
  const std::size_t expected = n * (8 * sizeof(double) + sizeof(std::uint32_t));
  if (in.left() != expected)
    return fail(ErrorCode::InvalidArgument, "sums of " + std::to_string(in.left()) + " bytes where " +
                                                std::to_string(s.width) + "x" + std::to_string(s.height) +
                                                " takes " + std::to_string(expected));
  s.sum.resize(n * 4);
  s.sumSquares.resize(n * 3);
  s.depthSum.resize(n);
  s.depthCount.resize(n);
  in.get(s.sum.data(), s.sum.size());
  in.get(s.sumSquares.data(), s.sumSquares.size());
  in.get(s.depthSum.data(), s.depthSum.size());
  in.get(s.depthCount.data(), s.depthCount.size());
  return s;
}

Result<void> PathTraceState::save(const std::string& path) const {
  const std::string tmp = path + ".tmp";
  const std::vector<std::uint8_t> bytes = encode();
  {
    std::ofstream out(tmp, std::ios::binary | std::ios::trunc);
    out.write(reinterpret_cast<const char*>(bytes.data()), std::streamsize(bytes.size()));
    out.close();
    if (!out) return fail(ErrorCode::Io, "PathTraceState::save: cannot write " + tmp);
  }
  if (std::rename(tmp.c_str(), path.c_str()) != 0)
    return fail(ErrorCode::Io, "PathTraceState::save: cannot rename " + tmp + " to " + path);
  return {};
}

Result<PathTraceState> PathTraceState::load(const std::string& path, const std::string& key) {
  // The largest state a decoder accepts: refuse a bigger file before reading it.
  constexpr std::uintmax_t kMaxStateBytes = 4096 + kMaxKeyLength + std::uintmax_t(kMaxStateEdge) * kMaxStateEdge *
                                                                       (8 * sizeof(double) + sizeof(std::uint32_t));
  std::error_code ec;
  const std::uintmax_t size = std::filesystem::file_size(path, ec);
  if (ec) return fail(ErrorCode::Io, "PathTraceState::load: cannot read " + path + ": " + ec.message());
  if (size > kMaxStateBytes)
    return fail(ErrorCode::InvalidArgument, "PathTraceState::load: " + path + ": " + std::to_string(size) +
                                                " bytes, more than any state");
  std::ifstream in(path, std::ios::binary);
  if (!in) return fail(ErrorCode::Io, "PathTraceState::load: cannot read " + path);
  const std::vector<std::uint8_t> bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  auto s = decode(bytes, key);
  if (!s) return fail(s.error().code, "PathTraceState::load: " + path + ": " + s.error().detail);
  return s;
}

}  // namespace sky::render
