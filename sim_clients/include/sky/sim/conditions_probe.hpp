// What a flight model would fly through: the replay host asks the IG for the
// weather at the ownship (CIGI Environmental Conditions Request, weather and
// aerosol bits) at a set rate, and joins the IG's answers (Weather Conditions
// Response: wind, humidity, temperature, visibility, pressure; Aerosol
// Concentration Response: cloud water per layer) with where and when it asked.
#pragma once

#include <cstddef>
#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "sky/cigi/codec.hpp"
#include "sky/geo/geodetic.hpp"

namespace sky::sim {

struct ConditionsRow {
  std::uint8_t requestId = 0;
  double flightTime_s = 0;    // when it was asked
  geo::Geodetic position;     // where
  double answeredAfter_s = 0; // flight time between asking and the answer
  std::optional<cigi::WeatherConditionsResponse> weather;
  std::vector<cigi::AerosolConcentrationResponse> aerosols;  // in arrival order
};

class ConditionsProbe {
 public:
  // rate_hz > 0: requests per second of flight time.
  explicit ConditionsProbe(double rate_hz);

  // The request to send with the frame at flightTime_s, when one is due.
  std::optional<cigi::EnvironmentalConditionsRequest> due(double flightTime_s, const geo::Geodetic& at);

  // Feeds the packets of one IG datagram; returns the requests answered by it
  // (a Weather Conditions Response completes a row; aerosol responses of the
  // same request in the same datagram are attached to it). Answers to ids
  // never asked (or already answered) are counted as stray.
  std::vector<ConditionsRow> onIgPackets(const std::vector<cigi::Packet>& packets, double flightTime_s);

  std::uint64_t asked() const { return asked_; }
  std::uint64_t answered() const { return answered_; }
  std::uint64_t stray() const { return stray_; }
  // Requests not answered by the time their id came round again (256 later).
  std::uint64_t unanswered() const { return unanswered_; }

  // CSV for --conditions-csv: a header line and one line per row (units in the header).
  static std::string csvHeader();
  static std::string csvLine(const ConditionsRow& row);

 private:
  double period_s_;
  std::optional<double> lastAsked_s_;
  std::uint8_t nextId_ = 0;
  std::map<std::uint8_t, ConditionsRow> pending_;
  std::uint64_t asked_ = 0, answered_ = 0, stray_ = 0, unanswered_ = 0;
};

}  // namespace sky::sim
