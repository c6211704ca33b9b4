// Cleaning a recorded track (see clean.hpp): time order, repeats, the
// longest chain of fixes the speed bound allows, single jumps, long gaps.
#include "sky/flight/clean.hpp"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <numeric>

#include "sky/flight/utf8_text.hpp"
#include "sky/geo/vec3.hpp"

namespace sky::flight {

namespace {

// Runs of mutually consistent fixes a run may link back over when the chain
// is built: a spoofed stretch cut into more pieces than this (each piece
// consistent, the pieces not) is not bridged. Bounds the work to 64 checks a
// run on hostile input.
constexpr std::size_t kMaxRunsBack = 64;

struct Point {
  Fix fix;
  std::size_t line = 0;
  geo::Vec3d ecef_m;
};

double distance_m(const Point& a, const Point& b) { return geo::length(b.ecef_m - a.ecef_m); }

// Whether b may follow a under the speed bound (a before b in time).
bool consistent(const Point& a, const Point& b, double maxSpeed_mps) {
  return std::max(0.0, distance_m(a, b) - kPositionSlack_m) <= maxSpeed_mps * (b.fix.time_s - a.fix.time_s);
}

// Where the straight track from a to b is at time t (ECEF lerp).
geo::Vec3d along(const Point& a, const Point& b, double t_s) {
  const double u = (t_s - a.fix.time_s) / (b.fix.time_s - a.fix.time_s);
  return a.ecef_m + (b.ecef_m - a.ecef_m) * u;
}

bool samePosition(const Fix& a, const Fix& b) {
  return a.pose.position.lat_deg == b.pose.position.lat_deg && a.pose.position.lon_deg == b.pose.position.lon_deg &&
         a.pose.position.alt_m == b.pose.position.alt_m;
}

std::string number(const char* format, double v) {
  char buf[48];
  std::snprintf(buf, sizeof buf, format, v);
  return buf;
}

std::string lineRange(std::size_t first, std::size_t last) {
  if (first == 0) return "";
  return first == last ? " at line " + std::to_string(first)
                       : " at lines " + std::to_string(first) + "-" + std::to_string(last);
}

std::string timeRange(double first_s, double last_s) {
  return first_s == last_s ? "t " + number("%.1f", first_s) + " s"
                           : "t " + number("%.1f", first_s) + "-" + number("%.1f", last_s) + " s";
}

// Groups the dropped points (each with its reason, in time order, with the
// kept points around) into stretches, and measures each against the kept
// track: the distance from the track between the kept neighbours, and the
// speed it implies against them.
std::vector<DroppedStretch> stretches(const std::vector<Point>& pts, const std::vector<int>& reasonOf,
                                      const std::vector<bool>& keep) {
  std::vector<DroppedStretch> out;
  std::vector<std::size_t> prevKept(pts.size(), pts.size()), nextKept(pts.size(), pts.size());
  for (std::size_t i = 0, last = pts.size(); i < pts.size(); ++i) {
    prevKept[i] = last;
    if (keep[i]) last = i;
  }
  for (std::size_t i = pts.size(), next = pts.size(); i-- > 0;) {
    nextKept[i] = next;
    if (keep[i]) next = i;
  }
  for (std::size_t i = 0; i < pts.size(); ++i) {
    if (keep[i]) continue;
    const auto reason = static_cast<DropReason>(reasonOf[i]);
    const bool extend = !out.empty() && out.back().reason == reason && i > 0 && !keep[i - 1] &&
                        reasonOf[i - 1] == reasonOf[i];
    if (!extend) {
      out.push_back(DroppedStretch{reason});
      out.back().first_s = pts[i].fix.time_s;
      out.back().firstLine = pts[i].line;
    }
    DroppedStretch& s = out.back();
    ++s.count;
    s.last_s = pts[i].fix.time_s;
    s.lastLine = pts[i].line;
    const std::size_t p = prevKept[i], n = nextKept[i];
    const double t = pts[i].fix.time_s;
    if (p < pts.size() && n < pts.size() && pts[n].fix.time_s > pts[p].fix.time_s)
      s.offTrack_m = std::max(s.offTrack_m, geo::length(pts[i].ecef_m - along(pts[p], pts[n], t)));
    else if (p < pts.size() || n < pts.size())
      s.offTrack_m = std::max(s.offTrack_m, distance_m(pts[i], pts[p < pts.size() ? p : n]));
    for (const std::size_t k : {p, n}) {
      if (k >= pts.size()) continue;
      const double dt = std::abs(pts[k].fix.time_s - t);
      if (dt > 0) s.impliedSpeed_mps = std::max(s.impliedSpeed_mps, distance_m(pts[i], pts[k]) / dt);
    }
  }
  return out;
}

}  // namespace

const char* toString(DropReason r) {
  switch (r) {
    case DropReason::Repeat: return "repeat";
    case DropReason::SameTime: return "same-time";
    case DropReason::Speed: return "speed";
    case DropReason::Jump: return "jump";
    case DropReason::AfterGap: return "after-gap";
  }
  return "?";
}

std::size_t CleanReport::droppedFor(DropReason r) const {
  std::size_t n = 0;
  for (const DroppedStretch& s : dropped)
    if (s.reason == r) n += s.count;
  return n;
}

std::vector<std::string> CleanReport::lines(const CleanOptions& options) const {
  std::vector<std::string> out;
  std::string head = "kept " + std::to_string(kept) + " of " + std::to_string(input) + " fixes";
  if (reordered) head += "; " + std::to_string(reordered) + " out of time order sorted into place";
  for (const DropReason r : {DropReason::Repeat, DropReason::SameTime, DropReason::Speed, DropReason::Jump,
                             DropReason::AfterGap})
    if (const std::size_t n = droppedFor(r)) head += "; " + std::to_string(n) + " dropped (" + toString(r) + ")";
  if (attitudeRederived) head += "; attitude derived again from the kept fixes";
  out.push_back(head);
  for (const DroppedStretch& s : dropped) {
    std::string l = std::to_string(s.count) + (s.count == 1 ? " fix" : " fixes") + lineRange(s.firstLine, s.lastLine) +
                    " (" + timeRange(s.first_s, s.last_s) + ") dropped: ";
    switch (s.reason) {
      case DropReason::Repeat: l += "a repeat of the fix before (same time and position)"; break;
      case DropReason::SameTime: l += "same time as the fix before, another position"; break;
      case DropReason::Speed:
        l += number("%.1f", s.offTrack_m / 1000) + " km off the kept track, " + number("%.0f", s.impliedSpeed_mps) +
             " m/s implied (bound " + number("%.0f", options.maxGroundSpeed_mps) + " m/s; GPS spoofing?)";
        break;
      case DropReason::Jump:
        l += number("%.1f", s.offTrack_m / 1000) + " km off the line between its neighbours, which agree";
        break;
      case DropReason::AfterGap:
        l += "after a gap longer than " + number("%.0f", options.maxGap_s) + " s (the track ends there)";
        break;
    }
    out.push_back(std::move(l));
  }
  for (const GapNote& g : gaps) {
    std::string l = number("%.0f", g.to_s - g.from_s) + " s gap" + lineRange(g.fromLine, g.toLine) + " (" +
                    timeRange(g.from_s, g.to_s) + "), " + number("%.1f", g.distance_m / 1000) + " km: ";
    switch (g.action) {
      case GapNote::Action::Interpolated: l += "interpolated in a straight line"; break;
      case GapNote::Action::Held:
        l += "held at the fix before it, then moved to the fix after (longer than --max-gap " +
             number("%.0f", options.maxGap_s) + " s)";
        break;
      case GapNote::Action::Ended: l += "the track ends before it (longer than --max-gap)"; break;
    }
    out.push_back(std::move(l));
  }
  return out;
}

std::optional<double> parseSpeed_mps(std::string_view text) {
  constexpr double kKnot_mps = 1852.0 / 3600.0;
  const auto trimmed = [](std::string_view s) {
    while (!s.empty() && s.front() == ' ') s.remove_prefix(1);
    while (!s.empty() && s.back() == ' ') s.remove_suffix(1);
    return s;
  };
  text = trimmed(text);
  double scale = 1;
  if (text.ends_with("kt")) {
    scale = kKnot_mps;
    text.remove_suffix(2);
  } else if (text.ends_with("m/s")) {
    text.remove_suffix(3);
  }
  text = trimmed(text);
  double v = 0;
  const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), v);
  if (text.empty() || ec != std::errc() || end != text.data() + text.size() || !std::isfinite(v) || !(v > 0))
    return std::nullopt;
  return v * scale;
}

