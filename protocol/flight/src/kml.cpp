// KML / KMZ track reader (OGC KML 2.2 with Google's gx: extensions, as
// FlightAware and Flightradar24 export flights): expat streams the document;
// every gx:Track, and every group of time-stamped Point placemarks, is a
// candidate track; one is chosen (by name, or the only one) and the shared
// time rules applied to it. A KMZ's KML is taken from its zip in memory
// (zip.cpp). Every rule is in flight.hpp.
#include <charconv>
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
#include "zip.hpp"

namespace sky::flight {

namespace {

using detail::printable;

// A time, a gx:coord or a Point's coordinates is never longer; longer text
// is kept only this far (and then fails to parse), so a huge text node
// cannot grow a buffer.
constexpr std::size_t kMaxValueChars = 128;
// Names are shown in messages and matched against ReadOptions::track; a
// longer name is kept cut.
constexpr std::size_t kMaxNameChars = 80;
// Tracks listed by name in the "several tracks" error; the rest counted.
constexpr std::size_t kMaxListedTracks = 20;
// Same bounds as GPX: below the Dead Sea shore, above any balloon.
constexpr double kMinAlt_m = -1000.0, kMaxAlt_m = 1.0e6;

// Splits s at any of seps (runs count as one), at most max + 1 parts.
std::vector<std::string_view> split(std::string_view s, std::string_view seps, std::size_t max) {
  std::vector<std::string_view> out;
  std::size_t i = 0;
  while (i < s.size() && out.size() <= max) {
    while (i < s.size() && seps.find(s[i]) != std::string_view::npos) ++i;
    std::size_t j = i;
    while (j < s.size() && seps.find(s[j]) == std::string_view::npos) ++j;
    if (j > i) out.push_back(s.substr(i, j - i));
    i = j;
  }
  return out;
}

std::string_view localName(const XML_Char* name) {
  const std::string_view n(name);
  const auto colon = n.rfind(':');
  return colon == std::string_view::npos ? n : n.substr(colon + 1);
}

struct Point {
  double utc_s = 0;
  geo::Geodetic position;
  std::size_t line = 0;  // of its <when>
};

struct Track {
  std::string name;
  std::size_t line = 0;            // where it starts
  std::vector<Point> points;       // gx:Track: zipped at its end
  std::vector<double> whens;       // gx:Track: <when>s, in order
  std::vector<std::size_t> whenLines;
  std::vector<geo::Geodetic> coords;  // gx:Track: <gx:coord>s, in order
  bool altitudeModeMissing = true;
  bool pointGroup = false;  // a group of time-stamped Point placemarks, not a gx:Track
};

// What the Placemark being read holds so far.
struct Placemark {
  std::size_t depth = 0;
  std::string name;
  std::vector<std::size_t> tracks;  // indices of its gx:Tracks
  bool point = false;
  std::optional<geo::Geodetic> pointPosition;
  std::size_t pointLine = 0;
  std::optional<double> when;
  std::size_t whenLine = 0;
  bool pointAltitudeModeMissing = true;
};

class KmlReader {
 public:
  KmlReader(XML_Parser parser, std::string_view source) : parser_(parser), warnings_(source) {}

  static void XMLCALL onStart(void* self, const XML_Char* name, const XML_Char**) {
    static_cast<KmlReader*>(self)->start(localName(name));
  }
  static void XMLCALL onEnd(void* self, const XML_Char*) { static_cast<KmlReader*>(self)->end(); }
  static void XMLCALL onText(void* self, const XML_Char* s, int len) {
    auto* r = static_cast<KmlReader*>(self);
    if (r->text_ && r->text_->size() <= r->textCap_)
      r->text_->append(s, std::min(static_cast<std::size_t>(len), r->textCap_ + 1 - r->text_->size()));
  }

  std::optional<Error> error;
  std::vector<Track> tracks;
  std::size_t lineStrings = 0;  // LineString placemarks (paths without times)
  detail::Warnings& warnings() { return warnings_; }

 private:
  enum class Capture { None, PlacemarkName, FolderName, TrackWhen, TrackCoord, AltitudeMode, PointCoordinates,
                       StampWhen };

  std::size_t line() const { return static_cast<std::size_t>(XML_GetCurrentLineNumber(parser_)); }

  void stop(ErrorCode code, std::size_t line, const std::string& what) {
    if (error) return;
    error = Error{code, warnings_.source() + ":" + std::to_string(line) + ": " + what};
    XML_StopParser(parser_, XML_FALSE);
  }

  std::string_view parent(std::size_t up = 1) const {
    return stack_.size() > up ? std::string_view(stack_[stack_.size() - 1 - up]) : std::string_view();
  }

  void capture(Capture what, std::size_t cap) {
    capture_ = what;
    captured_.clear();
    text_ = &captured_;
    textCap_ = cap;
    captureLine_ = line();
  }

