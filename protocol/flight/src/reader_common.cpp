// Capped warnings and the time-order rules shared by the IGC, GPX and ADS-B
// readers, and the choice of reader for a file.
#include "reader_common.hpp"

#include "sky/flight/utf8_text.hpp"

#include <cstdio>
#include <utility>

namespace sky::flight::detail {

namespace {

constexpr std::size_t kMaxFieldChars = 40;  // enough for any IGC/GPX field

constexpr std::array<const char*, static_cast<std::size_t>(WarningKind::Count_)> kKindNames = {
    "out-of-order fixes skipped", "duplicate-time fixes skipped", "gaps kept",
    "fixes with validity 'V' skipped", "fixes without altitude skipped",
    "unreadable lines skipped", "rows with an empty field skipped",
    "rows on the ground without a geometric altitude skipped", "new legs kept",
    "stale positions skipped", "other warnings"};

std::string seconds(double s) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.3g", s);
  return buf;
}

}  // namespace

std::string printable(std::string_view s) {
  std::string out;
  for (char c : s.substr(0, kMaxFieldChars)) out.push_back(c >= 0x20 && c < 0x7f ? c : '?');
  if (s.size() > kMaxFieldChars) out += "...";
  return out;
}

Warnings::Warnings(std::string_view source) : source_(messageText(source)) {}

void Warnings::add(WarningKind kind, std::size_t line, const std::string& text) {
  const std::size_t n = ++counts_[static_cast<std::size_t>(kind)];
  if (n > kMaxWarningsPerKind) return;
  list_.push_back(source_ + ":" + (line ? std::to_string(line) + ":" : std::string()) + " " + text);
}

std::vector<std::string> Warnings::finish() {
  for (std::size_t k = 0; k < counts_.size(); ++k)
    if (counts_[k] > kMaxWarningsPerKind)
      list_.push_back(source_ + ": " + std::to_string(counts_[k] - kMaxWarningsPerKind) + " more " +
                      kKindNames[k] + " (not listed)");
  return std::move(list_);
}

bool TimeOrder::accept(double t_s, std::size_t line, Warnings& warnings) {
  if (any_) {
    if (t_s < last_s_) {
      warnings.add(WarningKind::OutOfOrder, line,
                   "field 'time': " + seconds(last_s_ - t_s) + " s before the previous fix, fix skipped");
      return false;
    }
    if (t_s == last_s_) {
      warnings.add(WarningKind::Duplicate, line, "field 'time': same as the previous fix, fix skipped");
      return false;
    }
    if (t_s - last_s_ > kGapWarning_s)
      warnings.add(WarningKind::Gap, line,
                   "field 'time': " + seconds(t_s - last_s_) + " s gap before this fix (kept)");
  }
  any_ = true;
  last_s_ = t_s;
  return true;
}

}  // namespace sky::flight::detail

namespace sky::flight {

namespace {

// The first line that is neither blank nor a '#' comment: the header of
// either CSV format.
std::string_view firstCsvLine(std::string_view text) {
  std::string_view header;
  bool found = false;
  detail::forEachLine(text, [&](std::string_view line, std::size_t) {
    if (found) return;
    const auto start = line.find_first_not_of(" \t");
    if (start == std::string_view::npos || line[start] == '#') return;
    header = line;
    found = true;
  });
  return header;
}

}  // namespace

Result<ParsedFlight> parseFlight(std::string_view text, std::string_view sourceName, const ReadOptions& options) {
  const auto dot = sourceName.rfind('.');
  const auto slash = sourceName.rfind('/');
  std::string ext;
  if (dot != std::string_view::npos && (slash == std::string_view::npos || dot > slash))
    for (char c : sourceName.substr(dot + 1)) ext.push_back(c >= 'A' && c <= 'Z' ? static_cast<char>(c - 'A' + 'a') : c);
  if (ext == "csv")
    return isAdsbCsvHeader(firstCsvLine(text)) ? parseAdsbCsv(text, sourceName, options) : parseCsv(text, sourceName);
  if (ext == "igc") return parseIgc(text, sourceName);
  if (ext == "gpx") return parseGpx(text, sourceName);
  if (ext == "json") return parseReadsbTrace(text, sourceName, options);
  return fail(ErrorCode::Unsupported, messageText(sourceName) + ": unknown flight format '." + detail::printable(ext) +
                                          "' (expected .csv, .igc, .gpx or .json)");
}

}  // namespace sky::flight