Result<CleanReport> clean(ParsedFlight& flight, const CleanOptions& options, std::string_view sourceName) {
  CleanReport report;
  const std::size_t n = flight.fixes.size();
  report.input = n;
  const bool haveLines = flight.fixLines.size() == n;

  // 1. Time order (stable: among equal times the file's order), repeats.
  std::vector<Point> sorted(n);
  double latest_s = -INFINITY;
  for (std::size_t i = 0; i < n; ++i) {
    sorted[i] = Point{flight.fixes[i], haveLines ? flight.fixLines[i] : 0, geo::toEcef(flight.fixes[i].pose.position)};
    if (flight.fixes[i].time_s < latest_s) ++report.reordered;
    latest_s = std::max(latest_s, flight.fixes[i].time_s);
  }
  std::stable_sort(sorted.begin(), sorted.end(),
                   [](const Point& a, const Point& b) { return a.fix.time_s < b.fix.time_s; });
  std::vector<Point> pts;  // every fix, in time order
  std::vector<int> reasonOf;  // DropReason of a dropped one, -1 for kept
  pts.reserve(n);
  std::size_t firstOfTime = 0;  // the first fix of the latest time: the one kept
  for (const Point& p : sorted) {
    int reason = -1;
    if (!pts.empty() && p.fix.time_s == pts.back().fix.time_s)
      reason = static_cast<int>(samePosition(pts[firstOfTime].fix, p.fix) ? DropReason::Repeat : DropReason::SameTime);
    else
      firstOfTime = pts.size();
    pts.push_back(p);
    reasonOf.push_back(reason);
  }

  // 2. The longest chain. Candidates: the fixes not dropped in step 1, cut
  // into runs where one does not follow from the one before; a run links
  // back to an earlier run whose last fix its first fix follows from.
  std::vector<std::size_t> cand;
  for (std::size_t i = 0; i < pts.size(); ++i)
    if (reasonOf[i] < 0) cand.push_back(i);
  struct Run {
    std::size_t first, last;  // indices into cand
    std::size_t best = 0;     // fixes in the longest chain ending with this run
    std::size_t from = SIZE_MAX;  // the run before it in that chain
  };
  std::vector<Run> runs;
  const double vmax = options.maxGroundSpeed_mps;
  for (std::size_t c = 0; c < cand.size(); ++c) {
    if (runs.empty() || !consistent(pts[cand[c - 1]], pts[cand[c]], vmax))
      runs.push_back(Run{c, c});
    else
      runs.back().last = c;
  }
  std::size_t bestRun = 0;
  for (std::size_t r = 0; r < runs.size(); ++r) {
    Run& run = runs[r];
    std::size_t before = 0;
    for (std::size_t q = r; q-- > 0 && r - q <= kMaxRunsBack;)
      if (runs[q].best > before && consistent(pts[cand[runs[q].last]], pts[cand[run.first]], vmax)) {
        before = runs[q].best;
        run.from = q;
      }
    run.best = before + (run.last - run.first + 1);
    if (run.best > runs[bestRun].best) bestRun = r;
  }
  std::vector<bool> keep(pts.size(), false);
  for (auto r = runs.empty() ? SIZE_MAX : bestRun; r != SIZE_MAX; r = runs[r].from)
    for (std::size_t c = runs[r].first; c <= runs[r].last; ++c) keep[cand[c]] = true;
  for (const std::size_t i : cand)
    if (!keep[i]) reasonOf[i] = static_cast<int>(DropReason::Speed);

  // 3. Single jumps against two neighbours that agree with each other.
  {
    std::vector<std::size_t> kept;
    for (std::size_t i = 0; i < pts.size(); ++i)
      if (keep[i]) kept.push_back(i);
    std::vector<std::size_t> jumped;
    for (std::size_t k = 1; k + 1 < kept.size(); ++k) {
      const Point &a = pts[kept[k - 1]], &p = pts[kept[k]], &b = pts[kept[k + 1]];
      if (!consistent(a, b, vmax)) continue;
      const double ta = p.fix.time_s - a.fix.time_s, tb = b.fix.time_s - p.fix.time_s;
      const double bound_m = kJumpFloor_m + kMaxLateralAccel_mps2 * ta * tb / 2;
      if (geo::length(p.ecef_m - along(a, b, p.fix.time_s)) > bound_m) jumped.push_back(kept[k]);
    }
    for (const std::size_t i : jumped) {
      keep[i] = false;
      reasonOf[i] = static_cast<int>(DropReason::Jump);
    }
  }

  // 4. Gaps: ended at the first long one, or noted.
  std::vector<std::size_t> kept;
  for (std::size_t i = 0; i < pts.size(); ++i)
    if (keep[i]) kept.push_back(i);
  std::vector<std::size_t> holdBefore;  // positions in `kept` whose gap before is held
  for (std::size_t k = 1; k < kept.size(); ++k) {
    const Point &a = pts[kept[k - 1]], &b = pts[kept[k]];
    const double dt = b.fix.time_s - a.fix.time_s;
    // A hold needs room for its jump: a bound below 2 kHoldJump_s is taken as that.
    const double maxGap_s = std::max(options.maxGap_s, 2 * kHoldJump_s);
    if (dt <= kGapWarning_s && dt <= maxGap_s) continue;
    GapNote g{a.fix.time_s, b.fix.time_s, a.line, b.line, distance_m(a, b)};
    if (dt > maxGap_s) {
      if (options.longGap == LongGap::End) {
        g.action = GapNote::Action::Ended;
        report.gaps.push_back(g);
        for (std::size_t j = kept[k]; j < pts.size(); ++j)
          if (keep[j]) {
            keep[j] = false;
            reasonOf[j] = static_cast<int>(DropReason::AfterGap);
          }
        kept.resize(k);
        break;
      }
      g.action = GapNote::Action::Held;
      holdBefore.push_back(k);
    }
    report.gaps.push_back(g);
  }
  report.dropped = stretches(pts, reasonOf, keep);
  report.kept = kept.size();
  if (kept.size() < 2)
    return fail(ErrorCode::InvalidArgument,
                messageText(sourceName) + ": cleaning left " + std::to_string(kept.size()) + " of " +
                    std::to_string(n) + " fixes, a flight needs at least two (--no-clean replays the raw track)");

  // 5. The kept fixes, their attitude, the hold fixes.
  flight.fixes.clear();
  flight.fixLines.clear();
  for (const std::size_t i : kept) {
    flight.fixes.push_back(pts[i].fix);
    flight.fixLines.push_back(pts[i].line);
  }
  if (flight.attitudeFromTrack && kept.size() < n) {
    deriveAttitude(flight, flight.attitudeRateWindow_s);
    report.attitudeRederived = true;
  }
  for (std::size_t h = holdBefore.size(); h-- > 0;) {
    const std::size_t k = holdBefore[h];
    Fix hold = flight.fixes[k - 1];
    hold.time_s = flight.fixes[k].time_s - kHoldJump_s;
    flight.fixes.insert(flight.fixes.begin() + static_cast<std::ptrdiff_t>(k), hold);
    flight.fixLines.insert(flight.fixLines.begin() + static_cast<std::ptrdiff_t>(k), 0);
  }
  if (!haveLines) flight.fixLines.clear();
  return report;
}

}  // namespace sky::flight