  void start(std::string_view name) {
    stack_.emplace_back(name);
    text_ = nullptr;  // character data counts only directly inside a captured element
    capture_ = Capture::None;
    if (error) return;
    const std::size_t depth = stack_.size() - 1;
    const std::string_view up = parent();
    if (name == "Folder" || name == "Document") folders_.push_back({depth, {}});
    if (name == "Placemark" && !placemark_) {
      placemark_ = Placemark{};
      placemark_->depth = depth;
      return;
    }
    if (name == "name" && placemark_ && depth == placemark_->depth + 1) return capture(Capture::PlacemarkName, kMaxNameChars);
    if (name == "name" && !folders_.empty() && depth == folders_.back().first + 1)
      return capture(Capture::FolderName, kMaxNameChars);
    if (!placemark_) return;
    if (name == "Track" && !track_) {
      if (tracks.size() == kMaxKmlTracks)
        return stop(ErrorCode::TooLarge, line(), "more than " + std::to_string(kMaxKmlTracks) + " tracks");
      track_ = tracks.size();
      placemark_->tracks.push_back(tracks.size());
      tracks.push_back(Track{});
      tracks.back().line = line();
      trackDepth_ = depth;
      return;
    }
    if (track_ && depth == trackDepth_ + 1 && name == "when") return capture(Capture::TrackWhen, kMaxValueChars);
    if (track_ && depth == trackDepth_ + 1 && name == "coord") return capture(Capture::TrackCoord, kMaxValueChars);
    if (name == "altitudeMode" && (up == "Track" || up == "Point")) return capture(Capture::AltitudeMode, kMaxValueChars);
    if (name == "LineString") ++placemarkLineStrings_;
    if (name == "Point" && up == "Placemark") {
      placemark_->point = true;
      placemark_->pointLine = line();
    }
    if (name == "coordinates" && up == "Point" && parent(2) == "Placemark")
      return capture(Capture::PointCoordinates, kMaxValueChars);
    if (name == "when" && up == "TimeStamp" && parent(2) == "Placemark") return capture(Capture::StampWhen, kMaxValueChars);
  }

  // "lon lat alt" (gx:coord) or "lon,lat,alt" (coordinates) as a position.
  std::optional<geo::Geodetic> position(std::string_view text, std::string_view seps, std::string_view field,
                                        std::size_t at) {
    const auto parts = split(detail::trimSpace(text), seps, 3);
    if (parts.size() != 3) {
      stop(ErrorCode::Malformed, at, "field '" + std::string(field) + "': '" + printable(detail::trimSpace(text)) +
                                         "' is not three numbers (longitude, latitude, altitude m)");
      return std::nullopt;
    }
    const auto lon = detail::parseDecimal(parts[0]), lat = detail::parseDecimal(parts[1]), alt = detail::parseDecimal(parts[2]);
    if (!lon || !lat || !alt) {
      stop(ErrorCode::Malformed, at, "field '" + std::string(field) + "': '" + printable(detail::trimSpace(text)) +
                                         "' holds something that is not a number");
      return std::nullopt;
    }
    if (std::fabs(*lat) > 90 || std::fabs(*lon) > 180 || *alt < kMinAlt_m || *alt > kMaxAlt_m) {
      stop(ErrorCode::InvalidArgument, at, "field '" + std::string(field) + "': '" + printable(detail::trimSpace(text)) +
                                               "' is out of range (longitude [-180, 180], latitude [-90, 90], "
                                               "altitude [-1000, 1e6] m)");
      return std::nullopt;
    }
    return geo::Geodetic{*lat, *lon, *alt};
  }

  std::optional<double> time(std::string_view text, std::size_t at) {
    const auto t = detail::isoUtc_s(text);
    if (!t) stop(ErrorCode::Malformed, at, "field 'when': '" + printable(detail::trimSpace(text)) + "' is not an ISO 8601 UTC time");
    return t;
  }

  bool countPoint(std::size_t at) {
    if (++points_ <= kMaxKmlPoints) return true;
    stop(ErrorCode::TooLarge, at, "more than " + std::to_string(kMaxKmlPoints) + " points");
    return false;
  }

  // up: the element holding the <altitudeMode>.
  void altitudeMode(std::string_view mode, std::string_view up, std::size_t at) {
    mode = detail::trimSpace(mode);
    if (mode != "absolute")
      return stop(ErrorCode::Unsupported, at,
                  "field 'altitudeMode': '" + printable(mode) +
                      "': only 'absolute' (metres above sea level) can be replayed; heights above the ground "
                      "need a terrain model");
    if (up == "Track" && track_) tracks[*track_].altitudeModeMissing = false;
    if (up == "Point" && placemark_) placemark_->pointAltitudeModeMissing = false;
  }

