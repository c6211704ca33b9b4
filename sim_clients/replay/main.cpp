// skyshell-replay: replays a recorded flight as a CIGI 3.3 host over UDP, in
// real time (optionally scaled), so a renderer channel flies it as it would
// fly a simulator's ownship.
#include <array>
#include <chrono>
#include <functional>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <iostream>
#include <optional>
#include <stdexcept>
#include <string>

#include <CLI/CLI.hpp>
#include <boost/asio.hpp>

#include "sky/sim/cigi_host.hpp"
#include "sky/sim/conditions_probe.hpp"
#include "sky/sim/flight_file.hpp"

namespace asio = boost::asio;
using Clock = std::chrono::steady_clock;

namespace {

struct Options {
  std::string flightPath;
  std::string host = "127.0.0.1";
  unsigned port = 8004;
  double rate_hz = 60;
  double speed = 1;
  double start_s = 0;
  double end_s = -1;
  bool loop = false;
  bool littleEndian = false;
  bool quiet = false;
  double conditionsRate_hz = 1;  // 0: no Environmental Conditions Requests
  std::string conditionsCsv;
};

class Replay {
 public:
  Replay(asio::io_context& io, const Options& o, sky::flight::Flight flight,
         std::function<void()> onDone)
      : o_(o), flight_(std::move(flight)), onDone_(std::move(onDone)), socket_(io), timer_(io),
        host_(sky::sim::HostOptions{o.littleEndian ? sky::cigi::ByteOrder::Little : sky::cigi::ByteOrder::Big,
                                    60, 16.0 / 9.0, flight_.startUtc_s}) {
    socket_.open(asio::ip::udp::v4());
    socket_.bind({asio::ip::make_address(o.host), 0});
    target_ = {asio::ip::make_address(o.host), static_cast<unsigned short>(o.port)};
    if (o.conditionsRate_hz > 0) probe_.emplace(o.conditionsRate_hz);
    if (!o.conditionsCsv.empty()) {
      csv_.open(o.conditionsCsv, std::ios::trunc);
      if (!csv_) throw std::runtime_error("cannot write --conditions-csv " + o.conditionsCsv);
      csv_ << sky::sim::ConditionsProbe::csvHeader() << '\n';
    }
    t0_ = flight_.fixes.front().time_s + o.start_s;
    t1_ = o.end_s >= 0 ? std::min(flight_.fixes.front().time_s + o.end_s, flight_.fixes.back().time_s)
                       : flight_.fixes.back().time_s;
  }

  void start() {
    wallStart_ = Clock::now();
    lastReport_ = wallStart_;
    receive();
    tick();
  }

  int exitCode() const { return exitCode_; }

 private:
  void tick() {
    const double elapsed = std::chrono::duration<double>(Clock::now() - wallStart_).count();
    double t = t0_ + elapsed * o_.speed;
    const bool done = t >= t1_;
    if (done && o_.loop) {
      wallStart_ = Clock::now();
      t = t0_;
    }
    if (done && !o_.loop) t = t1_;
    const auto pose = sky::flight::sample(flight_, t);
    flightTime_s_ = t - flight_.fixes.front().time_s;
    const auto request = probe_ ? probe_->due(flightTime_s_, pose.position) : std::nullopt;
    const auto bytes = host_.nextFrame(pose, flightTime_s_, request);
    boost::system::error_code ec;
    socket_.send_to(asio::buffer(bytes), target_, 0, ec);
    if (ec) {
      std::fprintf(stderr, "skyshell-replay: send to %s:%u failed: %s\n", o_.host.c_str(), o_.port,
                   ec.message().c_str());
      exitCode_ = 1;
      finish();
      return;
    }
    report(t, done && !o_.loop);
    if (done && !o_.loop) {
      finish();
      return;
    }
    // Schedule on absolute times so the rate does not drift.
    ++ticks_;
    timer_.expires_at(wallTick0() + std::chrono::duration_cast<Clock::duration>(
                                        std::chrono::duration<double>(ticks_ / o_.rate_hz)));
    timer_.async_wait([this](boost::system::error_code e) {
      if (!e) tick();
    });
  }

  Clock::time_point wallTick0() {
    if (!tick0Set_) {
      tick0_ = wallStart_;
      tick0Set_ = true;
    }
    return tick0_;
  }

