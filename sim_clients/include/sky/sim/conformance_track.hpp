// Conformance along a replayed flight: the weather server's check (GET
// /api/conformance: METAR stations and forecast grid points, cover in oktas
// per layer and the ceiling, as the renderers' tiles draw them against the
// reports) asked at points of the flight a headless replay drew, each at the
// weather clock its frame drew. The points come from the replay's
// frames.jsonl (skyshell-render's metadata, one JSON object a line); the
// answers are joined into one table along the flight. The server answers
// from its weather as it stands when asked, evaluated at each frame's clock
// (ramps, scheduled changes and the forecast's time as at that clock; a
// change made while the replay ran counts from the weather clock it was made
// at, as it did for the frames): asked right after a replay, the check is of
// what the server streamed.
//
// Both inputs come from outside the process (a file, a server's answer):
// every field is checked for type and range, every count is bounded, and
// text from them is reduced to safe characters before it reaches a table.
#pragma once

#include <cstddef>
#include <cstdint>
#include <istream>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include <nlohmann/json.hpp>

#include "sky/core/result.hpp"

namespace sky::sim {

// A frame of the replay: where the camera was and which weather it drew.
struct TrackPoint {
  std::uint64_t frame = 0;
  double flight_s = 0;  // the flight's time at the frame (host_time_s)
  double lat_deg = 0, lon_deg = 0, alt_m = 0;
  double weatherClock_s = 0;
};

// A frames.jsonl line longer than this is refused (a frame's metadata is
// about 2 KB; a view with many definitions stays far below).
inline constexpr std::size_t kMaxTrackLine_bytes = 1u << 20;

// One line of frames.jsonl: the fields above (frame, host_time_s, lat_deg,
// lon_deg, alt_m, weather_clock_s). Errors (InvalidArgument) name the field.
Result<TrackPoint> parseTrackLine(std::string_view line);

struct TrackSampling {
  double every_s = 30;          // flight seconds between checked points, > 0
  std::size_t maxPoints = 500;  // at most this many points (the first ones)
};

// Reads frames.jsonl and keeps the first frame and then one at least
// every_s of flight time after the last kept, in file order (a replay
// writes its frames in flight time order; a line whose time goes back is
// refused). Errors: "<name>:<line>: <what>". Memory: the kept points only.
Result<std::vector<TrackPoint>> sampleTrack(std::istream& in, const std::string& name, const TrackSampling& sampling);

struct TrackCheckOptions {
  double radius_m = 60000;     // stations and grid points within this of each point, (0, 2e7]
  std::size_t stations = 20;   // at most this many stations per point, [0, 10000]
  std::size_t gridPoints = 8;  // at most this many forecast grid points per point, [0, 2000]
};

// The API target (path and query) for one point.
std::string conformanceTarget(const TrackPoint& at, const TrackCheckOptions& options);

// A station's row in the server's answer, reduced to the table's columns.
struct StationCheck {
  std::string name;  // ICAO, else "region <id>"; letters, digits, '-' and '?' only, at most 16 bytes
  double lat_deg = 0, lon_deg = 0;
  double distance_km = 0;  // from the point
  bool ok = false;
  int oktasOff = 0;        // the largest okta difference of a layer
  std::optional<double> ceilingReported_m, ceilingDrawn_m;
  // At a pilot's eye over the station; none: 10 km or more.
  std::optional<double> visibilityReported_m, visibilityDrawn_m;
};

// The server's answer at one point.
struct PointCheck {
  TrackPoint at;
  std::vector<StationCheck> stations;  // at most the number asked
  std::size_t gridPoints = 0, gridOk = 0;
  int worstGridOktasOff = 0;
};

// The most stations a point is asked for (the API's own bound).
inline constexpr std::size_t kMaxStationsPerPoint = 10000;

// Reads an answer of GET /api/conformance (its body), keeping at most
// maxStations stations (the number asked: a server that sends more is not
// followed, so the points' rows stay within what the command line asked).
// Errors (InvalidArgument) name what is not as the API gives it.
Result<PointCheck> readPointCheck(const TrackPoint& at, std::string_view body, std::size_t maxStations);

// The checks as JSON (the points, and a summary: stations met, passes and
// failures, the worst okta and ceiling differences, grid points) and as a
// Markdown table (a row per point with a station or grid point in reach).
nlohmann::json trackJson(const std::vector<PointCheck>& checks, const TrackCheckOptions& options);
std::string trackMarkdown(const std::vector<PointCheck>& checks, const TrackCheckOptions& options);

}  // namespace sky::sim