  void end() {
    const std::size_t depth = stack_.size() - 1;
    const std::string name = std::move(stack_.back());
    stack_.pop_back();
    const Capture what = capture_;
    capture_ = Capture::None;
    text_ = nullptr;
    if (error) return;
    switch (what) {
      case Capture::PlacemarkName: placemark_->name = std::string(detail::trimSpace(captured_)); break;
      case Capture::FolderName: folders_.back().second = std::string(detail::trimSpace(captured_)); break;
      case Capture::TrackWhen:
        if (const auto t = time(captured_, captureLine_); t && countPoint(captureLine_)) {
          tracks[*track_].whens.push_back(*t);
          tracks[*track_].whenLines.push_back(captureLine_);
        }
        break;
      case Capture::TrackCoord:
        if (const auto p = position(captured_, " \t\r\n", "gx:coord", captureLine_)) tracks[*track_].coords.push_back(*p);
        break;
      case Capture::AltitudeMode: altitudeMode(captured_, stack_.empty() ? "" : stack_.back(), captureLine_); break;
      case Capture::PointCoordinates: placemark_->pointPosition = position(captured_, ", \t\r\n", "coordinates", captureLine_); break;
      case Capture::StampWhen:
        placemark_->when = time(captured_, captureLine_);
        placemark_->whenLine = captureLine_;
        break;
      case Capture::None: break;
    }
    if (error) return;
    if (track_ && depth == trackDepth_ && name == "Track") endTrack();
    if (placemark_ && depth == placemark_->depth && name == "Placemark") endPlacemark();
    if (!folders_.empty() && folders_.back().first == depth) folders_.pop_back();
  }

  void endTrack() {
    Track& t = tracks[*track_];
    if (t.whens.size() != t.coords.size())
      return stop(ErrorCode::Malformed, t.line, "gx:Track with " + std::to_string(t.whens.size()) + " <when> and " +
                                                    std::to_string(t.coords.size()) +
                                                    " <gx:coord>: they must pair up one to one");
    for (std::size_t i = 0; i < t.whens.size(); ++i) t.points.push_back(Point{t.whens[i], t.coords[i], t.whenLines[i]});
    t.whens = {};
    t.whenLines = {};
    t.coords = {};
    track_.reset();
  }

  void endPlacemark() {
    Placemark p = std::move(*placemark_);
    placemark_.reset();
    if (placemarkLineStrings_ && p.tracks.empty() && !p.when) ++lineStrings;
    placemarkLineStrings_ = 0;
    const std::string base = p.name.empty() ? std::string() : p.name;
    for (std::size_t k = 0; k < p.tracks.size(); ++k) {
      Track& t = tracks[p.tracks[k]];
      t.name = base.empty() ? "track " + std::to_string(p.tracks[k] + 1) : base;
      if (p.tracks.size() > 1) t.name += " (part " + std::to_string(k + 1) + ")";
    }
    if (!p.point || !p.pointPosition || !p.when) return;  // a marker (airport, waypoint), not a fix
    if (!countPoint(p.whenLine)) return;
    // Time-stamped points group by the folder that holds them.
    const std::string folder = folders_.empty() || folders_.back().second.empty() ? "points" : folders_.back().second;
    const std::string groupName = folder + " (time-stamped points)";
    std::size_t index = tracks.size();
    for (std::size_t i = 0; i < tracks.size(); ++i)
      if (tracks[i].pointGroup && tracks[i].name == groupName) index = i;
    if (index == tracks.size()) {
      if (tracks.size() == kMaxKmlTracks)
        return stop(ErrorCode::TooLarge, p.pointLine, "more than " + std::to_string(kMaxKmlTracks) + " tracks");
      tracks.emplace_back();
      tracks.back().name = groupName;
      tracks.back().line = p.pointLine;
      tracks.back().pointGroup = true;
    }
    Track& t = tracks[index];
    t.altitudeModeMissing = t.altitudeModeMissing && p.pointAltitudeModeMissing;
    t.points.push_back(Point{*p.when, *p.pointPosition, p.whenLine});
  }

