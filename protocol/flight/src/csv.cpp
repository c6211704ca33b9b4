// CSV flight reader (strict: every anomaly is an error) and the sampler all
// flights share.
#include <algorithm>
#include <array>
#include <charconv>
#include <cmath>
#include <string>

#include "reader_common.hpp"
#include "sky/flight/flight.hpp"
#include "sky/flight/utf8_text.hpp"

namespace sky::flight {

namespace {

constexpr std::array<std::string_view, 7> kColumns = {"time_s",  "lat_deg",   "lon_deg", "alt_m",
                                                       "yaw_deg", "pitch_deg", "roll_deg"};

std::vector<std::string_view> split(std::string_view line) {
  std::vector<std::string_view> out;
  std::size_t start = 0;
  for (std::size_t i = 0; i <= line.size(); ++i) {
    if (i == line.size() || line[i] == ',') {
      out.push_back(detail::trimSpace(line.substr(start, i - start)));
      start = i + 1;
    }
  }
  return out;
}

struct Range {
  double lo, hi;
};
constexpr std::array<Range, 7> kRanges = {{{0, 1.0e7},
                                           {-90, 90},
                                           {-180, 180},
                                           {-1000, 1.0e6},
                                           {-360, 360},
                                           {-90, 90},
                                           {-180, 180}}};

}  // namespace

Result<ParsedFlight> parseCsv(std::string_view text, std::string_view sourceName) {
  ParsedFlight flight;
  bool headerSeen = false;
  std::size_t lineNo = 0;
  std::size_t pos = 0;
  const std::string src = messageText(sourceName);
  // Our own format is ASCII in practice; any ill-formed UTF-8 (a binary
  // file, a Latin-1 comment) is refused, not echoed.
  if (const auto bad = firstInvalidUtf8(text)) {
    const std::string_view before = text.substr(0, *bad);
    const std::size_t line = 1 + static_cast<std::size_t>(std::count(before.begin(), before.end(), '\n'));
    const std::size_t column = *bad - (before.rfind('\n') == std::string_view::npos ? 0 : before.rfind('\n') + 1);
    return fail(ErrorCode::Malformed, src + ":" + std::to_string(line) + ": byte " + std::to_string(column + 1) +
                                          " of the line is not UTF-8");
  }
  while (pos <= text.size()) {
    const std::size_t end = std::min(text.find('\n', pos), text.size());
    const std::string_view line = detail::trimSpace(text.substr(pos, end - pos));
    pos = end + 1;
    ++lineNo;
    if (line.empty() || line.front() == '#') {
      if (end == text.size()) break;
      continue;
    }
    const auto fields = split(line);
    const std::string at = src + ":" + std::to_string(lineNo) + ": ";
    if (!headerSeen) {
      if (fields.size() != kColumns.size() || !std::equal(fields.begin(), fields.end(), kColumns.begin()))
        return fail(ErrorCode::Malformed,
                    at + "header must be 'time_s,lat_deg,lon_deg,alt_m,yaw_deg,pitch_deg,roll_deg'");
      headerSeen = true;
      continue;
    }
    if (fields.size() != kColumns.size())
      return fail(ErrorCode::Malformed, at + std::to_string(fields.size()) + " fields, expected " +
                                            std::to_string(kColumns.size()));
    std::array<double, 7> v{};
    for (std::size_t i = 0; i < kColumns.size(); ++i) {
      const std::string_view f = fields[i];
      const auto [ptr, ec] = std::from_chars(f.data(), f.data() + f.size(), v[i]);
      if (ec != std::errc() || ptr != f.data() + f.size() || !std::isfinite(v[i]))
        return fail(ErrorCode::Malformed,
                    at + "field '" + std::string(kColumns[i]) + "': '" + detail::printable(f) + "' is not a number");
      if (v[i] < kRanges[i].lo || v[i] > kRanges[i].hi)
        return fail(ErrorCode::InvalidArgument, at + "field '" + std::string(kColumns[i]) + "': " +
                                                    detail::printable(f) + " outside [" +
                                                    std::to_string(kRanges[i].lo) + ", " +
                                                    std::to_string(kRanges[i].hi) + "]");
    }
    if (!flight.fixes.empty() && v[0] <= flight.fixes.back().time_s)
      return fail(ErrorCode::InvalidArgument,
                  at + "field 'time_s': " + detail::printable(fields[0]) + " does not increase");
    flight.fixes.push_back(Fix{v[0], {{v[1], v[2], v[3]}, v[4], v[5], v[6]}});
    flight.fixLines.push_back(lineNo);
    if (end == text.size()) break;
  }
  if (!headerSeen) return fail(ErrorCode::Malformed, src + ": no header line");
  if (flight.fixes.size() < 2)
    return fail(ErrorCode::InvalidArgument, src + ": a flight needs at least two fixes");
  return flight;
}

namespace {

// Attitude as a unit quaternion of the aerospace Z-Y-X rotation (yaw about
// down, pitch about the new right axis, roll about the new forward axis), so
// that interpolation follows the shortest rotation between two attitudes
// instead of three independent angles (which wobble when bank and heading
// change together, and break near pitch +-90).
struct Quaternion {
  double w, x, y, z;
};
struct Attitude {
  double yaw_deg, pitch_deg, roll_deg;
};
constexpr double kRad = 3.14159265358979323846 / 180.0;

Quaternion toQuaternion(const geo::GeodeticPose& p) {
  const double cy = std::cos(p.yaw_deg * kRad / 2), sy = std::sin(p.yaw_deg * kRad / 2);
  const double cp = std::cos(p.pitch_deg * kRad / 2), sp = std::sin(p.pitch_deg * kRad / 2);
  const double cr = std::cos(p.roll_deg * kRad / 2), sr = std::sin(p.roll_deg * kRad / 2);
  return {cr * cp * cy + sr * sp * sy, sr * cp * cy - cr * sp * sy, cr * sp * cy + sr * cp * sy,
          cr * cp * sy - sr * sp * cy};
}

Attitude toAttitude(const Quaternion& q) {
  const double sinPitch = std::clamp(2 * (q.w * q.y - q.z * q.x), -1.0, 1.0);
  return {std::atan2(2 * (q.w * q.z + q.x * q.y), 1 - 2 * (q.y * q.y + q.z * q.z)) / kRad,
          std::asin(sinPitch) / kRad,
          std::atan2(2 * (q.w * q.x + q.y * q.z), 1 - 2 * (q.x * q.x + q.y * q.y)) / kRad};
}

Quaternion operator*(const Quaternion& a, const Quaternion& b) {
  return {a.w * b.w - a.x * b.x - a.y * b.y - a.z * b.z, a.w * b.x + a.x * b.w + a.y * b.z - a.z * b.y,
          a.w * b.y - a.x * b.z + a.y * b.w + a.z * b.x, a.w * b.z + a.x * b.y - a.y * b.x + a.z * b.w};
}

Quaternion conjugate(const Quaternion& q) { return {q.w, -q.x, -q.y, -q.z}; }

// The local north-east-down frame at a geodetic point, as a rotation from NED
// to Earth-fixed (ECEF) axes: about z by the longitude, then about y by
// -(latitude + 90 deg). Attitudes are interpolated in Earth-fixed axes, so
// that a track over a pole (where heading flips from 0 to 180 in one step)
// turns the camera no more than the aircraft turned.
Quaternion nedToEcef(const geo::Geodetic& p) {
  const double hl = p.lon_deg * kRad / 2, hp = (-p.lat_deg - 90.0) * kRad / 2;
  const Quaternion z{std::cos(hl), 0, 0, std::sin(hl)};
  const Quaternion y{std::cos(hp), 0, std::sin(hp), 0};
  return z * y;
}

// Spherical linear interpolation along the shorter arc; normalised lerp when
// the two are within ~2.6 degrees (where slerp's sin ratio loses precision).
Quaternion slerp(const Quaternion& a, Quaternion b, double u) {
  double d = a.w * b.w + a.x * b.x + a.y * b.y + a.z * b.z;
  if (d < 0) {
    b = {-b.w, -b.x, -b.y, -b.z};
    d = -d;
  }
  double ka = 1 - u, kb = u;
  if (d < 0.9995) {
    const double theta = std::acos(d);
    ka = std::sin((1 - u) * theta) / std::sin(theta);
    kb = std::sin(u * theta) / std::sin(theta);
  }
  Quaternion q{ka * a.w + kb * b.w, ka * a.x + kb * b.x, ka * a.y + kb * b.y, ka * a.z + kb * b.z};
  const double n = std::sqrt(q.w * q.w + q.x * q.x + q.y * q.y + q.z * q.z);
  return {q.w / n, q.x / n, q.y / n, q.z / n};
}

}  // namespace

geo::GeodeticPose sample(const Flight& flight, double time_s) {
  const auto& fx = flight.fixes;
  if (time_s <= fx.front().time_s) return fx.front().pose;
  if (time_s >= fx.back().time_s) return fx.back().pose;
  const auto it = std::upper_bound(fx.begin(), fx.end(), time_s,
                                   [](double t, const Fix& f) { return t < f.time_s; });
  const Fix& b = *it;
  const Fix& a = *(it - 1);
  const double u = (time_s - a.time_s) / (b.time_s - a.time_s);
  const geo::Vec3d pa = geo::toEcef(a.pose.position), pb = geo::toEcef(b.pose.position);
  geo::GeodeticPose out;
  out.position = geo::fromEcef(pa + (pb - pa) * u);
  // ECEF lerp cuts the chord: re-impose the interpolated altitude.
  out.position.alt_m = a.pose.position.alt_m + (b.pose.position.alt_m - a.pose.position.alt_m) * u;
  const Quaternion qa = nedToEcef(a.pose.position) * toQuaternion(a.pose);
  const Quaternion qb = nedToEcef(b.pose.position) * toQuaternion(b.pose);
  const Attitude att = toAttitude(conjugate(nedToEcef(out.position)) * slerp(qa, qb, u));
  out.yaw_deg = std::fmod(att.yaw_deg + 360.0, 360.0);
  out.pitch_deg = att.pitch_deg;
  out.roll_deg = att.roll_deg;
  return out;
}

}  // namespace sky::flight
