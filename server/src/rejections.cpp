// Refused inputs by reason (see rejections.hpp).
#include "sky/server/rejections.hpp"

namespace sky::server {

const char* toString(RejectReason reason) {
  switch (reason) {
    case RejectReason::HttpInvalid: return "http_invalid";
    case RejectReason::Unauthorized: return "unauthorized";
    case RejectReason::CigiMalformed: return "cigi_malformed";
    case RejectReason::CigiRefused: return "cigi_refused";
    case RejectReason::MetarUnparsed: return "metar_unparsed";
    case RejectReason::StreamMalformed: return "stream_malformed";
    case RejectReason::ScenarioInvalid: return "scenario_invalid";
    case RejectReason::TimelineRefused: return "timeline_refused";
    case RejectReason::WsRefused: return "ws_refused";
    case RejectReason::HttpMalformed: return "http_malformed";
    case RejectReason::HttpTooLarge: return "http_too_large";
    case RejectReason::HttpHeaderTooLarge: return "http_header_too_large";
    case RejectReason::HttpForbidden: return "http_forbidden";
    case RejectReason::HttpBusy: return "http_busy";
    case RejectReason::HttpTimeout: return "http_timeout";
    case RejectReason::HttpInternal: return "http_internal";
    case RejectReason::GribBusy: return "grib_busy";
    case RejectReason::SubscriberCap: return "subscriber_cap";
    case RejectReason::HandlerFailed: return "handler_failed";
    case RejectReason::Count_: break;
  }
  return "?";
}

std::string Rejections::metrics() const {
  std::string m =
      "# HELP skyshell_rejected_inputs_total inputs refused, by reason\n"
      "# TYPE skyshell_rejected_inputs_total counter\n";
  for (std::size_t i = 0; i < kRejectReasons; ++i)
    m += std::string("skyshell_rejected_inputs_total{reason=\"") + toString(static_cast<RejectReason>(i)) + "\"} " +
         std::to_string(counts_[i].load(std::memory_order_relaxed)) + "\n";
  return m;
}

nlohmann::json Rejections::json() const {
  nlohmann::json j = nlohmann::json::object();
  for (std::size_t i = 0; i < kRejectReasons; ++i)
    j[toString(static_cast<RejectReason>(i))] = counts_[i].load(std::memory_order_relaxed);
  return j;
}

}  // namespace sky::server
