// What the weather stream benchmarks share (weatherd_bench.cpp,
// weatherd_relay_bench.cpp): subscribers on loopback that time each change's
// delivery by a marker (layer 1's or 9's base_m = kMarkerBase + the change's
// index), a thread's CPU time, percentiles.
#pragma once

#include <pthread.h>
#include <time.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <chrono>
#include <memory>
#include <mutex>
#include <optional>
#include <vector>

#include <utility>  // before asio: Boost 1.74 asio uses std::exchange without including it
#include <boost/asio.hpp>

#include "sky/stream/framing.hpp"
#include "sky/stream/messages.hpp"

namespace sky::bench {

namespace asio = boost::asio;
using asio::ip::tcp;
using Clock = std::chrono::steady_clock;

inline double threadCpu_s(pthread_t thread) {
  clockid_t id;
  if (pthread_getcpuclockid(thread, &id) != 0) return 0;
  timespec ts{};
  clock_gettime(id, &ts);
  return double(ts.tv_sec) + double(ts.tv_nsec) * 1e-9;
}

inline double percentile(std::vector<double> v, double p) {
  if (v.empty()) return 0;
  std::sort(v.begin(), v.end());
  const std::size_t i = std::min(v.size() - 1, static_cast<std::size_t>(p / 100.0 * double(v.size() - 1) + 0.5));
  return v[i];
}

// Submit times by marker (layer 1's base_m = kMarkerBase + index).
inline constexpr double kMarkerBase = 1000;

struct Shared {
  std::mutex mutex;
  std::vector<Clock::time_point> submitted;  // by change index
  std::vector<double> latencies_ms;
  std::uint64_t deliveries = 0, coalesced = 0, snapshots = 0;
};

class Subscriber : public std::enable_shared_from_this<Subscriber> {
 public:
  Subscriber(asio::io_context& io, Shared& shared) : socket_(io), shared_(shared) {}

  void start(std::uint16_t port, const sky::stream::Subscribe& subscribe) {
    socket_.connect(tcp::endpoint(asio::ip::make_address("127.0.0.1"), port));
    socket_.set_option(tcp::no_delay(true));
    const auto frame = sky::stream::encodeFrame(sky::stream::encodeMessage(subscribe));
    asio::write(socket_, asio::buffer(frame));
    read();
  }
  bool ready() const { return ready_.load(); }
  void close() {
    boost::system::error_code ec;
    socket_.close(ec);
  }

 private:
  void read() {
    socket_.async_read_some(asio::buffer(buffer_), [self = shared_from_this()](boost::system::error_code ec,
                                                                               std::size_t n) {
      if (ec) return;
      self->decoder_.append(std::span<const std::uint8_t>(self->buffer_.data(), n));
      for (;;) {
        auto payload = self->decoder_.next();
        if (!payload || !*payload) break;
        auto message = sky::stream::decodeMessage(**payload);
        if (message) self->onMessage(*message);
      }
      self->read();
    });
  }

  void onMessage(const sky::stream::Message& m) {
    // The layers this frame brings: a snapshot's table, or a delta's changed ones.
    const std::vector<sky::weather::CloudLayer>* layers = nullptr;
    if (const auto* s = std::get_if<sky::weather::WeatherSnapshot>(&m)) layers = &s->layers;
    if (const auto* d = std::get_if<sky::weather::WeatherDelta>(&m)) layers = &d->layers;
    if (!layers) return;
    ready_ = true;
    const auto now = Clock::now();
    std::lock_guard lock(shared_.mutex);
    ++shared_.snapshots;
    for (const auto& l : *layers) {
      if ((l.id != 1 && l.id != 9) || l.base_m < kMarkerBase) continue;
      const auto index = static_cast<std::size_t>(l.base_m - kMarkerBase + 0.5);
      if (index >= shared_.submitted.size() || shared_.submitted[index] == Clock::time_point{} ||
          (lastIndex_ && index <= *lastIndex_))
        continue;
      shared_.latencies_ms.push_back(std::chrono::duration<double, std::milli>(now - shared_.submitted[index]).count());
      ++shared_.deliveries;
      if (lastIndex_) shared_.coalesced += index - *lastIndex_ - 1;
      lastIndex_ = index;
    }
  }

  tcp::socket socket_;
  Shared& shared_;
  std::array<std::uint8_t, 256 * 1024> buffer_{};
  sky::stream::FrameDecoder decoder_;
  std::atomic<bool> ready_{false};
  std::optional<std::size_t> lastIndex_;
};

}  // namespace sky::bench
