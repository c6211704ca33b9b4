// Environmental conditions along a replayed flight (see conditions_probe.hpp).
#include "sky/sim/conditions_probe.hpp"

#include <cstdio>

#include "sky/core/assert.hpp"

namespace sky::sim {

namespace {

// Cloud layers reported as aerosol concentration columns in the CSV: CIGI's
// three cloud layer ids.
constexpr std::uint8_t kCsvCloudLayers[] = {1, 2, 3};

}  // namespace

ConditionsProbe::ConditionsProbe(double rate_hz) : period_s_(1.0 / rate_hz) { SKY_ASSERT(rate_hz > 0); }

std::optional<cigi::EnvironmentalConditionsRequest> ConditionsProbe::due(double t, const geo::Geodetic& at) {
  // (A relative tolerance: frame times are sums of 1/rate steps, and 0.3 - 0.2
  // is a hair under 0.1.) A flight time that went back (a loop) asks at once.
  if (lastAsked_s_ && t - *lastAsked_s_ < period_s_ * (1 - 1e-9) && t >= *lastAsked_s_) return std::nullopt;
  lastAsked_s_ = t;
  cigi::EnvironmentalConditionsRequest r;
  r.requestType = cigi::kRequestWeather | cigi::kRequestAerosol;
  r.requestId = nextId_++;
  r.lat_deg = at.lat_deg;
  r.lon_deg = geo::normalizeLon_deg(at.lon_deg);
  r.alt_m = at.alt_m;
  if (pending_.erase(r.requestId) > 0) ++unanswered_;
  ConditionsRow row;
  row.requestId = r.requestId;
  row.flightTime_s = t;
  row.position = {r.lat_deg, r.lon_deg, r.alt_m};
  pending_[r.requestId] = row;
  ++asked_;
  return r;
}

std::vector<ConditionsRow> ConditionsProbe::onIgPackets(const std::vector<cigi::Packet>& packets, double t) {
  std::vector<ConditionsRow> done;
  std::map<std::uint8_t, ConditionsRow> answeredNow;
  for (const auto& p : packets) {
    if (const auto* w = std::get_if<cigi::WeatherConditionsResponse>(&p)) {
      auto it = pending_.find(w->requestId);
      if (it == pending_.end()) {
        ++stray_;
        continue;
      }
      it->second.weather = *w;
      it->second.answeredAfter_s = t - it->second.flightTime_s;
      answeredNow[w->requestId] = std::move(it->second);
      pending_.erase(it);
    }
  }
  for (const auto& p : packets) {
    if (const auto* a = std::get_if<cigi::AerosolConcentrationResponse>(&p)) {
      auto it = answeredNow.find(a->requestId);
      if (it != answeredNow.end())
        it->second.aerosols.push_back(*a);
      else if (auto pend = pending_.find(a->requestId); pend != pending_.end())
        pend->second.aerosols.push_back(*a);  // weather answer still to come
      else
        ++stray_;
    }
  }
  for (auto& [id, row] : answeredNow) {
    ++answered_;
    done.push_back(std::move(row));
  }
  return done;
}

std::string ConditionsProbe::csvHeader() {
  std::string h = "flight_time_s,lat_deg,lon_deg,alt_m,answered_after_s,wind_mps,wind_from_deg,vertical_wind_mps,"
                  "humidity_pct,temperature_c,visibility_m,pressure_hpa";
  for (auto layer : kCsvCloudLayers) h += ",cloud" + std::to_string(layer) + "_gpm3";
  return h;
}

std::string ConditionsProbe::csvLine(const ConditionsRow& r) {
  char buf[256];
  if (r.weather) {
    const auto& w = *r.weather;
    std::snprintf(buf, sizeof buf, "%.3f,%.7f,%.7f,%.1f,%.3f,%.2f,%.1f,%.2f,%u,%.1f,%.0f,%.2f", r.flightTime_s,
                  r.position.lat_deg, r.position.lon_deg, r.position.alt_m, r.answeredAfter_s,
                  double(w.horizontalWind_mps), double(w.windDirection_deg), double(w.verticalWind_mps),
                  unsigned(w.humidity_pct), double(w.airTemperature_c), double(w.visibility_m), double(w.pressure_hpa));
  } else {
    std::snprintf(buf, sizeof buf, "%.3f,%.7f,%.7f,%.1f,,,,,,,,", r.flightTime_s, r.position.lat_deg,
                  r.position.lon_deg, r.position.alt_m);
  }
  std::string line = buf;
  for (auto layer : kCsvCloudLayers) {
    line += ',';
    for (const auto& a : r.aerosols)
      if (static_cast<std::uint8_t>(a.layerId) == layer) {
        std::snprintf(buf, sizeof buf, "%.4f", double(a.concentration_gpm3));
        line += buf;
        break;
      }
  }
  return line;
}

}  // namespace sky::sim
