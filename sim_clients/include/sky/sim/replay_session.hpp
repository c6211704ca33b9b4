// A recorded flight flown as a CIGI 3.3 host over UDP, in real time (scaled):
// IG Control + ownship Entity Control at a fixed rate on absolute deadlines,
// Environmental Conditions Requests at their own rate, Start of Frame and the
// IG's answers read back, progress on stdout. Runs on the caller's
// io_context; skyshell-replay runs it alone, skyshell-scenario next to its
// weather actions (the tick hook gives them the flight time).
#pragma once

#include <array>
#include <chrono>
#include <cstdint>
#include <fstream>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include <boost/asio/io_context.hpp>
#include <boost/asio/ip/udp.hpp>
#include <boost/asio/steady_timer.hpp>

#include "sky/flight/flight.hpp"
#include "sky/sim/cigi_host.hpp"
#include "sky/sim/conditions_probe.hpp"

namespace sky::sim {

struct ReplayOptions {
  std::string host = "127.0.0.1";  // the IG (renderer)
  unsigned port = 8004;            // its CIGI UDP port
  // Several IGs (the channels of one display), each "ADDR:PORT" (IPv4) or
  // "[ADDR]:PORT", all of one address family; every host datagram goes to
  // each, the conditions requests to the first only. Empty: host:port.
  std::vector<std::string> igs;
  std::uint32_t channels = 1;      // HostOptions::channels
  double channelWidth_deg = 0;     // HostOptions::channelWidth_deg; 0: one channel, no View Control
  double aspect = 16.0 / 9.0;      // width / height of each channel (the vertical half-angles)
  double rate_hz = 60;             // host frames per wall second
  double speed = 1;                // flight seconds per wall second
  double start_s = 0;              // offset into the flight
  double end_s = -1;               // offset into the flight; < 0: its end
  bool loop = false;
  bool littleEndian = false;
  bool quiet = false;              // no progress lines
  double conditionsRate_hz = 1;    // 0: no Environmental Conditions Requests
  std::string conditionsCsv;       // empty: answers are only printed
  std::string name = "replay";     // progress line prefix
  // Synchronous (the IGs run --cigi-sync): each host frame goes once every
  // IG's Start of Frame for the one before has come (or syncTimeout_s has
  // passed, counted), and the flight advances 1/rate_hz x speed per frame:
  // the host runs at the IGs' pace, every frame drawn exactly once.
  bool sync = false;
  double syncTimeout_s = 2.0;
};

// Parses an --ig value, "ADDR:PORT" or "[ADDR]:PORT" (PORT 1..65535);
// throws std::runtime_error saying what is wrong.
boost::asio::ip::udp::endpoint parseIgEndpoint(const std::string& text);

class ReplaySession {
 public:
  // Throws std::runtime_error when the socket or the CSV cannot be opened.
  ReplaySession(boost::asio::io_context& io, ReplayOptions options, flight::Flight flight,
                std::function<void()> onDone);

  // Called on every host frame with the flight time (s from the record's
  // start), before the frame is sent.
  void onTick(std::function<void(double flightTime_s)> hook) { tickHook_ = std::move(hook); }

  void start();
  // Stops sending; onDone runs.
  void stop();

  int exitCode() const { return exitCode_; }
  // Synchronous: host frames sent on before every IG's Start of Frame came.
  std::uint64_t syncTimeouts() const { return syncTimeouts_; }
  double flightTime_s() const { return flightTime_s_; }
  const CigiHost& host() const { return host_; }
  const std::optional<ConditionsProbe>& probe() const { return probe_; }

 private:
  using Clock = std::chrono::steady_clock;
  void tick();
  void report(double t, bool final);
  void finish();
  void receive();

  ReplayOptions o_;
  flight::Flight flight_;
  std::function<void()> onDone_;
  std::function<void(double)> tickHook_;
  boost::asio::ip::udp::socket socket_;
  boost::asio::steady_timer timer_;
  std::vector<boost::asio::ip::udp::endpoint> targets_;
  boost::asio::ip::udp::endpoint from_;
  CigiHost host_;
  std::array<std::uint8_t, 2048> rx_{};
  std::optional<ConditionsProbe> probe_;
  std::optional<ConditionsRow> lastConditions_;
  std::ofstream csv_;
  double flightTime_s_ = 0;
  double t0_ = 0, t1_ = 0;
  Clock::time_point wallStart_, lastReport_, tick0_;
  std::uint64_t ticks_ = 0;
  // Synchronous: the host frame waited for, and which IGs have answered it.
  std::optional<std::uint32_t> awaited_;
  std::vector<bool> answered_;
  std::uint64_t syncTimeouts_ = 0;
  int exitCode_ = 0;
  bool finished_ = false;
};

}  // namespace sky::sim