  void report(double t, bool final) {
    const auto now = Clock::now();
    if (o_.quiet || (!final && now - lastReport_ < std::chrono::seconds(1))) return;
    lastReport_ = now;
    const double wall = std::chrono::duration<double>(now - tick0_).count();
    const double total = t1_ - t0_, done = t - t0_;
    const double left_s = o_.speed > 0 ? (total - done) / o_.speed : 0;
    std::printf("replay: flight time %.1f / %.1f s (%.0f%%, %.0f s left), %u frames sent (%.1f Hz), "
                "%llu Start of Frame received, IG %u frames behind%s\n",
                t - flight_.fixes.front().time_s, t1_ - flight_.fixes.front().time_s,
                total > 0 ? 100.0 * done / total : 100.0, left_s, host_.framesSent(),
                wall > 0 ? host_.framesSent() / wall : 0.0,
                static_cast<unsigned long long>(host_.startOfFramesReceived()), host_.igLagFrames(),
                final ? ", done" : "");
    if (probe_ && lastConditions_ && lastConditions_->weather) {
      const auto& w = *lastConditions_->weather;
      std::printf("replay: conditions at %.0f m: wind %.1f m/s from %.0f deg, vertical %.1f m/s",
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

  void finish() {
    socket_.close();
    if (csv_.is_open()) csv_.flush();
    onDone_();
  }

  void receive() {
    socket_.async_receive_from(asio::buffer(rx_), from_, [this](boost::system::error_code ec, std::size_t n) {
      if (ec) return;
      if (host_.onIgDatagram(std::span(rx_.data(), n)) && probe_)
        for (auto& row : probe_->onIgPackets(host_.lastReplies(), flightTime_s_)) {
          if (csv_.is_open()) csv_ << sky::sim::ConditionsProbe::csvLine(row) << '\n';
          lastConditions_ = std::move(row);
        }
      receive();
    });
  }

  Options o_;
  sky::flight::Flight flight_;
  std::function<void()> onDone_;
  asio::ip::udp::socket socket_;
  asio::steady_timer timer_;
  asio::ip::udp::endpoint target_, from_;
  sky::sim::CigiHost host_;
  std::array<std::uint8_t, 2048> rx_{};
  std::optional<sky::sim::ConditionsProbe> probe_;
  std::optional<sky::sim::ConditionsRow> lastConditions_;
  std::ofstream csv_;
  double flightTime_s_ = 0;
  double t0_ = 0, t1_ = 0;
  Clock::time_point wallStart_, lastReport_, tick0_;
  bool tick0Set_ = false;
  std::uint64_t ticks_ = 0;
  int exitCode_ = 0;
};

}  // namespace

int main(int argc, char** argv) {
  Options o;
  CLI::App app{"skyshell-replay: replay a recorded flight as a CIGI 3.3 host over UDP"};
  app.add_option("flight", o.flightPath, "flight file: .csv (time_s,lat_deg,lon_deg,alt_m,yaw_deg,pitch_deg,roll_deg), .igc or .gpx")
      ->required();
  app.add_option("--host", o.host, "IG (renderer) address");
  app.add_option("--port", o.port, "IG (renderer) CIGI UDP port")->check(CLI::Range(1, 65535));
  app.add_option("--rate", o.rate_hz, "host frames per second")->check(CLI::Range(1.0, 1000.0));
  app.add_option("--speed", o.speed, "replay speed factor")->check(CLI::Range(0.05, 100.0));
  app.add_option("--start", o.start_s, "start offset into the flight, s")->check(CLI::NonNegativeNumber);
  app.add_option("--end", o.end_s, "end offset into the flight, s (default: the whole flight)");
  app.add_flag("--loop", o.loop, "start again at the end");
  app.add_flag("--little-endian", o.littleEndian, "send little-endian CIGI (default big-endian)");
  app.add_flag("--quiet", o.quiet, "no progress lines");
  app.add_option("--conditions-rate", o.conditionsRate_hz,
                 "Environmental Conditions Requests (weather + aerosol) at the ownship per second of flight; "
                 "0: none")
      ->check(CLI::Range(0.0, 60.0));
  app.add_option("--conditions-csv", o.conditionsCsv,
                 "write every answer (wind, temperature, cloud per layer) to this CSV file");
  CLI11_PARSE(app, argc, argv);

  auto flight = sky::sim::loadFlight(o.flightPath);
  if (!flight) {
    std::fprintf(stderr, "skyshell-replay: %s\n", sky::describe(flight.error()).c_str());
    return 2;
  }
  for (const auto& warning : flight->warnings) std::fprintf(stderr, "skyshell-replay: warning: %s\n", warning.c_str());
  try {
    asio::io_context io;
    asio::signal_set signals(io, SIGINT, SIGTERM);
    signals.async_wait([&](boost::system::error_code ec, int) {
      if (!ec) io.stop();
    });
    Replay replay(io, o, std::move(*flight), [&] { signals.cancel(); });
    replay.start();
    io.run();
    return replay.exitCode();
  } catch (const std::exception& e) {
    std::fprintf(stderr, "skyshell-replay: %s\n", e.what());
    return 1;
  }
}
