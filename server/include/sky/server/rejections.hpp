// Inputs the server refused, counted by reason, for /metrics
// (skyshell_rejected_inputs_total{reason="..."}) and the console's health
// message. One instance per server, shared by every input on its io thread;
// the counters are atomic so /metrics and tests may read them from anywhere.
#pragma once

#include <array>
#include <atomic>
#include <cstddef>
#include <cstdint>
#include <string>

#include <nlohmann/json.hpp>

namespace sky::server {

enum class RejectReason : std::size_t {
  HttpInvalid,      // an API request body that does not parse, or changes the model refuses (400)
  Unauthorized,     // a change without the token (401)
  CigiMalformed,    // a CIGI datagram that does not decode
  CigiRefused,      // CIGI weather the model refuses
  MetarUnparsed,    // a METAR report that does not parse (one per report)
  StreamMalformed,  // a weather-stream frame or message a subscriber sent that the stream refuses
  ScenarioInvalid,  // a scenario (POST /api/scenario) that does not parse or whose timeline the model refuses
  TimelineRefused,  // a scenario timeline entry the model refused when it came due
  WsRefused,        // a WebSocket client over the bound, or an upgrade that failed
  // The HTTP API's transport: one count per refused request or connection.
  HttpMalformed,    // not HTTP, or a target or header that is not valid UTF-8 (400)
  HttpTooLarge,     // a body over its route's limit, refused before it is read (413)
  HttpHeaderTooLarge,  // a request line and header over 8 KiB (431)
  HttpForbidden,    // a foreign Origin or a Host that is not this server's (403)
  HttpBusy,         // a connection past the cap on connections in flight (503)
  HttpTimeout,      // a client that did not finish its request within the deadline (dropped)
  HttpInternal,     // a request whose handling failed inside the server (500/503)
  GribBusy,         // POST /api/grib while kGribDecodeSlots forecasts decode (503)
  SubscriberCap,    // a stream connection past ServerOptions::maxSubscribers (sent an Error, closed)
  HandlerFailed,    // a handler threw: the peer's connection or datagram was dropped, the server runs on
  Count_
};

inline constexpr std::size_t kRejectReasons = static_cast<std::size_t>(RejectReason::Count_);

// The label: "http_invalid", "unauthorized", ...
const char* toString(RejectReason reason);

class Rejections {
 public:
  void count(RejectReason reason, std::uint64_t n = 1) {
    counts_[static_cast<std::size_t>(reason)].fetch_add(n, std::memory_order_relaxed);
  }
  std::uint64_t get(RejectReason reason) const {
    return counts_[static_cast<std::size_t>(reason)].load(std::memory_order_relaxed);
  }
  // Prometheus text: one labelled counter line per reason (zeros included).
  std::string metrics() const;
  // {"http_invalid": 0, "unauthorized": 2, ...}: every reason.
  nlohmann::json json() const;

 private:
  std::array<std::atomic<std::uint64_t>, kRejectReasons> counts_{};
};

}  // namespace sky::server
