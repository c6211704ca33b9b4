// The lines of skyshell-replay --info (see info.hpp).
#include "sky/flight/info.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>

namespace sky::flight {

namespace {

std::string format(const char* f, double a, double b) {
  char buf[96];
  std::snprintf(buf, sizeof buf, f, a, b);
  return buf;
}

std::string clock(double s) {
  const long t = std::lround(std::max(0.0, s));
  char buf[32];
  std::snprintf(buf, sizeof buf, "%ldh%02ldm%02lds", t / 3600, t / 60 % 60, t % 60);
  return buf;
}

std::string utcText(std::int64_t utc_s) {
  using namespace std::chrono;
  const auto day = floor<days>(sys_seconds{seconds{utc_s}});
  const year_month_day ymd{day};
  const hh_mm_ss hms{sys_seconds{seconds{utc_s}} - day};
  char buf[40];
  std::snprintf(buf, sizeof buf, "%04d-%02u-%02uT%02ld:%02ld:%02ldZ", static_cast<int>(ymd.year()),
                static_cast<unsigned>(ymd.month()), static_cast<unsigned>(ymd.day()),
                static_cast<long>(hms.hours().count()), static_cast<long>(hms.minutes().count()),
                static_cast<long>(hms.seconds().count()));
  return buf;
}

}  // namespace

std::string formatName(std::string_view text, std::string_view sourceName) {
  const auto dot = sourceName.rfind('.');
  const auto slash = sourceName.rfind('/');
  std::string ext;
  if (dot != std::string_view::npos && (slash == std::string_view::npos || dot > slash))
    for (char c : sourceName.substr(dot + 1)) ext.push_back(c >= 'A' && c <= 'Z' ? static_cast<char>(c - 'A' + 'a') : c);
  if (ext == "csv") {
    // The first line that is neither blank nor a '#' comment, as parseFlight reads it.
    std::size_t pos = 0;
    while (pos < text.size()) {
      std::size_t end = text.find_first_of("\r\n", pos);
      if (end == std::string_view::npos) end = text.size();
      const std::string_view line = text.substr(pos, end - pos);
      const auto start = line.find_first_not_of(" \t");
      if (start != std::string_view::npos && line[start] != '#')
        return isAdsbCsvHeader(line) ? "ADS-B CSV" : "Skyshell CSV";
      pos = end + 1;
    }
    return "Skyshell CSV";
  }
  if (ext == "igc") return "IGC";
  if (ext == "gpx") return "GPX";
  if (ext == "json") return "readsb trace JSON";
  if (ext == "kml") return "KML";
  if (ext == "kmz") return "KMZ";
  if (ext == "fdr") return "X-Plane FDR";
  std::string shown;
  for (char c : ext.substr(0, 16)) shown.push_back(c >= 0x20 && c < 0x7f ? c : '?');
  return "." + shown + " (unknown)";
}

std::vector<std::string> describeFlight(const ParsedFlight& flight, std::string_view formatText,
                                        const CleanReport* cleaning, const CleanOptions& options) {
  std::vector<std::string> out;
  out.push_back("format: " + std::string(formatText));
  out.push_back("aircraft: " + (flight.aircraft.empty() ? std::string("not recorded in the file") : flight.aircraft));
  const auto& fx = flight.fixes;
  const double first_s = fx.empty() ? 0 : fx.front().time_s, last_s = fx.empty() ? 0 : fx.back().time_s;
  out.push_back(format("time: %.1f s to %.1f s of the record", first_s, last_s) + " (" + clock(last_s - first_s) + ")");
  out.push_back("utc start: " + (flight.startUtc_s ? utcText(*flight.startUtc_s + static_cast<std::int64_t>(
                                                                                       std::floor(first_s)))
                                                     : std::string("not recorded (no date in the file)")));
  const auto holds = cleaning ? static_cast<std::size_t>(std::count_if(
                                     cleaning->gaps.begin(), cleaning->gaps.end(),
                                     [](const GapNote& g) { return g.action == GapNote::Action::Held; }))
                               : 0;
  out.push_back("fixes: " + std::to_string(fx.size() - holds));
  if (!fx.empty()) {
    double latLo = 90, latHi = -90, lonLo = 180, lonHi = -180, altLo = INFINITY, altHi = -INFINITY;
    bool antimeridian = false;
    for (std::size_t i = 0; i < fx.size(); ++i) {
      const geo::Geodetic& p = fx[i].pose.position;
      latLo = std::min(latLo, p.lat_deg), latHi = std::max(latHi, p.lat_deg);
      lonLo = std::min(lonLo, p.lon_deg), lonHi = std::max(lonHi, p.lon_deg);
      altLo = std::min(altLo, p.alt_m), altHi = std::max(altHi, p.alt_m);
      if (i > 0 && std::abs(p.lon_deg - fx[i - 1].pose.position.lon_deg) > 180) antimeridian = true;
    }
    out.push_back(format("bounding box: lat %.5f to %.5f deg", latLo, latHi) +
                  format(", lon %.5f to %.5f deg", lonLo, lonHi) + (antimeridian ? " (crosses the antimeridian)" : "") +
                  format(", altitude %.0f to %.0f m", altLo, altHi));
  }
  out.push_back("altitude: " + (flight.altitudeSource.empty() ? std::string("as the file records it (m)")
                                                               : flight.altitudeSource));
  if (cleaning) {
    for (const std::string& l : cleaning->lines(options)) out.push_back("cleaning: " + l);
  } else {
    out.push_back("cleaning: off (--no-clean): the track as read");
  }
  for (const std::string& w : flight.warnings) out.push_back("reader: " + w);
  return out;
}

}  // namespace sky::flight
