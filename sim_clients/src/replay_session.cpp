// A recorded flight flown as a CIGI host (see replay_session.hpp).
#include "sky/sim/replay_session.hpp"

#include <algorithm>
#include <charconv>
#include <cstdio>
#include <span>
#include <stdexcept>

#include <boost/asio/buffer.hpp>
#include <boost/asio/ip/address.hpp>

namespace sky::sim {

namespace asio = boost::asio;

asio::ip::udp::endpoint parseIgEndpoint(const std::string& text) {
  std::string address = text, port;
  if (!text.empty() && text.front() == '[') {
    const auto close = text.find("]:");
    if (close == std::string::npos) throw std::runtime_error("--ig '" + text + "': IPv6 is written [ADDR]:PORT");
    address = text.substr(1, close - 1);
    port = text.substr(close + 2);
  } else {
    const auto colon = text.rfind(':');
    if (colon == std::string::npos) throw std::runtime_error("--ig '" + text + "': not ADDR:PORT");
    address = text.substr(0, colon);
    port = text.substr(colon + 1);
  }
  boost::system::error_code ec;
  const auto a = asio::ip::make_address(address, ec);
  if (ec) throw std::runtime_error("--ig '" + text + "': '" + address + "' is not an IP address");
  unsigned value = 0;
  const auto [end, pec] = std::from_chars(port.data(), port.data() + port.size(), value);
  if (pec != std::errc() || end != port.data() + port.size() || value == 0 || value > 65535)
    throw std::runtime_error("--ig '" + text + "': the port is not in 1..65535");
  return {a, static_cast<unsigned short>(value)};
}

ReplaySession::ReplaySession(asio::io_context& io, ReplayOptions o, flight::Flight flight,
                             std::function<void()> onDone)
    : o_(std::move(o)), flight_(std::move(flight)), onDone_(std::move(onDone)), socket_(io), timer_(io),
      host_(HostOptions{o_.littleEndian ? cigi::ByteOrder::Little : cigi::ByteOrder::Big, 60, o_.aspect,
                        flight_.startUtc_s, o_.channels, o_.channelWidth_deg}) {
  if (o_.igs.empty()) {
    boost::system::error_code ec;
    const auto address = asio::ip::make_address(o_.host, ec);
    if (ec) throw std::runtime_error("IG address '" + o_.host + "': " + ec.message());
    targets_.push_back({address, static_cast<unsigned short>(o_.port)});
  }
  for (const auto& text : o_.igs) targets_.push_back(parseIgEndpoint(text));
  for (const auto& t : targets_)
    if (t.address().is_v6() != targets_.front().address().is_v6())
      throw std::runtime_error("--ig: IPv4 and IPv6 IGs mixed; one socket sends to all");
  socket_.open(targets_.front().protocol());
  socket_.bind({targets_.front().address(), 0});
  if (o_.conditionsRate_hz > 0) probe_.emplace(o_.conditionsRate_hz);
  if (!o_.conditionsCsv.empty()) {
    csv_.open(o_.conditionsCsv, std::ios::trunc);
    if (!csv_) throw std::runtime_error("cannot write conditions CSV " + o_.conditionsCsv);
    csv_ << ConditionsProbe::csvHeader() << '\n';
  }
  t0_ = flight_.fixes.front().time_s + o_.start_s;
  t1_ = o_.end_s >= 0 ? std::min(flight_.fixes.front().time_s + o_.end_s, flight_.fixes.back().time_s)
                      : flight_.fixes.back().time_s;
}

void ReplaySession::start() {
  wallStart_ = Clock::now();
  tick0_ = wallStart_;
  lastReport_ = wallStart_;
  receive();
  tick();
}

void ReplaySession::stop() {
  if (finished_) return;
  timer_.cancel();
  finish();
}

void ReplaySession::tick() {
  if (finished_) return;
  // Synchronous: sim time, one step per frame; else wall time.
  const double elapsed = o_.sync ? double(ticks_) / o_.rate_hz
                                 : std::chrono::duration<double>(Clock::now() - wallStart_).count();
  double t = t0_ + elapsed * o_.speed;
  const bool done = t >= t1_;
  if (done && o_.loop) {
    wallStart_ = Clock::now();
    t = t0_;
    if (o_.sync) ticks_ = 0;
  }
  if (done && !o_.loop) t = t1_;
  const auto pose = flight::sample(flight_, t);
  flightTime_s_ = t - flight_.fixes.front().time_s;
  if (tickHook_) tickHook_(flightTime_s_);
  const auto request = probe_ ? probe_->due(flightTime_s_, pose.position) : std::nullopt;
  const auto bytes = host_.nextFrame(pose, flightTime_s_, request);
  // The request (appended last) to the first IG only: one answer each.
  const std::size_t common = request ? bytes.size() - cigi::EnvironmentalConditionsRequest::kSize : bytes.size();
  for (std::size_t i = 0; i < targets_.size(); ++i) {
    boost::system::error_code ec;
    socket_.send_to(asio::buffer(bytes.data(), i == 0 ? bytes.size() : common), targets_[i], 0, ec);
    if (ec) {
      std::fprintf(stderr, "skyshell-%s: send to %s:%u failed: %s\n", o_.name.c_str(),
                   targets_[i].address().to_string().c_str(), unsigned(targets_[i].port()), ec.message().c_str());
      exitCode_ = 1;
      finish();
      return;
    }
  }
  report(t, done && !o_.loop);
  if (done && !o_.loop) {
    finish();
    return;
  }
  ++ticks_;
  if (o_.sync) {
    // The frame just sent is host frame framesSent() - 1; the next goes
    // when every IG has drawn it, or after the timeout.
    awaited_ = host_.framesSent() - 1;
    answered_.assign(targets_.size(), false);
    timer_.expires_after(std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(o_.syncTimeout_s)));
    timer_.async_wait([this](boost::system::error_code e) {
      if (e) return;
      ++syncTimeouts_;
      awaited_.reset();
      tick();
    });
    return;
  }
  // Absolute deadlines, so the rate does not drift.
  timer_.expires_at(tick0_ + std::chrono::duration_cast<Clock::duration>(
                                 std::chrono::duration<double>(double(ticks_) / o_.rate_hz)));
  timer_.async_wait([this](boost::system::error_code e) {
    if (!e) tick();
  });
}

