// Side-by-side mode: one view rendered N times, one line per frame in a fixed
// format, so the cloud pass can be timed against another renderer on the same
// machine in one run (issue 7; the peer's view in lavapipe.md).
#pragma once

#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <string>

#include "sky/bench/configurations.hpp"
#include "sky/core/result.hpp"

namespace sky::bench {

struct SideBySideOptions {
  // The renderer has no terrain: the ground is the WGS84 ellipsoid, so the
  // camera's altitude is its height above ground.
  double heightAboveGround_m = 800;
  double lat_deg = 46.0, lon_deg = 13.0;
  double yaw_deg = 0, pitch_deg = 0;  // CIGI heading and pitch
  // Heading added per frame (warm-up frames included): a camera in a turn,
  // so the temporal passes are timed on a moving view, not only a still one.
  double turn_deg = 0;
  double verticalFov_deg = 60;
  double sunEast = -0.5, sunNorth = 0.5, sunUp = 1.0;  // direction towards the sun, local ENU, any length > 0
  std::uint32_t width = 640, height = 360;
  std::uint32_t frames = 10;  // printed frames
  std::uint32_t warmup = 2;   // frames before them, not printed (first use compiles)
  std::filesystem::path weatherFile;  // scenario format
  Configuration configuration;
};

struct SunAngles {
  double azimuth_deg = 0;    // clockwise from north, [0, 360)
  double elevation_deg = 0;  // [-90, 90]
};
// The sun's azimuth and elevation from a direction in local east-north-up.
// Errors: InvalidArgument for a zero or non-finite vector.
Result<SunAngles> sunAnglesFromEnu(double east, double north, double up);

// "CLOUDPASS <W>x<H> <wall_ms> cpu_ms=<x> cores=<x> max_thread_ms=<x>", no
// newline; ms with 3 decimals, cores (cpu_ms / wall_ms) with 2.
std::string cloudPassLine(std::uint32_t width, std::uint32_t height, double wall_ms, double cpu_ms,
                          double maxThread_ms);

// Renders the view warmup + frames times; prints a header line to `err`
// saying where the wall time comes from, then one CLOUDPASS line per timed
// frame to `out`. Wall time is the renderer's GPU time of its cloud passes
// when it reports one, else the fence wall time around the frame. Errors:
// the renderer's, the weather file's, InvalidArgument for bad options.
Result<void> runSideBySide(const SideBySideOptions& options, std::FILE* out, std::FILE* err);

}  // namespace sky::bench
