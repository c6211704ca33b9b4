// The bench's scene suite as data: a TOML file (deploy/bench/suite.toml, its
// format documented there) naming scenes, each a camera pose or a camera path,
// a weather file (the server's scenario format, deploy/scenarios/) and a sun.
// Parsing is pure and strict like every TOML input of ours: unknown keys,
// missing fields and values out of range are errors naming source, line and
// field. Reading the files is in suite_loader.hpp.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "sky/core/result.hpp"
#include "sky/geo/geodetic.hpp"
#include "sky/weather/lightning.hpp"

namespace sky::bench {

// Frames of one camera path: bounds a path's cost (every frame is rendered by
// every configuration) and its memory (the reference frames are kept).
inline constexpr std::uint32_t kMaxPathFrames = 600;
// Scenes per suite; a bound for the fuzzer as much as for anyone.
inline constexpr std::size_t kMaxScenes = 256;

// A camera pose at a time on the path (t_s = 0 for a still).
struct CameraKey {
  double t_s = 0;  // s from the path's start, strictly increasing along a path
  geo::GeodeticPose pose;  // CIGI pose: lat/lon deg, alt m above the ellipsoid, yaw/pitch/roll deg
};

// A change of one layer's coverage within a disc during a path: the layer
// is given tiles round the path's first pose (kChangeTiledRadius_m), all at
// its own coverage and density until t_s, from when those whose centre lies
// within the disc ramp linearly to `coverage` over ramp_s (a storm cell
// growing in view, as the server's ramps change it).
struct WeatherChange {
  double t_s = 0;                  // path time it starts, [0, 1e6]
  double ramp_s = 0;               // [0, 1e6]; 0: a step
  std::uint32_t layer = 0;         // index into the weather file's layers
  double lat_deg = 0, lon_deg = 0; // the disc's centre
  double radius_m = 0;             // (0, 100 km]
  double coverage = 0;             // [0, 1]
};
// How far round the first pose a changed layer has tiles, m: past the
// renderer's fine weather ring (100 km); beyond it the layer is empty.
inline constexpr double kChangeTiledRadius_m = 150000.0;

struct Scene {
  std::string name;         // [A-Za-z0-9_-]+, unique in the suite; names output files
  std::string description;  // one line for the report
  std::string weatherFile;  // as written: relative to the suite file unless absolute
  double verticalFov_deg = 60;                     // (0, 179)
  double sunAzimuth_deg = 0, sunElevation_deg = 0;  // local ENU at the camera: az clockwise from north [0, 360), el [-90, 90]
  std::vector<CameraKey> keys;  // one key: a still; two or more: a path
  std::uint32_t frames = 1;     // a path's frames, evenly spaced from the first key's time to the last's, [2, kMaxPathFrames]
  std::optional<WeatherChange> change;  // a path's only
  // A still's lightning flash (its time_s is the seconds before the frame's
  // clock its first stroke struck: the frame sees it that long after).
  std::optional<weather::LightningFlash> flash;

  bool isPath() const { return keys.size() > 1; }
};

struct Suite {
  std::vector<Scene> scenes;
};

// Parses suite text; sourceName goes into error details ("suite.toml:12:5:
// scene[2].camera.alt_m: ..."). Errors: Malformed (syntax, wrong type,
// unknown or missing key), InvalidArgument (a value out of range, a duplicate
// name, path keys out of order).
Result<Suite> parseSuite(std::string_view text, std::string_view sourceName);

// Time of a frame on the scene's path, s from its start (0 for a still).
// frame in [0, scene.frames).
double frameTime_s(const Scene& scene, std::uint32_t frame);

// The camera at time t_s on the path: linear in latitude, longitude (the short
// way round), altitude and each attitude angle (the short way round) between
// the two keys around t_s; clamped to the first and last key.
geo::GeodeticPose poseAt(const Scene& scene, double t_s);

}  // namespace sky::bench
