// Recorded flights: a time series of geodetic poses, read from text the
// caller hands in (protocol/ opens no files), and sampled at any time.
// Readers: CSV (our own format, with attitude), ADS-B CSV (OpenSky state
// vectors and similar exports), readsb/tar1090 trace JSON, IGC (FAI glider
// loggers), GPX (XML tracks), KML/KMZ (flight trackers' exports) and
// X-Plane FDR; our CSV carries attitude, FDR pitch and roll, and
// deriveAttitude fills the rest from the track.
#pragma once

#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "sky/core/result.hpp"
#include "sky/geo/geodetic.hpp"

namespace sky::flight {

struct Fix {
  double time_s = 0;  // seconds from the start of the record, strictly increasing
  geo::GeodeticPose pose;
};

struct Flight {
  std::vector<Fix> fixes;  // at least two
  // UTC of time_s == 0 in seconds since 1970-01-01T00:00:00Z, when the record
  // says (IGC with a date header, GPX); lets a replay send the recorded date.
  std::optional<std::int64_t> startUtc_s;
  double duration_s() const { return fixes.empty() ? 0 : fixes.back().time_s - fixes.front().time_s; }
};

// Widths of the centred windows deriveAttitude fits the turn and climb rates
// over (attitude.cpp says why). A logger's own track (IGC, GPX, X-Plane's
// DATA rows): fixes on time and a few metres apart, so a turn's roll-in
// stays within a few seconds. An ADS-B track (ADS-B CSV, readsb, flight
// trackers' KML): 10 m of position noise and positions up to 0.5 s off
// their time stamps, which a narrower window turns into a shaking bank.
inline constexpr double kLoggerRateWindow_s = 10.0;
inline constexpr double kAdsbRateWindow_s = 30.0;

// What a reader returns: the flight plus what it chose to skip or assume,
// one human line each ("a.igc:37: field 'validity': 'V' ... fix skipped").
// It is a Flight (public base) so that code wanting only the fixes can take it
// as one; the warnings are for the main to log.
struct ParsedFlight : Flight {
  std::vector<std::string> warnings;
  // Where the altitudes came from, for a replay's report, when the format
  // has more than one kind (ADS-B: geometric or barometric); empty otherwise.
  // E.g. "geometric ('geoaltitude', m) for 118 fixes; barometric
  // ('baroaltitude', m) to geometric by the ICAO standard atmosphere for 2".
  std::string altitudeSource;
  std::size_t geometricAltitudeFixes = 0;   // fixes whose altitude was recorded as geometric
  std::size_t barometricAltitudeFixes = 0;  // fixes whose altitude was converted from barometric
  // The file's line of each fix (fixLines[i] for fixes[i]) when the reader
  // knows it, for the cleaning's report (clean.hpp); empty otherwise.
  std::vector<std::size_t> fixLines;
  // Whether deriveAttitude filled the attitude (the file records none), so
  // that the cleaning derives it again from the fixes it keeps.
  bool attitudeFromTrack = false;
  // The rate window deriveAttitude took for this format, which the cleaning
  // takes again.
  double attitudeRateWindow_s = kLoggerRateWindow_s;
  // Who flew it, when the file says ("icao24 3c6444, callsign DLH9U"), for
  // skyshell-replay --info; empty otherwise.
  std::string aircraft;
};

// Unit of the altitude columns of an ADS-B CSV.
enum class AltitudeUnit {
  FromColumnName,  // as the column's name says ('baroaltitude': m, 'altitude_ft': ft, ...)
  Metres,
  Feet,
};

// What the caller of a reader may choose; the defaults suit a file that
// holds one aircraft and names its altitude units.
struct ReadOptions {
  // ADS-B CSV: the aircraft to read, as its ICAO 24-bit address in hex (1 to
  // 6 digits, any letter case); empty: the file must hold one aircraft.
  std::string icao24;
  // ADS-B CSV: the unit of every altitude column; FromColumnName: each
  // column's name says, and a name that does not ('altitude') is an error.
  AltitudeUnit altitudeUnit = AltitudeUnit::FromColumnName;
  // KML/KMZ: the track to read, by its name as the error listing the
  // file's tracks shows it (a Placemark's <name>); empty: the file must hold
  // one track.
  std::string track;
};

// Fixes dropped or kept with a warning, shared by the IGC and GPX readers
// (CSV is our own format and stays strict: every anomaly is an error):
//  * time not after the previous kept fix (out of order) ... skipped, warning
//  * time equal to the previous kept fix (duplicate) ....... skipped, warning
//  * gap of more than kGapWarning_s after the previous fix .. kept, warning
//    (sample() interpolates straight across it; deriveAttitude does not
//    differentiate across it)
// At most kMaxWarningsPerKind warnings of one kind name their line; one more
// says how many were not listed, so a long bad stretch cannot flood a log.
// Loggers record every 1-20 s; a minute without a fix means the signal or
// the power was lost, and a straight line across it is a guess.
inline constexpr double kGapWarning_s = 60.0;
inline constexpr std::size_t kMaxWarningsPerKind = 8;

// CSV flight: a header line naming the columns
//   time_s,lat_deg,lon_deg,alt_m,yaw_deg,pitch_deg,roll_deg
// (altitude MSL; yaw = true heading; pitch nose-up +; roll right-wing-down +),
// then one fix per line. Blank lines and lines starting with '#' are ignored.
// Errors name the source, line and field: "climb.csv:7: field 'lat_deg': ...".
// Ill-formed UTF-8 anywhere in the text is an error naming line and byte.
// Never warns; startUtc_s stays empty.
Result<ParsedFlight> parseCsv(std::string_view text, std::string_view sourceName);

// ADS-B CSV flight (OpenSky state vectors, and exports with the same column
// names): a header line naming the columns, in any order and letter case,
// then one row per position report. Columns are found by name:
//   time: 'time', 'timestamp' (Unix seconds, or ISO 8601 UTC
//         'YYYY-MM-DD[T ]hh:mm:ss[.f][Z]')                     required
//   latitude: 'lat', 'latitude'; longitude: 'lon', 'longitude' (deg) required
//   barometric altitude: 'baroaltitude', 'baro_altitude' (m), 'altitude'
//         (unit not named: needs ReadOptions::altitudeUnit), 'altitude_ft',
//         'baroaltitude_ft', 'alt_baro' (ft), 'altitude_m' (m)
//   geometric altitude: 'geoaltitude', 'geo_altitude' (m), 'geoaltitude_ft',
//         'alt_geom' (ft)                            at least one altitude
//   'icao24', 'callsign', 'onground' (true/false/1/0); 'velocity',
//   'groundspeed', 'heading', 'track', 'vertrate', 'vertical_rate' are
//   recognised and not read: attitude comes from the track (deriveAttitude).
// Altitude: geometric when the row has it, else barometric (pressure
// altitude) converted to geometric by the ICAO standard atmosphere
// (sky/weather/standard_atmosphere.hpp, QNH 1013.25); ParsedFlight says
// which. The altitude "ground" (readsb) without a geometric altitude, or
// onground true with neither altitude (OpenSky): on the ground at an unknown
// height, row skipped. Blank lines and lines starting with '#' are ignored;
// fields may be in double quotes.
// Rows skipped with a counted warning naming the line: an empty field
// ('', 'nan', 'null'; OpenSky leaves unknown positions empty) among time,
// lat, lon, altitude; on the ground without a geometric altitude; and the
// shared time rules above. Rows of another aircraft than options.icao24 are
// ignored. Errors (file, line and field): a header without time, lat, lon
// or an altitude; a value that is not a number or out of range (lat
// [-90, 90], lon [-180, 180], altitudes [-1, 20] km baro and [-1, 100] km
// geometric); a line over kMaxAdsbLineBytes; more than kMaxAdsbRows rows or
// kMaxAdsbAircraft aircraft; several aircraft and no options.icao24 (the
// message lists each: icao24, callsign, fixes); options.icao24 absent from
// the file; fewer than two fixes.
// time_s is 0 at the whole second at or before the first kept fix;
// startUtc_s is that second.
Result<ParsedFlight> parseAdsbCsv(std::string_view text, std::string_view sourceName,
                                  const ReadOptions& options = {});
// Longest line, data rows and distinct aircraft parseAdsbCsv reads. An
// OpenSky row is ~150 bytes; a day of one aircraft at 1 Hz is 86400 rows;
// an hour of OpenSky over Europe holds a few thousand aircraft.
inline constexpr std::size_t kMaxAdsbLineBytes = 4096;
inline constexpr std::size_t kMaxAdsbRows = 10'000'000;
inline constexpr std::size_t kMaxAdsbAircraft = 20'000;

// Whether a header line names the columns of an ADS-B CSV (a time, a
// latitude and a longitude column by the names above), not of our own CSV.
// A line longer than kMaxAdsbLineBytes is not.
bool isAdsbCsvHeader(std::string_view headerLine);

// readsb / tar1090 trace (trace_full_<icao>.json, trace_recent_<icao>.json,
// as readsb writes them: gzip-compressed or plain JSON; readsb's
// README-json.md, "trace"): an object with "icao" (hex, '~' for non-ICAO
// addresses), "timestamp" (Unix s, the base) and "trace", an array of rows
//   [offset_s, lat, lon, altitude, ground speed kt, track deg, flags,
//    vertical rate fpm, details or null, source type, alt_geom, ...]
// of which the reader uses offset (s after timestamp), lat and lon (deg),
// altitude (ft: barometric, or geometric when flags bit 3 (8) is set;
// "ground"; or null), flags and alt_geom (ft, geometric; optional, as is
// every element after the fourth). Other keys and elements are ignored.
// Altitude: geometric (alt_geom, or column 3 with flags bit 3) when the row
// has it, else barometric converted by the ICAO standard atmosphere (QNH
// 1013.25) as for the ADS-B CSV; ParsedFlight says which.
// Fixes skipped with a counted warning naming the row ("trace[12]"): a null
// lat or lon; no altitude (null); "ground" without a geometric altitude;
// flags bit 0 (1, a stale position: the last one repeated); and the shared
// time rules above. A row with flags bit 1 (2, a new leg: a landing and
// take-off or a long gap lies before it) is kept with a warning.
// Errors name the source and the JSON path and field ("a.json: JSON
// '/trace/7/1' (lat): 91.2 is outside [-90, 90]"): not JSON, or nested
// deeper than 16; no numeric "timestamp" or no "trace" array; a row that is
// not an array of at least 4 elements; a value of the wrong type or out of
// range (lat [-90, 90], lon [-180, 180], altitudes as for the ADS-B CSV,
// offset within 1e7 s); options.icao24 not the file's "icao"; more than
// kMaxReadsbTraceBytes (before or after gzip) or kMaxReadsbTraceRows rows;
// fewer than two fixes.
// time_s is 0 at the whole second at or before the first kept fix;
// startUtc_s is that second. Attitude is derived by deriveAttitude.
Result<ParsedFlight> parseReadsbTrace(std::string_view bytes, std::string_view sourceName,
                                      const ReadOptions& options = {});
// Largest trace parseReadsbTrace reads (bytes, after gzip) and most rows. A
// day of one aircraft is a few MB and some 20 000 rows (readsb writes a
// row every few seconds while something changes); the JSON tree in memory
// is some ten times the text.
inline constexpr std::size_t kMaxReadsbTraceBytes = std::size_t{64} << 20;
inline constexpr std::size_t kMaxReadsbTraceRows = 1'000'000;

// IGC flight (FAI Technical Specification for IGC-approved flight recorders,
// Appendix A): one record per line, any line ending, bytes beyond ASCII
// allowed in records we do not read.
//  * Date: the first HFDTE record, as 'HFDTEDDMMYY' or 'HFDTEDATE:DDMMYY,NN'
//    (YY < 80 is 20YY, else 19YY). Missing or unreadable: warning, and
//    startUtc_s stays empty.
//  * I record: extension byte ranges in B records. LAD/LOD (extra digit of
//    decimal minutes) refine the position when present; every other extension
//    is skipped. An unreadable I record: warning, extensions ignored.
//  * B records: HHMMSS DDMMmmm[NS] DDDMMmmm[EW] [AV] PPPPP GGGGG (UTC time,
//    latitude, longitude, validity, pressure altitude ISA, GNSS altitude, m).
//    Altitude: GNSS if non-zero, else pressure (warning once, at the first
//    such fix). Times that fall back by more than 12 h are a crossing of
//    midnight UTC: a day is added.
// Anomalies (besides the time rules above), each skipped with a warning
// naming line and field, never fatal:
//  * validity 'V' (2D or no GNSS fix) ...................... fix skipped
//  * pressure and GNSS altitude both 0 (no altitude) ........ fix skipped
//  * a B record that does not parse (short, non-digit, minutes >= 60,
//    latitude > 90, bad hemisphere) ......................... line skipped
//  * a line that is not a record (first byte not 'A'-'Z') .. line skipped
// Records of other types (A, G, L, C, E, F, K, ...) are ignored silently.
// Fails (Malformed) only with fewer than two usable fixes.
// Altitudes are taken as they are written (GNSS: ellipsoid or geoid per the
// logger's HFALG, pressure: ISA); no geoid model is applied.
// time_s is 0 at the first kept fix; startUtc_s is that fix's UTC.
// Attitude is derived by deriveAttitude.
Result<ParsedFlight> parseIgc(std::string_view text, std::string_view sourceName);

// GPX 1.0/1.1 track: every <trk>/<trkseg>/<trkpt lat=".." lon=".."> in
// document order, each with <ele> (m) and <time> (ISO 8601 with 'Z' or a
// +hh:mm offset, optional fractional seconds). Namespace prefixes are ignored;
// waypoints and routes are not part of a flight and are ignored.
// A track point that lacks lat, lon, ele or time, or whose value does not
// parse or is out of range, is an error (InvalidArgument / Malformed) naming
// source, line and field: "a.gpx:12: field 'lat': 'x' is not a number".
// Malformed XML is an error naming the line (expat's message). Time order:
// the shared rules above (skipped or kept with a warning).
// time_s is 0 at the whole second at or before the first kept point;
// startUtc_s is that second. Attitude is derived by deriveAttitude.
Result<ParsedFlight> parseGpx(std::string_view text, std::string_view sourceName);

// KML 2.2 track (OGC KML 2.2 with Google's gx: extension, as FlightAware
// and Flightradar24 export flights). Candidate tracks, in document order:
//  * each <gx:Track> in a <Placemark> (also inside <gx:MultiTrack>): its
//    <when> (ISO 8601 with 'Z' or an offset) and <gx:coord> ("lon lat alt",
//    degrees and metres) pair up one to one, in order; named by the
//    Placemark's <name> ("track N" when it has none; " (part K)" added
//    when one Placemark holds several);
//  * the Placemarks of one <Folder> that each hold a <Point> with
//    <coordinates> "lon,lat,alt" and a <TimeStamp><when> (Flightradar24's
//    points): one track named "<folder name> (time-stamped points)".
// A Point without a TimeStamp (an airport marker) is ignored; a LineString
// has no times and is not a track: a file with LineStrings and no track is
// an error saying it has a path but no times. One candidate is read; with
// several, options.track picks one by name, and without it the error lists
// them ('name' (N points)). Namespace prefixes are ignored.
// altitudeMode must be 'absolute' (m above sea level, taken as the
// ellipsoid height as for GPX: no geoid model); any other mode is an error
// (heights above the ground need terrain); none at all is read as absolute
// with a warning (KML's default, clampToGround, would drop the altitude).
// Errors name source, XML line and field ("a.kml:31: field 'gx:coord':
// ..."): malformed XML (expat's message); a time or position that does not
// parse or is out of range (lat [-90, 90], lon [-180, 180], alt [-1000,
// 1e6] m); a gx:Track whose <when> and <gx:coord> counts differ; more than
// kMaxKmlBytes, kMaxKmlTracks tracks or kMaxKmlPoints points in all; fewer
// than two usable points in the chosen track. The shared time rules above
// apply to the chosen track (line of each <when>).
// time_s is 0 at the whole second at or before the first kept point;
// startUtc_s is that second. Attitude is derived by deriveAttitude.
Result<ParsedFlight> parseKml(std::string_view text, std::string_view sourceName, const ReadOptions& options = {});
// KMZ: a zip archive holding doc.kml (any letter case, at its top), else
// its first *.kml entry, read from memory and parsed by parseKml (messages
// name "a.kmz (doc.kml)"). Stored and deflate entries are read; ZIP64,
// encrypted and other methods are errors, as are more than kMaxKmzEntries
// entries, an entry over kMaxKmlBytes once decompressed (checked while
// inflating, so a zip bomb stops there), and a CRC-32 mismatch.
Result<ParsedFlight> parseKmz(std::string_view bytes, std::string_view sourceName, const ReadOptions& options = {});
// Largest KML read (bytes, after unzipping), most candidate tracks and most
// points in all of them. A FlightAware KML of a long-haul flight is about
// 1 MB with a few thousand points; an ADS-B day at 1 Hz is 86 400 points.
inline constexpr std::size_t kMaxKmlBytes = std::size_t{256} << 20;
inline constexpr std::size_t kMaxKmlTracks = 10'000;
inline constexpr std::size_t kMaxKmlPoints = 5'000'000;
// Most entries in a KMZ's zip (a KMZ holds doc.kml and a few images).
inline constexpr std::size_t kMaxKmzEntries = 10'000;

// X-Plane flight data recorder file (.fdr, text), versions 1 to 4. Sources:
// X-Plane's "Creating FDR Files" (x-plane.com/kb/creating-fdr-files) for
// the header rows; X-Plane's rule for version 4 rows as restated in the
// header comment of the fdr module of a Rust FDR writer (crate "hangar")
// and as written by 42fdr (github.com/MadReasonable/42fdr).
// Layout: a line 'A' or 'I' (the writer's line ending), a line with the
// version (1-4), then rows "KEY, values": DATE (MM/DD/YY or MM/DD/YYYY, the
// US order X-Plane's files use) and TIME (zulu hh:mm:ss) are read; ACFT,
// TAIL, PRES, TEMP, WIND, CALI, WARN, TEXT, MARK, EVNT, COMM, DREF and any
// other four-capital key are skipped ("//" starts a comment anywhere).
// Data rows:
//  * version 4: bare CSV rows whose first 7 columns are zulu time
//    (hh:mm:ss[.f], or seconds), longitude, latitude (deg), altitude (ft
//    MSL), magnetic heading, pitch (nose up +), roll (right wing down +)
//    (deg); DREF columns after them are not read;
//  * "DATA, ..." rows (versions 1-3, also accepted in 4): time (s),
//    temperature, longitude, latitude, altitude (ft MSL), ...; only those
//    columns are read: the attitude columns of X-Plane's DATA table could
//    not be confirmed offline, so a DATA row's attitude is derived.
// Attitude: pitch and roll from version 4 rows as the file gives them;
// yaw always from the track (deriveAttitude's heading), because the file's
// heading is magnetic and no magnetic model is at hand; with DATA rows all
// three come from the track. Altitude is the file's MSL altitude (no
// barometric conversion: PRES, the sea-level pressure, is not needed).
// Skipped with a warning: an unreadable DATE or TIME (no start date); in a
// version 1-3 file, a line that is neither a key row nor a DATA row; the
// shared time rules above. Zulu times that fall back by more than 12 h
// cross midnight (a day added). Errors naming source, line and field: no
// 'A'/'I' line or a version other than 1-4; a data row with too few columns
// or a value that is not a number or out of range (lat [-90, 90], lon
// [-180, 180], altitude -1 to 100 km, pitch [-90, 90], roll [-180, 180],
// heading [-360, 360]); rows mixing zulu times and seconds; a line over
// kMaxFdrLineBytes; more than kMaxFdrRows data rows; fewer than two fixes.
// time_s is 0 at the whole zulu second at or before the first kept row (at
// the first row when no zulu time is known); startUtc_s needs DATE and a
// zulu time (hh:mm:ss rows, or TIME plus the rows' seconds).
Result<ParsedFlight> parseFdr(std::string_view text, std::string_view sourceName);
// Longest line and most data rows parseFdr reads. A row with a few dozen
// DREF columns is under 2 KB; a 10 h flight at 10 Hz is 360 000 rows.
inline constexpr std::size_t kMaxFdrLineBytes = 65536;
inline constexpr std::size_t kMaxFdrRows = 10'000'000;

// FlightGear recordings (.fgtape) are not read. FlightGear's
// docs-mini/README-recordings.md (FlightGear/flightgear) describes the
// container (a magic string, the Meta and Config property trees, then
// frames of a time and a signals blob; Normal tapes inside SimGear's
// gzContainer stream, Continuous ones with per-frame flags and optional
// compression), but not the signals blob itself: the order of the value
// kinds, how bools are packed, the byte order (the writing machine's) and
// padding exist only in flightrecorder.cxx, the gzContainer framing only in
// SimGear's source, and which signal holds the position and attitude is set
// per aircraft by its flight-recorder configuration. Without a documented
// layout or a real tape to test against, a reader would be a guess.

// Any of the readers, chosen by the extension of sourceName in any letter
// case: .csv, .igc, .gpx, .json (a readsb trace), .kml, .kmz, .fdr. A .csv
// whose first line that is neither blank nor a '#' comment is an ADS-B
// header (isAdsbCsvHeader) is read by parseAdsbCsv with options, any other
// .csv by parseCsv; options also reach the readsb and KML/KMZ readers.
// Unsupported for another extension, naming it.
Result<ParsedFlight> parseFlight(std::string_view text, std::string_view sourceName,
                                 const ReadOptions& options = {});

// Text from the file is never echoed raw: a field quoted in a message shows
// only printable ASCII ('?' for other bytes, cut at 40), and the source name
// is shown with ill-formed UTF-8 replaced (utf8_text.hpp: messageText). GPX
// text that is not well-formed in its declared encoding (UTF-8 by default) is
// an XML error; IGC bytes beyond ASCII are allowed in records we do not read.

// Fills yaw, pitch and roll of every fix from the track alone:
//  * yaw: geodesic azimuth of the chord through the neighbouring fixes;
//  * pitch: climb angle atan2(climb rate, ground speed);
//  * roll: bank of a coordinated turn atan(v * omega / g) from the turn rate;
// the climb and turn rates fitted (weighted least squares) and the speed
// averaged over a centred window of rateWindow_s (kAdsbRateWindow_s for
// ADS-B tracks, so that their noise does not shake the camera; a steady
// turn's rate is exact at any width, a roll-in is spread over the width);
// yaw and roll then smoothed by a centred 5 s moving average
// (angles unwrapped first) and clamped to the limits in attitude.cpp.
// Differences never span a gap of more than kGapWarning_s. Below a ground
// speed of 2 m/s the heading is held.
// Needs fixes.size() >= 2 (a precondition, asserted).
void deriveAttitude(Flight& flight, double rateWindow_s = kLoggerRateWindow_s);

// Days from 1970-01-01 to the proleptic Gregorian date y-m-d (negative
// before), month in [1, 12], day in [1, 31]. H. Hinnant, "chrono-Compatible
// Low-Level Date Algorithms", days_from_civil.
std::int64_t daysFromCivil(std::int64_t y, unsigned m, unsigned d);

// The pose at time t (clamped to the record): position interpolated along the
// ellipsoid (ECEF lerp re-projected), attitude by quaternion slerp of the
// body's rotation in Earth-fixed axes (the shortest rotation between the two
// fixes, continuous over a pole), expressed in the local frame of the
// interpolated position.
// Yaw in [0, 360), pitch in [-90, 90], roll in (-180, 180].
geo::GeodeticPose sample(const Flight& flight, double time_s);

}  // namespace sky::flight
