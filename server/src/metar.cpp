// METAR/SPECI decoder (see metar.hpp): groups are matched by hand-written
// pattern checks, no regex, so any byte string is decoded in linear time; a
// group that fits no pattern is skipped and noted, never fatal past the
// station.
#include "sky/server/metar.hpp"

#include <algorithm>
#include <array>
#include <cstddef>

namespace sky::server {

namespace {

// Knots per unit (1 kt = 1852 m / 3600 s).
constexpr double kKnotsPerMps = 3600.0 / 1852.0;
constexpr double kKnotsPerKmh = 1.0 / 1.852;
// hPa per inch of mercury (ICAO standard atmosphere conversion).
constexpr double kHpaPerInHg = 33.8639;

bool isDigit(char c) { return c >= '0' && c <= '9'; }
bool isUpper(char c) { return c >= 'A' && c <= 'Z'; }

bool allDigits(std::string_view s) {
  if (s.empty()) return false;
  for (char c : s)
    if (!isDigit(c)) return false;
  return true;
}

bool allSlashes(std::string_view s) {
  if (s.empty()) return false;
  for (char c : s)
    if (c != '/') return false;
  return true;
}

// Value of an all-digits string; saturates at 999,999,999 so that a run of
// digits longer than any real group cannot overflow.
int toInt(std::string_view s) {
  constexpr int kMax = 999'999'999;
  int v = 0;
  for (char c : s) {
    if (v > (kMax - 9) / 10) return kMax;
    v = v * 10 + (c - '0');
  }
  return v;
}

bool endsWith(std::string_view s, std::string_view suffix) {
  return s.size() >= suffix.size() && s.substr(s.size() - suffix.size()) == suffix;
}

bool isSpace(char c) { return c == ' ' || c == '\t' || c == '\n' || c == '\r' || c == '\v' || c == '\f'; }

std::vector<std::string_view> splitGroups(std::string_view text) {
  std::vector<std::string_view> groups;
  std::size_t i = 0;
  while (i < text.size()) {
    while (i < text.size() && isSpace(text[i])) ++i;
    std::size_t j = i;
    while (j < text.size() && !isSpace(text[j])) ++j;
    if (j > i) groups.push_back(text.substr(i, j - i));
    i = j;
  }
  // The end-of-message '=' may stick to the last group or stand alone.
  while (!groups.empty()) {
    std::string_view& last = groups.back();
    while (!last.empty() && last.back() == '=') last.remove_suffix(1);
    if (!last.empty()) break;
    groups.pop_back();
  }
  return groups;
}

class Groups {
 public:
  // `groups` are views of `capitals`, the report in capitals; notes quote the
  // same bytes of `written`, the report as it came.
  Groups(std::vector<std::string_view> groups, std::string_view capitals, std::string_view written)
      : groups_(std::move(groups)), capitals_(capitals), written_(written) {}
  bool done() const { return next_ >= groups_.size(); }
  std::string_view peek(std::size_t ahead = 0) const {
    return next_ + ahead < groups_.size() ? groups_[next_ + ahead] : std::string_view{};
  }
  void advance(std::size_t n = 1) { next_ += n; }
  std::size_t position() const { return next_ + 1; }  // of peek(), 1-based
  tl::unexpected<Error> error(ErrorCode code, const std::string& what) const {
    if (done()) return fail(code, "report ends early: " + what);
    return fail(code, "group " + std::to_string(next_ + 1) + " '" + std::string(peek()) +
                          "': " + what);
  }
  // Notes the current group as skipped (not decoded) with the reason.
  void skip(MetarReport& out, std::string reason) const {
    ++out.skippedCount;
    note(out.skipped, 0, std::move(reason));
  }
  // Notes the group `ahead` of the current one as read together with it.
  void join(MetarReport& out, std::size_t ahead, std::string reason) const {
    note(out.joined, ahead, std::move(reason));
  }

 private:
  void note(std::vector<MetarGroupNote>& notes, std::size_t ahead, std::string reason) const {
    if (notes.size() >= kMaxNotedGroups) return;
    const std::string_view g = peek(ahead);
    const std::string_view written = written_.substr(static_cast<std::size_t>(g.data() - capitals_.data()), g.size());
    notes.push_back({next_ + ahead + 1, std::string(written.substr(0, kMaxNotedGroupBytes)), std::move(reason)});
  }

