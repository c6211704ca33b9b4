// Cleaning a recorded track before it is replayed: real ADS-B and GNSS
// tracks repeat and reorder their fixes, jump hundreds of kilometres under
// GPS spoofing and stop for hours; a replay should fly the aircraft, not the
// glitches, and say what it left out. Pure: fixes in, fixes and a report out.
#pragma once

#include <cstddef>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "sky/core/result.hpp"
#include "sky/flight/flight.hpp"

namespace sky::flight {

// Default bound on the ground speed a track may imply between two fixes.
// Airliners cruise at 230-260 m/s true airspeed (M 0.78-0.85 at FL350) and
// jet-stream cores add up to ~100 m/s of tailwind (records near 120 m/s), so
// ~350 m/s is the fastest ground speed an airliner reaches; a fix implying
// more is a glitch. Business jets (M 0.9) fit too; a faster aircraft class
// needs --max-speed.
inline constexpr double kDefaultMaxGroundSpeed_mps = 350.0;
// Default longest gap flown through by interpolation. ADS-B receivers lose an
// aircraft for tens of seconds between stations; two minutes at airliner
// speed is ~30 km, which a straight line still follows; past that the line
// may cross an ocean the aircraft went round.
inline constexpr double kDefaultMaxGap_s = 120.0;
// Slack on the distance between two fixes before their speed is judged: two
// positions each within NACp 8's 93 m (95 %, the accuracy the FAA's ADS-B Out
// rule asks, 14 CFR 91.227) are up to 186 m apart from where they should be;
// without the slack two fixes 0.1 s apart would imply 1860 m/s of noise.
inline constexpr double kPositionSlack_m = 200.0;
// A fix off the line between its two neighbours by more than
// kJumpFloor_m + kMaxLateralAccel_mps2 * ta * tb / 2 (ta, tb: seconds to
// each neighbour) is a jump: a path whose acceleration stays below a leaves
// the chord by at most a*ta*tb/2. 20 m/s^2 is a 2 g turn (63 deg of bank),
// past any airliner and most aerobatics; the 1 km floor is five times
// kPositionSlack_m, so noise never reaches it and spoofing (tens to hundreds
// of km) always does.
inline constexpr double kMaxLateralAccel_mps2 = 20.0;
inline constexpr double kJumpFloor_m = 1000.0;
// A held aircraft (LongGap::Hold) moves to the far side of the gap in this
// time: shorter than any frame step, so no frame shows it half-way.
inline constexpr double kHoldJump_s = 1e-3;

// What a replay does at a gap longer than CleanOptions::maxGap_s.
enum class LongGap {
  Hold,  // stay at the last fix before the gap until its end, then jump
  End,   // end the track at the last fix before the gap
};

struct CleanOptions {
  double maxGroundSpeed_mps = kDefaultMaxGroundSpeed_mps;  // (0, inf)
  double maxGap_s = kDefaultMaxGap_s;  // shorter gaps are interpolated; >= 1 s (> kHoldJump_s)
  LongGap longGap = LongGap::Hold;
};

enum class DropReason {
  Repeat,    // same time and position as a kept fix (a repeated row)
  SameTime,  // same time as a kept fix, another position
  Speed,     // off the longest chain of fixes the speed bound allows
  Jump,      // off the line between its neighbours, which agree
  AfterGap,  // after a long gap, with LongGap::End
};
const char* toString(DropReason r);  // "repeat", "same-time", "speed", "jump", "after-gap"

// A stretch of consecutive fixes (in time order) dropped for one reason.
struct DroppedStretch {
  DropReason reason;
  std::size_t count = 0;
  double first_s = 0, last_s = 0;                // times of its first and last fix, s
  std::size_t firstLine = 0, lastLine = 0;       // their lines in the file; 0 if unknown
  double offTrack_m = 0;  // Speed, Jump: the largest distance of a fix from the kept track
  double impliedSpeed_mps = 0;  // Speed: the largest speed a fix implies against its kept neighbours
};

// A gap longer than kGapWarning_s between two kept fixes.
struct GapNote {
  double from_s = 0, to_s = 0;  // times of the fixes either side, s
  std::size_t fromLine = 0, toLine = 0;
  double distance_m = 0;  // straight (ECEF chord) distance across it
  enum class Action { Interpolated, Held, Ended } action = Action::Interpolated;
};

struct CleanReport {
  std::size_t input = 0;   // fixes in
  std::size_t kept = 0;    // of those, kept (hold fixes not counted)
  std::size_t reordered = 0;  // fixes that were out of time order and were sorted into place
  std::vector<DroppedStretch> dropped;  // in time order
  std::vector<GapNote> gaps;            // in time order
  bool attitudeRederived = false;  // the attitude was derived again from the kept fixes

  std::size_t droppedFor(DropReason r) const;
  // One human line per finding, for a log ("3 fixes at lines 120-122
  // (t 310.0-312.0 s) dropped: 412.0 km off the kept track, 137000 m/s
  // implied (bound 350 m/s; GPS spoofing?)"); the first sums it up ("kept
  // 1180 of 1183 fixes; 3 dropped (speed)").
  std::vector<std::string> lines(const CleanOptions& options) const;
};

// A speed as a command line gives it: a number in m/s, or followed by a
// unit, "m/s" or "kt" (international knot, 1852 m/h), with or without a
// space: "350", "350m/s", "680 kt". nullopt unless finite and > 0.
std::optional<double> parseSpeed_mps(std::string_view text);

// Cleans a parsed track in place, in this order:
//  1. sorts the fixes by time (stable), drops exact repeats and fixes at the
//     same time as an earlier one;
//  2. keeps the longest chain of fixes (most fixes) in which each implies a
//     speed of at most maxGroundSpeed_mps from the one before (distance less
//     kPositionSlack_m, over time): a spoofed fix or stretch of fixes is a
//     run the chain goes round, however far it jumps;
//  3. drops a fix off the line between its two kept neighbours by more than
//     the jump bound above (a smaller jump that the speed bound lets pass);
//  4. gaps longer than maxGap_s: End truncates the track at the first; Hold
//     adds a fix with the pose before the gap kHoldJump_s before its end;
//     shorter gaps are left for sample() to interpolate, and every gap over
//     kGapWarning_s is noted;
//  5. derives the attitude again (deriveAttitude) when attitudeFromTrack and
//     a fix was dropped, before the hold fixes are added (so a hold keeps the
//     attitude it had).
// fixLines follows the fixes (hold fixes get line 0), and fixes' times are
// strictly increasing afterwards. Times keep their origin (time_s 0 stays
// the record's start, startUtc_s holds). Fails (InvalidArgument, naming the
// source) when fewer than two fixes are left. Never throws.
Result<CleanReport> clean(ParsedFlight& flight, const CleanOptions& options, std::string_view sourceName);

}  // namespace sky::flight
