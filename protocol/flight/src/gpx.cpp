// GPX track reader: expat (streaming XML) hands us elements; we keep the
// track points of trk/trkseg with their ele and time. Strict on values (an
// error names line and field), shared time-order rules (flight.hpp).
#include <charconv>
#include <climits>
#include <cmath>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <expat.h>

#include "reader_common.hpp"
#include "xml_document.hpp"
#include "sky/flight/flight.hpp"
#include "sky/flight/utf8_text.hpp"

namespace sky::flight {

namespace {

using detail::isDigit;
using detail::isoUtc_s;
using detail::printable;

// A number or timestamp is never longer; longer text is kept only this far,
// so a huge text node cannot grow a buffer (and still fails to parse).
constexpr std::size_t kMaxValueChars = 64;

// Same bounds as the CSV reader: below the Dead Sea shore, above any balloon.
constexpr double kMinEle_m = -1000.0, kMaxEle_m = 1.0e6;

std::string_view localName(const XML_Char* name) {
  const std::string_view n(name);
  const auto colon = n.rfind(':');
  return colon == std::string_view::npos ? n : n.substr(colon + 1);
}

struct Point {
  std::size_t line = 0;
  double lat_deg = 0, lon_deg = 0;
  std::optional<std::string> ele, time;
  std::size_t eleLine = 0, timeLine = 0;
};

struct Kept {
  double utc_s;
  geo::Geodetic position;
  std::size_t line;  // of the <trkpt>
};

class GpxReader {
 public:
  GpxReader(XML_Parser parser, std::string_view source) : parser_(parser), warnings_(source) {}

  static void XMLCALL onStart(void* self, const XML_Char* name, const XML_Char** attrs) {
    static_cast<GpxReader*>(self)->start(localName(name), attrs);
  }
  static void XMLCALL onEnd(void* self, const XML_Char*) { static_cast<GpxReader*>(self)->end(); }
  static void XMLCALL onText(void* self, const XML_Char* s, int len) {
    auto* r = static_cast<GpxReader*>(self);
    if (r->text_ && r->text_->size() <= kMaxValueChars)
      r->text_->append(s, std::min(static_cast<std::size_t>(len), kMaxValueChars + 1 - r->text_->size()));
  }

  std::optional<Error> error;
  std::vector<Kept> kept;
  detail::Warnings& warnings() { return warnings_; }

 private:
  std::size_t line() const { return static_cast<std::size_t>(XML_GetCurrentLineNumber(parser_)); }

  void stop(ErrorCode code, std::size_t line, const std::string& what) {
    if (error) return;
    error = Error{code, warnings_.source() + ":" + std::to_string(line) + ": " + what};
    XML_StopParser(parser_, XML_FALSE);
  }

  void start(std::string_view name, const XML_Char** attrs) {
    const std::size_t depth = stack_.size();
    stack_.emplace_back(name);
    text_ = nullptr;  // character data counts only directly inside <ele>/<time>
    if (error) return;
    // A <trkpt> nested in an open one (found by fuzzing: it replaced the open
    // point while text_ still pointed into it) is not a track point.
    if (name == "trkpt" && !point_ && depth >= 2 && stack_[depth - 1] == "trkseg" && stack_[depth - 2] == "trk") {
      point_ = Point{line(), 0, 0, {}, {}, 0, 0};
      pointDepth_ = depth;
      readCoordinate(attrs, "lat", 90.0, point_->lat_deg);
      readCoordinate(attrs, "lon", 180.0, point_->lon_deg);
      return;
    }
    if (point_ && depth == pointDepth_ + 1 && (name == "ele" || name == "time")) {
      auto& slot = name == "ele" ? point_->ele : point_->time;
      (name == "ele" ? point_->eleLine : point_->timeLine) = line();
      slot.emplace();
      text_ = &*slot;
    }
  }