  std::vector<std::string_view> groups_;
  std::string_view capitals_, written_;
  std::size_t next_ = 0;
};

bool isTrendOrRemarks(std::string_view g) {
  if (g == "NOSIG" || g == "BECMG" || g == "TEMPO" || g == "INTER" || g == "RMK") return true;
  if (g.size() == 6 && g.substr(0, 4) == "PROB" && allDigits(g.substr(4))) return true;
  if (g.size() >= 6 && g.substr(0, 2) == "FM" && allDigits(g.substr(2))) return true;
  return false;
}

bool isStation(std::string_view g) {
  if (g.size() != 4 || !isUpper(g[0])) return false;
  for (char c : g)
    if (!isUpper(c) && !isDigit(c)) return false;
  return true;
}

Result<MetarTime> parseTime(const Groups& in) {
  std::string_view g = in.peek();
  if (g.size() != 7 || g[6] != 'Z' || !allDigits(g.substr(0, 6)))
    return fail(ErrorCode::Malformed, "time is not DDHHMMZ");
  MetarTime t{toInt(g.substr(0, 2)), toInt(g.substr(2, 2)), toInt(g.substr(4, 2))};
  if (t.day < 1 || t.day > 31) return fail(ErrorCode::InvalidArgument, "day outside [1, 31]");
  if (t.hour > 23) return fail(ErrorCode::InvalidArgument, "hour outside [0, 23]");
  if (t.minute > 59) return fail(ErrorCode::InvalidArgument, "minute outside [0, 59]");
  return t;
}

bool looksLikeWind(std::string_view g) {
  return endsWith(g, "KT") || endsWith(g, "MPS") || endsWith(g, "KMH");
}

// dddff(f)(Gff(f))KT|MPS|KMH, VRBff.., 00000KT (calm), /////KT (not measured).
Result<std::optional<MetarWind>> parseWind(const Groups& in) {
  std::string_view g = in.peek();
  MetarWind wind;
  std::string_view body = g;
  double toKnots = 1;
  if (endsWith(g, "KT")) {
    body.remove_suffix(2);
  } else if (endsWith(g, "MPS")) {
    body.remove_suffix(3);
    wind.reportedUnit = WindUnit::MetresPerSecond;
    toKnots = kKnotsPerMps;
  } else {
    body.remove_suffix(3);
    wind.reportedUnit = WindUnit::KilometresPerHour;
    toKnots = kKnotsPerKmh;
  }
  if (allSlashes(body) && body.size() == 5) return std::optional<MetarWind>{};
  if (body.size() < 5) return fail(ErrorCode::Malformed, "wind is not dddff");
  std::string_view dir = body.substr(0, 3);
  if (dir == "VRB") {
    wind.variable = true;
  } else if (allDigits(dir)) {
    wind.direction_deg = toInt(dir);
    if (*wind.direction_deg > 360)
      return fail(ErrorCode::InvalidArgument, "wind direction above 360");
  } else {
    return fail(ErrorCode::Malformed, "wind direction is not three digits or VRB");
  }
  std::string_view rest = body.substr(3);
  std::size_t gustAt = rest.find('G');
  std::string_view speed = rest.substr(0, gustAt);
  if (speed.size() < 2 || speed.size() > 3 || !allDigits(speed))
    return fail(ErrorCode::Malformed, "wind speed is not two or three digits");
  wind.speed_kt = toInt(speed) * toKnots;
  if (gustAt != std::string_view::npos) {
    std::string_view gust = rest.substr(gustAt + 1);
    if (gust.size() < 2 || gust.size() > 3 || !allDigits(gust))
      return fail(ErrorCode::Malformed, "gust is not two or three digits");
    wind.gust_kt = toInt(gust) * toKnots;
  }
  return std::optional<MetarWind>{wind};
}

bool looksLikeVariableSector(std::string_view g) {
  return g.size() == 7 && g[3] == 'V' && allDigits(g.substr(0, 3)) && allDigits(g.substr(4));
}

bool isCompass(std::string_view s) {
  static constexpr std::array<std::string_view, 8> kPoints{"N", "NE", "E", "SE", "S", "SW", "W", "NW"};
  for (std::string_view p : kPoints)
    if (s == p) return true;
  return false;
}

// "3/4", "15/16": the finest fraction reported is sixteenths, so each side
// has one or two digits.
bool isMilesFraction(std::string_view v, std::size_t slash) {
  const std::string_view num = v.substr(0, slash), den = v.substr(slash + 1);
  return num.size() <= 2 && den.size() <= 2 && allDigits(num) && allDigits(den);
}

// 9999, 0800, 4000N, 0000E, 9999NDV, //// (metres); 10SM, P6SM, M1/4SM, 3/4SM.
bool isVisibility(std::string_view g) {
  if (g == "////") return true;
  if (g.size() >= 4 && allDigits(g.substr(0, 4))) {
    std::string_view rest = g.substr(4);
    return rest.empty() || rest == "NDV" || isCompass(rest);
  }
  if (!endsWith(g, "SM")) return false;
  std::string_view v = g.substr(0, g.size() - 2);
  if (!v.empty() && (v[0] == 'P' || v[0] == 'M')) v.remove_prefix(1);
  std::size_t slash = v.find('/');
  if (slash == std::string_view::npos) return allDigits(v) && v.size() <= 2;
  return isMilesFraction(v, slash);
}

// The whole-miles part of "1 1/2SM": one or two digits followed by a fraction.
bool isWholeMilesBefore(std::string_view g, std::string_view next) {
  return !g.empty() && g.size() <= 2 && allDigits(g) && endsWith(next, "SM") &&
         next.find('/') != std::string_view::npos && isVisibility(next);
}

// Runway visual range: Rdd[LCR]/..., R//////, e.g. R24/P2000N, R19R/1600V2000FT.
bool isRunwayVisualRange(std::string_view g) {
  if (g.size() < 4 || g[0] != 'R') return false;
  std::size_t slash = g.find('/');
  if (slash == std::string_view::npos) return false;
  std::string_view runway = g.substr(1, slash - 1);
  bool runwayOk = runway.empty() || runway == "//" ||
                  (runway.size() >= 2 && runway.size() <= 3 && allDigits(runway.substr(0, 2)) &&
                   (runway.size() == 2 || runway[2] == 'L' || runway[2] == 'C' || runway[2] == 'R'));
  if (!runwayOk) return false;
  std::string_view value = g.substr(slash + 1);
  if (value.empty()) return false;
  for (char c : value)
    if (!(isDigit(c) || c == '/' || c == 'P' || c == 'M' || c == 'V' || c == 'N' || c == 'U' ||
          c == 'D' || c == 'F' || c == 'T'))
      return false;
  return true;
}

// Present weather: (+|-|VC)? descriptor? phenomena*, at least one code; "//"
// is weather not observed; RE.. is recent weather, NSW no significant weather.
bool isWeather(std::string_view g) {
  if (g == "//") return true;
  static constexpr std::array<std::string_view, 22> kPhenomena{
      "DZ", "RA", "SN", "SG", "IC", "PL", "GR", "GS", "UP", "BR", "FG",
      "FU", "VA", "DU", "SA", "HZ", "PY", "PO", "SQ", "FC", "SS", "DS"};
  if (g == "NSW") return true;  // no significant weather
  std::string_view s = g;
  if (!s.empty() && (s[0] == '+' || s[0] == '-')) s.remove_prefix(1);
  else if (s.substr(0, 2) == "VC" || s.substr(0, 2) == "RE") s.remove_prefix(2);
  bool any = false;
  if (s.size() >= 2) {
    for (std::string_view d : kWeatherDescriptors)
      if (s.substr(0, 2) == d) {
        s.remove_prefix(2);
        any = true;
        break;
      }
  }
  while (s.size() >= 2) {
    bool found = false;
    for (std::string_view p : kPhenomena)
      if (s.substr(0, 2) == p) {
        found = true;
        break;
      }
    if (!found) return false;
    s.remove_prefix(2);
    any = true;
  }
  return any && s.empty();
}

bool startsCloudGroup(std::string_view g) {
  std::string_view a = g.substr(0, 3);
  if (a == "FEW" || a == "SCT" || a == "BKN" || a == "OVC") return true;
  // "///..." is a cloud group of unknown amount when 6 or more long ("////" is
  // visibility, "//" weather).
  return a == "///" && g.size() >= 6;
}

Result<MetarCloud> parseCloud(const Groups& in) {
  std::string_view g = in.peek();
  MetarCloud cloud;
  std::string_view a = g.substr(0, 3);
  if (a == "FEW") cloud.amount = CloudAmount::Few;
  else if (a == "SCT") cloud.amount = CloudAmount::Scattered;
  else if (a == "BKN") cloud.amount = CloudAmount::Broken;
  else if (a == "OVC") cloud.amount = CloudAmount::Overcast;
  else cloud.amount = CloudAmount::Unknown;
  std::string_view height = g.substr(3, 3);
  if (height.size() == 3 && allDigits(height)) {
    cloud.height_ft = toInt(height) * 100;
  } else if (height != "///") {
    return fail(ErrorCode::Malformed, "height is not three digits");
  }
  std::string_view type = g.size() > 6 ? g.substr(6) : std::string_view{};
  if (type.empty()) cloud.convective = ConvectiveCloud::None;
  else if (type == "CB") cloud.convective = ConvectiveCloud::Cumulonimbus;
  else if (type == "TCU") cloud.convective = ConvectiveCloud::ToweringCumulus;
  else if (type == "///") cloud.convective = ConvectiveCloud::Unknown;
  else return fail(ErrorCode::Malformed, "cloud type is not CB, TCU or ///");
  return cloud;
}

// M05/M07, 27/25, 15/, 15///, M01/// ; "//" for a missing value.
bool parseTemperature(std::string_view g, std::optional<int>& temperature, std::optional<int>& dewpoint) {
  std::size_t slash = g.find('/');
  if (slash == std::string_view::npos || slash == 0) return false;
  auto value = [](std::string_view s, std::optional<int>& v) {
    if (s.empty() || s == "//") return true;
    bool minus = s[0] == 'M';
    if (minus) s.remove_prefix(1);
    if (s.size() != 2 || !allDigits(s)) return false;
    v = minus ? -toInt(s) : toInt(s);
    return true;
  };
  std::optional<int> t, d;
  std::string_view left = g.substr(0, slash);
  if (left.empty() || !value(left, t) || !value(g.substr(slash + 1), d)) return false;
  temperature = t;
  dewpoint = d;
  return true;
}

bool isPressure(std::string_view g) {
  return g.size() == 5 && (g[0] == 'Q' || g[0] == 'A') &&
         (allDigits(g.substr(1)) || g.substr(1) == "////");
}

void parsePressure(std::string_view g, MetarReport& out) {
  if (!allDigits(g.substr(1))) return;
  double v = toInt(g.substr(1));
  out.qnh_hPa = g[0] == 'Q' ? v : v / 100.0 * kHpaPerInHg;
}

// Groups that may stand before the station and be skipped.
constexpr std::size_t kMaxGroupsBeforeStation = 3;

// Digits and a Z: a time group, maybe a malformed one (1212Z).
bool isTimeGroup(std::string_view t) {
  return t.size() >= 5 && t.back() == 'Z' && allDigits(t.substr(0, t.size() - 1));
}

// Reads a wind group at the current position into out.wind, and a variable
// sector after it; a wind group that does not parse is skipped.
void readWind(Groups& in, MetarReport& out) {
  auto wind = parseWind(in);
  if (!wind) {
    in.skip(out, wind.error().detail);
    in.advance();
    return;
  }
  out.wind = *wind;
  in.advance();
  if (in.done() || !looksLikeVariableSector(in.peek())) return;
  const int from = toInt(in.peek().substr(0, 3));
  const int to = toInt(in.peek().substr(4, 3));
  if (from > 360 || to > 360) {
    in.skip(out, "variable sector direction above 360");
  } else if (out.wind) {
    out.wind->variableFrom_deg = from;
    out.wind->variableTo_deg = to;
  }
  in.advance();
}

// Header: [METAR|SPECI] [COR] CCCC [DDHHMMZ] [NIL] [AUTO|COR]* [wind [dddVddd]].
// Only the station is required; a bad time or wind is skipped.
Result<void> parseHeader(Groups& in, MetarReport& out) {
  if (in.peek() == "METAR" || in.peek() == "SPECI") {
    out.speci = in.peek() == "SPECI";
    in.advance();
  }
  if (in.peek() == "COR") {
    out.corrected = true;
    in.advance();
  }
  if (in.done()) return in.error(ErrorCode::Malformed, "no station");
  // Something before the station ("METAR:", a bulletin's date line "2018/09/14
  // 12:35"): skipped when a station and its time follow within a few groups.
  if (!isStation(in.peek()))
    for (std::size_t ahead = 1; ahead <= kMaxGroupsBeforeStation; ++ahead)
      if (isStation(in.peek(ahead)) && isTimeGroup(in.peek(ahead + 1))) {
        for (std::size_t k = 0; k < ahead; ++k) {
          in.skip(out, "not a station, before the station");
          in.advance();
        }
        break;
      }
  if (!isStation(in.peek()))
    return in.error(ErrorCode::Malformed, "station is not a four-character ICAO code");
  out.icao = std::string(in.peek());
  in.advance();
  if (!in.done() && isTimeGroup(in.peek())) {
    auto time = parseTime(in);
    if (time) out.time = *time;
    else in.skip(out, time.error().detail);
    in.advance();
  }
  if (in.peek() == "NIL") {
    out.nil = true;
    in.advance();
    // A missing report: whatever follows is not an observation.
    while (!in.done()) {
      in.skip(out, "group after NIL");
      in.advance();
    }
    return {};
  }
  while (in.peek() == "AUTO" || in.peek() == "COR" || in.peek() == "RTD") {
    if (in.peek() == "AUTO") out.automatic = true;
    if (in.peek() == "COR") out.corrected = true;
    in.advance();
  }
  if (!in.done() && looksLikeWind(in.peek())) readWind(in, out);
  return {};
}

// A fraction or whole number of statute miles written apart from its unit:
// "1/4 SM", "2 SM".
bool isMilesBeforeUnit(std::string_view g, std::string_view next) {
  if (next != "SM") return false;
  std::string_view v = g;
  if (!v.empty() && (v[0] == 'P' || v[0] == 'M')) v.remove_prefix(1);
  const std::size_t slash = v.find('/');
  if (slash == std::string_view::npos) return v.size() <= 2 && allDigits(v);
  return isMilesFraction(v, slash);
}

constexpr double kMetresPerStatuteMile = 1609.344;
// 9999 means 10 km or more (WMO FM 15).
constexpr double kMetarMaxVisibility_m = 10000;

// Miles of "10", "3/4", "P6", "M1/4" (the caller checked the shape); nullopt
// for a zero denominator.
std::optional<double> milesOf(std::string_view v, bool& above, bool& below) {
  above = !v.empty() && v[0] == 'P';
  below = !v.empty() && v[0] == 'M';
  if (above || below) v.remove_prefix(1);
  const std::size_t slash = v.find('/');
  double miles = -1;
  if (slash == std::string_view::npos) {
    if (!v.empty()) miles = toInt(v);
  } else if (slash > 0 && toInt(v.substr(slash + 1)) > 0) {
    miles = double(toInt(v.substr(0, slash))) / toInt(v.substr(slash + 1));
  }
  if (miles < 0) return std::nullopt;
  return miles;
}

// The prevailing visibility of the first visibility group: g (and the whole
// miles before it, if any), "SM" already stripped when `miles`.
void keepVisibility(MetarReport& out, std::string_view g, bool miles, int wholeMiles) {
  if (out.visibility_m || out.visibilityAbove) return;  // a later group is a sector's minimum
  if (g == "////") return;
  bool above = false, below = false;
  if (miles) {
    const std::optional<double> m = milesOf(g, above, below);
    if (!m) return;
    out.visibility_m = (wholeMiles + *m) * kMetresPerStatuteMile;
  } else {
    const int metres = toInt(g.substr(0, 4));
    above = metres >= 9999;
    out.visibility_m = above ? kMetarMaxVisibility_m : metres;
  }
  out.visibilityAbove = above;
  out.visibilityBelow = below;
}

bool sameCloud(const MetarCloud& a, const MetarCloud& b) {
  return a.amount == b.amount && a.height_ft == b.height_ft && a.convective == b.convective;
}

// Body: visibility, RVR, weather, sky and temperature groups in any order, up
// to the pressure, a trend or remarks. A group that fits nothing is skipped.
void parseBody(Groups& in, MetarReport& out) {
  // Position of the last cloud group read, for a cloud type written apart.
  std::size_t lastCloudAt = 0;
  while (!in.done()) {
    const std::string_view g = in.peek();
    if (isTrendOrRemarks(g)) return;
    if (isPressure(g)) {
      parsePressure(g, out);
      return;  // what follows the pressure is supplementary
    }
    if (g == "CAVOK") {
      out.cavok = true;
      out.visibility_m = kMetarMaxVisibility_m;
      out.visibilityAbove = true;
    } else if (g == "NSC" || g == "NCD" || g == "SKC" || g == "CLR") {
      out.noCloud = g == "NSC"   ? NoCloud::NSC
                    : g == "NCD" ? NoCloud::NCD
                    : g == "SKC" ? NoCloud::SKC
                                 : NoCloud::CLR;
    } else if (startsCloudGroup(g)) {
      auto cloud = parseCloud(in);
      if (!cloud) {
        in.skip(out, cloud.error().detail);
      } else if (std::any_of(out.clouds.begin(), out.clouds.end(),
                             [&](const MetarCloud& c) { return sameCloud(c, *cloud); })) {
        in.skip(out, "repeats an earlier cloud group");
      } else {
        out.clouds.push_back(*cloud);
        lastCloudAt = in.position();
      }
    } else if ((g == "CB" || g == "TCU") && lastCloudAt + 1 == in.position() &&
               out.clouds.back().convective == ConvectiveCloud::None && out.clouds.back().height_ft) {
      // "FEW050 CB": the type written apart from its cloud group.
      out.clouds.back().convective = g == "CB" ? ConvectiveCloud::Cumulonimbus : ConvectiveCloud::ToweringCumulus;
      in.join(out, 0, "cloud type of the group before");
    } else if (g.substr(0, 2) == "VV") {
      const std::string_view h = g.substr(2);
      if (h == "///") {
        out.verticalVisibility = true;
        out.verticalVisibility_ft.reset();
      } else if (h.size() == 3 && allDigits(h)) {
        out.verticalVisibility = true;
        out.verticalVisibility_ft = toInt(h) * 100;
      } else {
        in.skip(out, "vertical visibility is not three digits");
      }
    } else if (isWholeMilesBefore(g, in.peek(1))) {
      // "1 1/2SM": the whole miles, then the fraction with its unit.
      const std::string_view fraction = in.peek(1);
      keepVisibility(out, fraction.substr(0, fraction.size() - 2), true, toInt(g));
      in.advance();
    } else if (allDigits(g) && g.size() <= 2 && isMilesBeforeUnit(in.peek(1), in.peek(2)) &&
               in.peek(1).find('/') != std::string_view::npos) {
      // "1 1/4 SM": whole miles, the fraction and the unit apart.
      keepVisibility(out, in.peek(1), true, toInt(g));
      in.join(out, 1, "fraction of the visibility before");
      in.join(out, 2, "unit of the visibility before");
      in.advance(2);
    } else if (isMilesBeforeUnit(g, in.peek(1))) {
      keepVisibility(out, g, true, 0);
      in.join(out, 1, "unit of the visibility before");
      in.advance();
    } else if (isVisibility(g)) {
      const bool miles = endsWith(g, "SM");
      keepVisibility(out, miles ? g.substr(0, g.size() - 2) : g, miles, 0);
    } else if (isWeather(g)) {
      if (g != "//" && g.substr(0, 2) != "RE" && out.weather.size() < kMaxNotedGroups)
        out.weather.emplace_back(g.substr(0, kMaxNotedGroupBytes));
    } else if (isRunwayVisualRange(g) || g == "$") {
      // recognised, not used by the mapping ("$": the station needs maintenance)
    } else if (g == "WS" && (in.peek(1).substr(0, 1) == "R" || in.peek(1) == "ALL")) {
      // Wind shear on a runway ("WS R27", "WS ALL RWY"): supplementary.
      in.join(out, 1, "runway of the wind shear before");
      in.advance();
      if (in.peek() == "ALL" && in.peek(1) == "RWY") {
        in.join(out, 1, "runway of the wind shear before");
        in.advance();
      }
    } else if (std::optional<int> t, d; parseTemperature(g, t, d)) {
      if (out.temperature_degC || out.dewpoint_degC) {
        in.skip(out, "second temperature group");
      } else {
        out.temperature_degC = t;
        out.dewpoint_degC = d;
      }
    } else if (looksLikeWind(g)) {
      if (out.wind) {
        in.skip(out, "second wind group");
      } else {
        readWind(in, out);  // a wind out of its place is still the wind
        continue;
      }
    } else if (g == "CB" || g == "TCU") {
      in.skip(out, "cloud type without amount and height");
    } else {
      in.skip(out, "unrecognised group");
    }
    in.advance();
  }
}

}  // namespace

Result<MetarReport> parseMetar(std::string_view report) {
  // Capitals: a report typed or pasted in lower case is the same report.
  std::string text(report);
  for (char& c : text)
    if (c >= 'a' && c <= 'z') c = static_cast<char>(c - 'a' + 'A');
  Groups in(splitGroups(text), text, report);
  if (in.done()) return fail(ErrorCode::Malformed, "empty report");
  MetarReport out;
  if (auto header = parseHeader(in, out); !header) return tl::unexpected(header.error());
  if (!out.nil) parseBody(in, out);
  return out;
}

}  // namespace sky::server
