// Capped warnings, the time-order rules and ISO 8601 times shared by the readers,
// and the choice of reader for a file.
#include "reader_common.hpp"

#include <charconv>
#include <cmath>
#include <system_error>

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

std::optional<double> parseDecimal(std::string_view s) {
  s = trimSpace(s);
  if (!s.empty() && s.front() == '+') s.remove_prefix(1);
  double v = 0;
  const auto [ptr, ec] = std::from_chars(s.data(), s.data() + s.size(), v);
  if (s.empty() || ec != std::errc() || ptr != s.data() + s.size() || !std::isfinite(v)) return std::nullopt;
  return v;
}

std::string printable(std::string_view s) {
  std::string out;
  for (char c : s.substr(0, kMaxFieldChars)) out.push_back(c >= 0x20 && c < 0x7f ? c : '?');
  if (s.size() > kMaxFieldChars) out += "...";
  return out;
}

std::optional<double> isoUtc_s(std::string_view s) {
  const auto space = [](char c) { return c == ' ' || c == '\t' || c == '\n' || c == '\r'; };
  while (!s.empty() && space(s.front())) s.remove_prefix(1);
  while (!s.empty() && space(s.back())) s.remove_suffix(1);
  const auto num = [&](std::size_t at, std::size_t n) { return detail::digitsValue(detail::sub(s, at, n)); };
  if (s.size() < 20 || s[4] != '-' || s[7] != '-' || (s[10] != 'T' && s[10] != 't') || s[13] != ':' ||
      s[16] != ':')
    return std::nullopt;
  const long long y = num(0, 4), mo = num(5, 2), d = num(8, 2), h = num(11, 2), mi = num(14, 2), sec = num(17, 2);
  if (y < 0 || mo < 1 || mo > 12 || d < 1 || d > 31 || h < 0 || h > 23 || mi < 0 || mi > 59 || sec < 0 ||
      sec > 60)
    return std::nullopt;
  std::size_t i = 19;
  double fraction = 0;
  if (s[i] == '.') {
    double scale = 0.1;
    for (++i; i < s.size() && detail::isDigit(s[i]); ++i, scale /= 10) fraction += (s[i] - '0') * scale;
  }
  if (i >= s.size()) return std::nullopt;
  long long offset_s = 0;
  if (s[i] == 'Z' || s[i] == 'z') {
    ++i;
  } else if (s[i] == '+' || s[i] == '-') {
    const long long oh = num(i + 1, 2), om = num(i + 4, 2);
    if (s.size() < i + 6 || s[i + 3] != ':' || oh < 0 || oh > 23 || om < 0 || om > 59) return std::nullopt;
    offset_s = (s[i] == '+' ? 1 : -1) * (oh * 3600 + om * 60);
    i += 6;
  } else {
    return std::nullopt;
  }
  if (i != s.size()) return std::nullopt;
  const std::int64_t days = daysFromCivil(y, static_cast<unsigned>(mo), static_cast<unsigned>(d));
  return static_cast<double>(days * 86400 + h * 3600 + mi * 60 + sec - offset_s) + fraction;
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
  if (ext == "kml") return parseKml(text, sourceName, options);
  if (ext == "kmz") return parseKmz(text, sourceName, options);
  if (ext == "fdr") return parseFdr(text, sourceName);
  return fail(ErrorCode::Unsupported, messageText(sourceName) + ": unknown flight format '." + detail::printable(ext) +
                                          "' (expected .csv, .igc, .gpx, .json, .kml, .kmz or .fdr)");
}

}  // namespace sky::flight
