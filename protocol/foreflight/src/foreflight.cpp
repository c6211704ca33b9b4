// ForeFlight UDP text lines (see foreflight.hpp).
#include "sky/foreflight/foreflight.hpp"

#include <array>
#include <charconv>
#include <cmath>
#include <cstdio>

namespace sky::foreflight {

namespace {

constexpr std::size_t kMaxSimName = 64;

bool printableAscii(std::string_view s) {
  for (const char c : s)
    if (c < 0x20 || c > 0x7e) return false;
  return true;
}

// Splits at commas into at most `max` fields (the rest stays in the last).
std::vector<std::string_view> fields(std::string_view text, std::size_t max) {
  std::vector<std::string_view> out;
  while (out.size() + 1 < max) {
    const auto comma = text.find(',');
    if (comma == std::string_view::npos) break;
    out.push_back(text.substr(0, comma));
    text.remove_prefix(comma + 1);
  }
  out.push_back(text);
  return out;
}

// A decimal number as senders write it ("-158.300", "0.0", "1e3"), with
// surrounding spaces tolerated.
Result<double> number(std::string_view text, const char* kind, const char* field) {
  while (!text.empty() && text.front() == ' ') text.remove_prefix(1);
  while (!text.empty() && text.back() == ' ') text.remove_suffix(1);
  if (!text.empty() && text.front() == '+') text.remove_prefix(1);
  double v = 0;
  const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), v);
  if (text.empty() || ec != std::errc() || end != text.data() + text.size())
    return fail(ErrorCode::Malformed, std::string(kind) + ": field '" + field + "' is not a number");
  if (!std::isfinite(v))
    return fail(ErrorCode::InvalidArgument, std::string(kind) + ": field '" + field + "' is not finite");
  return v;
}

Result<double> inRange(Result<double> v, double lo, double hi, const char* kind, const char* field) {
  if (!v) return v;
  if (*v < lo || *v > hi) {
    char buf[160];
    std::snprintf(buf, sizeof buf, "%s: field '%s' %g outside [%g, %g]", kind, field, *v, lo, hi);
    return fail(ErrorCode::InvalidArgument, buf);
  }
  return v;
}

Result<std::string> simName(std::string_view name, const char* kind) {
  if (name.size() > kMaxSimName)
    return fail(ErrorCode::Malformed, std::string(kind) + ": the simulator name is longer than 64 bytes");
  return std::string(name);
}

Result<Message> position(std::string_view rest) {
  const auto f = fields(rest, 7);
  if (f.size() != 6) return fail(ErrorCode::Malformed, "XGPS: " + std::to_string(f.size() - 1) + " values, not 5");
  auto sim = simName(f[0], "XGPS");
  if (!sim) return tl::unexpected(sim.error());
  Position p;
  p.sim = std::move(*sim);
  const std::array<std::pair<double*, Result<double>>, 5> values{{
      {&p.lon_deg, inRange(number(f[1], "XGPS", "longitude"), -180, 180, "XGPS", "longitude")},
      {&p.lat_deg, inRange(number(f[2], "XGPS", "latitude"), -90, 90, "XGPS", "latitude")},
      {&p.alt_m, inRange(number(f[3], "XGPS", "altitude"), -1000, 30000, "XGPS", "altitude")},
      {&p.track_deg, inRange(number(f[4], "XGPS", "track"), -360, 360, "XGPS", "track")},
      {&p.groundSpeed_mps, inRange(number(f[5], "XGPS", "ground speed"), 0, 1000, "XGPS", "ground speed")},
  }};
  for (const auto& [to, v] : values) {
    if (!v) return tl::unexpected(v.error());
    *to = *v;
  }
  if (p.track_deg < 0) p.track_deg += 360;
  return Message{std::move(p)};
}

