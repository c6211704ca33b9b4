// Recorded flights: a time series of geodetic poses, read from text the
// caller hands in (protocol/ opens no files), and sampled at any time.
#pragma once

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
  double duration_s() const { return fixes.empty() ? 0 : fixes.back().time_s - fixes.front().time_s; }
};

// CSV flight: a header line naming the columns
//   time_s,lat_deg,lon_deg,alt_m,yaw_deg,pitch_deg,roll_deg
// (altitude MSL; yaw = true heading; pitch nose-up +; roll right-wing-down +),
// then one fix per line. Blank lines and lines starting with '#' are ignored.
// Errors name the source, line and field: "climb.csv:7: field 'lat_deg': ...".
Result<Flight> parseCsv(std::string_view text, std::string_view sourceName);

// The pose at time t (clamped to the record): position interpolated along the
// ellipsoid (ECEF lerp re-projected), angles along their shortest arc.
geo::GeodeticPose sample(const Flight& flight, double time_s);

}  // namespace sky::flight
