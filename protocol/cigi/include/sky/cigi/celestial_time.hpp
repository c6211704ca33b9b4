// CIGI Celestial Sphere Control's date and time of day <-> UTC seconds since
// 1970: what a host (skyshell-replay) writes and an IG (skyshell-render)
// reads, written once so the two agree. Proleptic Gregorian calendar, UTC
// (the ICD leaves the time zone open: cigi.md §6.1; we state UTC).
#pragma once

#include <cstdint>
#include <optional>

#include "sky/cigi/packets.hpp"

namespace sky::cigi {

// Years a Celestial Sphere Control date may carry: the ephemeris
// (renderer/core ephemeris.hpp, Meeus' low-precision series) is stated for
// about 1950-2050 and degrades slowly outside; 1900-2100 keeps it under
// ~0.1 degree, and a year outside is a host's error, not a date.
inline constexpr int kCelestialMinYear = 1900, kCelestialMaxYear = 2100;

// UTC seconds since 1970 -> hour, minute and MMDDYYYY date (seconds are
// dropped: the packet has none), with Date/Time Valid and Ephemeris Enable
// set. utc_s: any instant of years kCelestialMinYear..kCelestialMaxYear.
CelestialSphereControl celestialAt(std::int64_t utc_s);

// The UTC instant (s since 1970, at the start of the packet's minute) of a
// date and time; nullopt when the date is not a calendar date of years
// kCelestialMinYear..kCelestialMaxYear (month 13, 30 February, day 0) or the
// hour or minute is out of range. Ignores Date/Time Valid.
std::optional<std::int64_t> celestialUtc(const CelestialSphereControl& c);

}  // namespace sky::cigi
