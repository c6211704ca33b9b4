// The ForeFlight UDP text format (ForeFlight's "GPS Integration" spec), which
// X-Plane 11/12 (Settings > Network), FlightGear (--generic protocol
// foreflight-xgps) and add-ons for other simulators already send, by default
// to UDP port 49002: one ASCII line per message,
//   XGPS<sim>,<lon deg>,<lat deg>,<alt m MSL>,<track deg true>,<ground speed m/s>
//   XATT<sim>,<heading deg true>,<pitch deg>,<roll deg>[,more fields ignored]
// and XTRAFFIC/other lines for things a sky renderer does not draw. <sim> is
// the sender's name (any printable ASCII but a comma, may be empty).
#pragma once

#include <cstdint>
#include <span>
#include <string>
#include <variant>
#include <vector>

#include "sky/core/result.hpp"

namespace sky::foreflight {

// Default UDP port of the format.
inline constexpr unsigned short kDefaultPort = 49002;
// A datagram longer than this is refused unread: a real one is one or two
// lines of under 100 bytes.
inline constexpr std::size_t kMaxDatagramBytes = 1024;
// Lines taken from one datagram at most (a sender may batch XGPS and XATT).
inline constexpr std::size_t kMaxLinesPerDatagram = 8;

struct Position {  // XGPS
  std::string sim;
  double lon_deg = 0;  // [-180, 180]; 180 and -180 are the same meridian
  double lat_deg = 0;  // [-90, 90]
  double alt_m = 0;    // MSL, [-1000, 30000]
  double track_deg = 0;         // true, [0, 360]
  double groundSpeed_mps = 0;   // [0, 1000]
};

struct Attitude {  // XATT
  std::string sim;
  double heading_deg = 0;  // true, [0, 360] (negative values as sent by some add-ons are wrapped)
  double pitch_deg = 0;    // [-90, 90]
  double roll_deg = 0;     // [-180, 180]
};

// A well-formed line of another kind (XTRAFFIC, ...): counted, not used.
struct Other {
  std::string kind;  // "XTRAFFIC", or the first four letters of another kind
};

using Message = std::variant<Position, Attitude, Other>;

// One line without its end ("\n", "\r\n" or none). Errors name the field:
// Malformed for text that is not the format (non-ASCII or control bytes, a
// missing or non-numeric field), InvalidArgument for a number outside the
// ranges above or not finite.
Result<Message> parseLine(std::string_view line);

// Every line of a datagram, in order; an empty datagram or one past
// kMaxDatagramBytes or with more than kMaxLinesPerDatagram lines is an
// error, as is any bad line (the datagram is dropped whole: a sender that
// garbles one line is not trusted for the other).
Result<std::vector<Message>> parseDatagram(std::span<const std::uint8_t> bytes);

// The lines of a message as a sender writes them (for tests and tools).
std::string formatLine(const Position& p);
std::string formatLine(const Attitude& a);

}  // namespace sky::foreflight