void ReplaySession::report(double t, bool final) {
  const auto now = Clock::now();
  if (o_.quiet || (!final && now - lastReport_ < std::chrono::seconds(1))) return;
  lastReport_ = now;
  const double wall = std::chrono::duration<double>(now - tick0_).count();
  const double total = t1_ - t0_, done = t - t0_;
  const double left_s = o_.speed > 0 ? (total - done) / o_.speed : 0;
  std::printf("%s: flight time %.1f / %.1f s (%.0f%%, %.0f s left), %u frames sent (%.1f Hz), "
              "%llu Start of Frame received, IG %u frames behind%s\n",
              o_.name.c_str(), t - flight_.fixes.front().time_s, t1_ - flight_.fixes.front().time_s,
              total > 0 ? 100.0 * done / total : 100.0, left_s, host_.framesSent(),
              wall > 0 ? host_.framesSent() / wall : 0.0,
              static_cast<unsigned long long>(host_.startOfFramesReceived()), host_.igLagFrames(),
              final ? ", done" : "");
  if (o_.sync && final)
    std::printf("%s: synchronous: %llu host frames sent on after a %.1f s wait for Start of Frame\n", o_.name.c_str(),
                static_cast<unsigned long long>(syncTimeouts_), o_.syncTimeout_s);
  if (probe_ && lastConditions_ && lastConditions_->weather) {
    const auto& w = *lastConditions_->weather;
    std::printf("%s: conditions at %.0f m: wind %.1f m/s from %.0f deg, vertical %.1f m/s", o_.name.c_str(),
                lastConditions_->position.alt_m, double(w.horizontalWind_mps), double(w.windDirection_deg),
                double(w.verticalWind_mps));
    for (const auto& a : lastConditions_->aerosols)
      std::printf(", cloud layer %u %.3f g/m3", unsigned(static_cast<std::uint8_t>(a.layerId)),
                  double(a.concentration_gpm3));
    std::printf(" (%llu asked, %llu answered)\n", static_cast<unsigned long long>(probe_->asked()),
                static_cast<unsigned long long>(probe_->answered()));
  }
  std::fflush(stdout);
}

void ReplaySession::finish() {
  if (finished_) return;
  finished_ = true;
  boost::system::error_code ignored;
  socket_.close(ignored);
  if (csv_.is_open()) csv_.flush();
  if (onDone_) onDone_();
}

void ReplaySession::receive() {
  socket_.async_receive_from(asio::buffer(rx_), from_, [this](boost::system::error_code ec, std::size_t n) {
    if (ec) return;
    const bool sof = host_.onIgDatagram(std::span(rx_.data(), n));
    if (sof && probe_)
      for (auto& row : probe_->onIgPackets(host_.lastReplies(), flightTime_s_)) {
        if (csv_.is_open()) csv_ << ConditionsProbe::csvLine(row) << '\n';
        lastConditions_ = std::move(row);
      }
    if (sof && awaited_ && host_.lastStartOfFrameHostFrame() == awaited_) {
      for (std::size_t i = 0; i < targets_.size(); ++i)
        if (targets_[i] == from_) answered_[i] = true;
      if (std::all_of(answered_.begin(), answered_.end(), [](bool b) { return b; })) {
        awaited_.reset();
        timer_.cancel();
        asio::post(socket_.get_executor(), [this] { tick(); });
      }
    }
    receive();
  });
}

}  // namespace sky::sim