  void readCoordinate(const XML_Char** attrs, std::string_view field, double limit, double& out) {
    for (std::size_t i = 0; attrs[i]; i += 2) {
      if (localName(attrs[i]) != field) continue;
      const auto v = detail::parseDecimal(attrs[i + 1]);
      if (!v) {
        stop(ErrorCode::Malformed, point_->line,
             "field '" + std::string(field) + "': '" + printable(attrs[i + 1]) + "' is not a number");
      } else if (*v < -limit || *v > limit) {
        stop(ErrorCode::InvalidArgument, point_->line,
             "field '" + std::string(field) + "': " + printable(attrs[i + 1]) + " outside [-" +
                 std::to_string(static_cast<int>(limit)) + ", " + std::to_string(static_cast<int>(limit)) + "]");
      }
      out = v.value_or(0);
      return;
    }
    stop(ErrorCode::Malformed, point_->line, "field '" + std::string(field) + "': missing from <trkpt>");
  }

  void end() {
    const std::size_t depth = stack_.size() - 1;
    stack_.pop_back();
    text_ = nullptr;
    if (error || !point_ || depth != pointDepth_) return;
    const Point p = std::move(*point_);
    point_.reset();
    if (!p.ele) return stop(ErrorCode::Malformed, p.line, "field 'ele': missing from <trkpt>");
    if (!p.time) return stop(ErrorCode::Malformed, p.line, "field 'time': missing from <trkpt>");
    const auto ele = detail::parseDecimal(*p.ele);
    if (!ele) return stop(ErrorCode::Malformed, p.eleLine, "field 'ele': '" + printable(*p.ele) + "' is not a number");
    if (*ele < kMinEle_m || *ele > kMaxEle_m)
      return stop(ErrorCode::InvalidArgument, p.eleLine, "field 'ele': " + printable(*p.ele) + " m out of range");
    const auto utc = isoUtc_s(*p.time);
    if (!utc)
      return stop(ErrorCode::Malformed, p.timeLine,
                  "field 'time': '" + printable(detail::trimSpace(*p.time)) + "' is not an ISO 8601 UTC time");
    if (!order_.accept(*utc, p.line, warnings_)) return;
    kept.push_back(Kept{*utc, {p.lat_deg, p.lon_deg, *ele}, p.line});
  }

  XML_Parser parser_;
  detail::Warnings warnings_;
  detail::TimeOrder order_;
  std::vector<std::string> stack_;  // local names of the open elements
  std::optional<Point> point_;      // the <trkpt> being read
  std::size_t pointDepth_ = 0;
  std::string* text_ = nullptr;  // where character data goes (inside <ele>/<time>)
};

}  // namespace

Result<ParsedFlight> parseGpx(std::string_view text, std::string_view sourceName) {
  const std::string src = messageText(sourceName);
  const detail::XmlParser parser(XML_ParserCreate(nullptr));
  if (!parser) return fail(ErrorCode::Io, src + ": cannot create an XML parser (out of memory)");
  GpxReader reader(parser.get(), sourceName);
  XML_SetUserData(parser.get(), &reader);
  XML_SetElementHandler(parser.get(), &GpxReader::onStart, &GpxReader::onEnd);
  XML_SetCharacterDataHandler(parser.get(), &GpxReader::onText);

  if (auto parsed = detail::parseXmlText(parser.get(), text, src, reader.error); !parsed)
    return tl::unexpected(parsed.error());

  if (reader.kept.size() < 2)
    return fail(ErrorCode::Malformed, src + ": " + std::to_string(reader.kept.size()) +
                                          " usable <trkpt>, a flight needs at least two");
  ParsedFlight flight;
  const double start_s = std::floor(reader.kept.front().utc_s);
  flight.startUtc_s = static_cast<std::int64_t>(start_s);
  for (const Kept& k : reader.kept) {
    flight.fixes.push_back(Fix{k.utc_s - start_s, {k.position, 0, 0, 0}});
    flight.fixLines.push_back(k.line);
  }
  deriveAttitude(flight);
  flight.attitudeFromTrack = true;
  flight.warnings = reader.warnings().finish();
  return flight;
}

}  // namespace sky::flight