  XML_Parser parser_;
  detail::Warnings warnings_;
  std::vector<std::string> stack_;  // local names of the open elements
  std::vector<std::pair<std::size_t, std::string>> folders_;  // open Folder/Document: depth, name
  std::optional<Placemark> placemark_;
  std::size_t placemarkLineStrings_ = 0;
  std::optional<std::size_t> track_;  // index in tracks of the open gx:Track
  std::size_t trackDepth_ = 0;
  std::size_t points_ = 0;
  Capture capture_ = Capture::None;
  std::string captured_;
  std::size_t captureLine_ = 0;
  std::string* text_ = nullptr;
  std::size_t textCap_ = 0;
};

std::string listTracks(const std::vector<const Track*>& tracks) {
  std::string out;
  for (std::size_t i = 0; i < tracks.size() && i < kMaxListedTracks; ++i)
    out += (i ? ", " : "") + std::string("'") + printable(tracks[i]->name) + "' (" +
           std::to_string(tracks[i]->points.size()) + " points)";
  if (tracks.size() > kMaxListedTracks) out += " and " + std::to_string(tracks.size() - kMaxListedTracks) + " more";
  return out;
}

}  // namespace

Result<ParsedFlight> parseKml(std::string_view text, std::string_view sourceName, const ReadOptions& options) {
  const std::string src = messageText(sourceName);
  if (text.size() > kMaxKmlBytes)
    return fail(ErrorCode::TooLarge, src + ": " + std::to_string(text.size()) + " bytes, at most " +
                                         std::to_string(kMaxKmlBytes) + " read");
  const detail::XmlParser parser(XML_ParserCreate(nullptr));
  if (!parser) return fail(ErrorCode::Io, src + ": cannot create an XML parser (out of memory)");
  KmlReader reader(parser.get(), sourceName);
  XML_SetUserData(parser.get(), &reader);
  XML_SetElementHandler(parser.get(), &KmlReader::onStart, &KmlReader::onEnd);
  XML_SetCharacterDataHandler(parser.get(), &KmlReader::onText);
  if (auto parsed = detail::parseXmlText(parser.get(), text, src, reader.error); !parsed)
    return tl::unexpected(parsed.error());

  std::vector<const Track*> candidates;
  for (const Track& t : reader.tracks)
    if (!t.points.empty()) candidates.push_back(&t);
  if (candidates.empty()) {
    if (reader.lineStrings)
      return fail(ErrorCode::Unsupported,
                  src + ": the file has a path (" + std::to_string(reader.lineStrings) +
                      " LineString placemark(s)) but no times: a flight needs a gx:Track with <when>, or "
                      "placemarks with a Point and a TimeStamp");
    return fail(ErrorCode::Malformed, src + ": no track (gx:Track, or placemarks with a Point and a TimeStamp)");
  }
  const Track* chosen = nullptr;
  if (!options.track.empty()) {
    std::size_t matches = 0;
    for (const Track* t : candidates)
      if (t->name == options.track) {
        chosen = chosen ? chosen : t;
        ++matches;
      }
    if (!chosen)
      return fail(ErrorCode::InvalidArgument, src + ": no track named '" + printable(options.track) +
                                                  "'; the file holds " + listTracks(candidates));
    if (matches > 1)
      return fail(ErrorCode::InvalidArgument, src + ": " + std::to_string(matches) + " tracks are named '" +
                                                  printable(options.track) + "'; the first is read only when the name is unique");
  } else if (candidates.size() > 1) {
    return fail(ErrorCode::InvalidArgument, src + ": " + std::to_string(candidates.size()) +
                                                " tracks in the file, pick one by its name: " + listTracks(candidates));
  } else {
    chosen = candidates.front();
  }

  detail::Warnings& warnings = reader.warnings();
  if (chosen->altitudeModeMissing)
    warnings.add(detail::WarningKind::Other, chosen->line,
                 "no altitudeMode: KML's default (clampToGround) would ignore the altitudes; they are read as "
                 "'absolute' (m above sea level)");
  detail::TimeOrder order;
  std::vector<Point> kept;
  for (const Point& p : chosen->points)
    if (order.accept(p.utc_s, p.line, warnings)) kept.push_back(p);
  if (kept.size() < 2)
    return fail(ErrorCode::Malformed, src + ": track '" + printable(chosen->name) + "' has " +
                                          std::to_string(kept.size()) + " usable points, a flight needs at least two");
  ParsedFlight flight;
  const double start_s = std::floor(kept.front().utc_s);
  flight.startUtc_s = static_cast<std::int64_t>(start_s);
  for (const Point& p : kept) {
    flight.fixes.push_back(Fix{p.utc_s - start_s, {p.position, 0, 0, 0}});
    flight.fixLines.push_back(p.line);
  }
  flight.attitudeRateWindow_s = kAdsbRateWindow_s;
  deriveAttitude(flight, flight.attitudeRateWindow_s);
  flight.attitudeFromTrack = true;
  flight.aircraft = "track '" + messageText(chosen->name, kMaxNameChars) + "'";
  flight.warnings = warnings.finish();
  return flight;
}

Result<ParsedFlight> parseKmz(std::string_view bytes, std::string_view sourceName, const ReadOptions& options) {
  const std::string src = messageText(sourceName);
  auto kml = detail::readKmlFromZip(bytes, src, kMaxKmzEntries, kMaxKmlBytes);
  if (!kml) return tl::unexpected(kml.error());
  return parseKml(kml->text, src + " (" + kml->entryName + ")", options);
}

}  // namespace sky::flight