Result<Message> attitude(std::string_view rest) {
  // Heading, pitch, roll; X-Plane and add-ons may append more values.
  const auto f = fields(rest, 5);
  if (f.size() < 4) return fail(ErrorCode::Malformed, "XATT: " + std::to_string(f.size() - 1) + " values, not 3");
  auto sim = simName(f[0], "XATT");
  if (!sim) return tl::unexpected(sim.error());
  Attitude a;
  a.sim = std::move(*sim);
  const std::array<std::pair<double*, Result<double>>, 3> values{{
      {&a.heading_deg, inRange(number(f[1], "XATT", "heading"), -360, 360, "XATT", "heading")},
      {&a.pitch_deg, inRange(number(f[2], "XATT", "pitch"), -90, 90, "XATT", "pitch")},
      {&a.roll_deg, inRange(number(f[3], "XATT", "roll"), -180, 180, "XATT", "roll")},
  }};
  for (const auto& [to, v] : values) {
    if (!v) return tl::unexpected(v.error());
    *to = *v;
  }
  if (a.heading_deg < 0) a.heading_deg += 360;
  return Message{std::move(a)};
}

}  // namespace

Result<Message> parseLine(std::string_view line) {
  if (!line.empty() && line.back() == '\r') line.remove_suffix(1);
  if (!printableAscii(line)) return fail(ErrorCode::Malformed, "a byte that is not printable ASCII");
  if (line.starts_with("XGPS")) return position(line.substr(4));
  if (line.starts_with("XATT")) return attitude(line.substr(4));
  if (line.starts_with("XTRAFFIC")) return Message{Other{"XTRAFFIC"}};
  // Another kind: its name runs into the sender's, so the first four
  // letters stand for it, as XGPS and XATT have four.
  std::size_t letters = 0;
  while (letters < line.size() && letters < 4 && line[letters] >= 'A' && line[letters] <= 'Z') ++letters;
  if (letters < 4 || line[0] != 'X')
    return fail(ErrorCode::Malformed, "a line that does not start with a message kind (XGPS, XATT, ...)");
  return Message{Other{std::string(line.substr(0, letters))}};
}

Result<std::vector<Message>> parseDatagram(std::span<const std::uint8_t> bytes) {
  if (bytes.empty()) return fail(ErrorCode::Malformed, "an empty datagram");
  if (bytes.size() > kMaxDatagramBytes)
    return fail(ErrorCode::TooLarge, "a datagram of " + std::to_string(bytes.size()) + " bytes (at most " +
                                         std::to_string(kMaxDatagramBytes) + ")");
  std::string_view text(reinterpret_cast<const char*>(bytes.data()), bytes.size());
  std::vector<Message> out;
  std::size_t lineNo = 0;
  while (!text.empty()) {
    const auto end = text.find('\n');
    const std::string_view line = text.substr(0, end);
    text = end == std::string_view::npos ? std::string_view() : text.substr(end + 1);
    ++lineNo;
    if (line.empty() || line == "\r") continue;
    if (out.size() == kMaxLinesPerDatagram)
      return fail(ErrorCode::TooLarge, "more than " + std::to_string(kMaxLinesPerDatagram) + " lines in a datagram");
    auto m = parseLine(line);
    if (!m) return fail(m.error().code, "line " + std::to_string(lineNo) + ": " + m.error().detail);
    out.push_back(std::move(*m));
  }
  if (out.empty()) return fail(ErrorCode::Malformed, "a datagram of empty lines");
  return out;
}

std::string formatLine(const Position& p) {
  char buf[160];
  std::snprintf(buf, sizeof buf, ",%.6f,%.6f,%.1f,%.3f,%.1f", p.lon_deg, p.lat_deg, p.alt_m, p.track_deg,
                p.groundSpeed_mps);
  return "XGPS" + p.sim + buf;
}

std::string formatLine(const Attitude& a) {
  char buf[128];
  std::snprintf(buf, sizeof buf, ",%.2f,%.2f,%.2f", a.heading_deg, a.pitch_deg, a.roll_deg);
  return "XATT" + a.sim + buf;
}

}  // namespace sky::foreflight
