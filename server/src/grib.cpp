// Reading GRIB2 messages with ecCodes (grib.hpp). The file is split into
// messages and fields here, by the lengths GRIB2's sections state, so a
// hostile length is refused before ecCodes sees the bytes; ecCodes then
// decodes each field as a message of its own (no state carried from one
// message to the next, as its multi-field reader keeps). ecCodes reports through a logging callback (kept as the last
// message for the error text, never printed) and, on an internal assertion,
// through a callback that by default aborts the process: ours throws instead,
// and the message is skipped.
#include <eccodes.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <ctime>
#include <limits>
#include <memory>
#include <mutex>
#include <stdexcept>
#include <string>
#include <tuple>
#include <vector>

#include "sky/server/grib.hpp"

namespace sky::server {

namespace {

// GRIB2 section 0 (WMO Manual on Codes, FM 92): "GRIB", 2 reserved bytes,
// the discipline, the edition, then the total length as 8 bytes big-endian.
constexpr std::size_t kSection0Bytes = 16;
// The smallest GRIB2 message: sections 0, 1, 3, 4, 5, 6, 7 and "7777".
constexpr std::size_t kMinMessageBytes = 16 + 21 + 14 + 9 + 11 + 6 + 5 + 4;
// What ecCodes answers for a value that a bitmap or the packing marks
// missing, set by us so that no real value can be taken for it.
constexpr double kMissingSentinel = 1.0e35;

thread_local std::string lastEccodesMessage;

struct EccodesAssertion : std::runtime_error {
  using std::runtime_error::runtime_error;
};

void onLog(const codes_context*, int, const char* message) { lastEccodesMessage = message ? message : ""; }
[[noreturn]] void onAssertion(const char* message) {
  throw EccodesAssertion(std::string("ecCodes assertion: ") + (message ? message : "?"));
}

codes_context* context() {
  static std::once_flag once;
  std::call_once(once, [] {
    codes_context_set_logging_proc(codes_context_get_default(), onLog);
    codes_set_codes_assertion_failed_proc(onAssertion);
  });
  return codes_context_get_default();
}

struct HandleDeleter {
  void operator()(codes_handle* h) const { codes_handle_delete(h); }
};
using Handle = std::unique_ptr<codes_handle, HandleDeleter>;

std::string ecError(int err) {
  std::string s = codes_get_error_message(err);
  if (!lastEccodesMessage.empty()) s += " (" + lastEccodesMessage + ")";
  return s;
}

Result<long> getLong(codes_handle* h, const char* key) {
  long v = 0;
  if (int err = codes_get_long(h, key, &v); err) return fail(ErrorCode::Malformed, std::string(key) + ": " + ecError(err));
  return v;
}

Result<double> getDouble(codes_handle* h, const char* key) {
  double v = 0;
  if (int err = codes_get_double(h, key, &v); err)
    return fail(ErrorCode::Malformed, std::string(key) + ": " + ecError(err));
  return v;
}

std::string getString(codes_handle* h, const char* key) {
  char buf[256] = {};
  std::size_t len = sizeof buf;
  if (codes_get_string(h, key, buf, &len) != 0) return "";
  return std::string(buf, strnlen(buf, sizeof buf));
}

bool isMissing(codes_handle* h, const char* key) {
  int err = 0;
  return codes_is_missing(h, key, &err) == 1 || err != 0;
}

// yyyymmdd and hhmm to Unix seconds (UTC); nullopt for a date that is none.
std::optional<std::int64_t> unixTime(long date, long time) {
  const long y = date / 10000, m = date / 100 % 100, d = date % 100, hh = time / 100, mm = time % 100;
  if (y < 1900 || y > 2200 || m < 1 || m > 12 || d < 1 || d > 31 || hh > 24 || mm > 59 || time < 0) return std::nullopt;
  // Days from civil (Howard Hinnant's algorithm, proleptic Gregorian).
  const long yy = m <= 2 ? y - 1 : y;
  const long era = (yy >= 0 ? yy : yy - 399) / 400;
  const long yoe = yy - era * 400;
  const long doy = (153 * (m + (m > 2 ? -3 : 9)) + 2) / 5 + d - 1;
  const long doe = yoe * 365 + yoe / 4 - yoe / 100 + doy;
  const std::int64_t days = era * 146097 + doe - 719468;
  return days * 86400 + hh * 3600 + mm * 60;
}

// The sphere of GRIB2 code table 3.2; nullopt for an oblate Earth.
std::optional<double> sphereRadius(codes_handle* h) {
  const auto shape = getLong(h, "shapeOfTheEarth");
  if (!shape) return std::nullopt;
  switch (*shape) {
    case 0: return 6367470.0;
    case 6: return 6371229.0;
    case 8: return 6371200.0;
    case 1: {
      const auto factor = getLong(h, "scaleFactorOfRadiusOfSphericalEarth");
      const auto value = getLong(h, "scaledValueOfRadiusOfSphericalEarth");
      if (!factor || !value || *factor < 0 || *factor > 9) return std::nullopt;
      return static_cast<double>(*value) / std::pow(10.0, static_cast<double>(*factor));
    }
    default: return std::nullopt;
  }
}

Result<GribGrid> gridOf(codes_handle* h) {
  const auto templ = getLong(h, "gridDefinitionTemplateNumber");
  if (!templ) return tl::unexpected(templ.error());
  GribGrid g;
  auto flag = [&](const char* key) { return getLong(h, key).value_or(0) != 0; };
  if (flag("alternativeRowScanning")) return fail(ErrorCode::Unsupported, "rows scanned in alternating directions");
  g.iNegative = flag("iScansNegatively");
  g.jPositive = flag("jScansPositively");
  g.jConsecutive = flag("jPointsAreConsecutive");
  g.uvRelativeToGrid = flag("uvRelativeToGrid");
  auto dbl = [&](const char* key, double& out) -> Result<void> {
    const auto v = getDouble(h, key);
    if (!v) return tl::unexpected(v.error());
    out = *v;
    return {};
  };
  auto lng = [&](const char* key, int& out) -> Result<void> {
    if (isMissing(h, key)) return fail(ErrorCode::Malformed, std::string(key) + " missing");
    const auto v = getLong(h, key);
    if (!v) return tl::unexpected(v.error());
    if (*v < 1 || *v > (1 << 20)) return fail(ErrorCode::Malformed, std::string(key) + " " + std::to_string(*v));
    out = static_cast<int>(*v);
    return {};
  };
  Result<void> r;
  if (*templ == 0) {
    g.projection = GribGrid::Projection::LatLon;
    for (auto step : {lng("Ni", g.ni), lng("Nj", g.nj), dbl("latitudeOfFirstGridPointInDegrees", g.lat1_deg),
                      dbl("longitudeOfFirstGridPointInDegrees", g.lon1_deg),
                      dbl("latitudeOfLastGridPointInDegrees", g.lat2_deg),
                      dbl("longitudeOfLastGridPointInDegrees", g.lon2_deg)})
      if (!step) return tl::unexpected(step.error());
  } else if (*templ == 30) {
    g.projection = GribGrid::Projection::Lambert;
    for (auto step : {lng("Nx", g.ni), lng("Ny", g.nj), dbl("latitudeOfFirstGridPointInDegrees", g.lat1_deg),
                      dbl("longitudeOfFirstGridPointInDegrees", g.lon1_deg), dbl("LaDInDegrees", g.lad_deg),
                      dbl("LoVInDegrees", g.lov_deg), dbl("Latin1InDegrees", g.latin1_deg),
                      dbl("Latin2InDegrees", g.latin2_deg), dbl("DxInMetres", g.dx_m), dbl("DyInMetres", g.dy_m)})
      if (!step) return tl::unexpected(step.error());
    const auto radius = sphereRadius(h);
    if (!radius)
      return fail(ErrorCode::Unsupported, "Lambert grid on an oblate Earth (shapeOfTheEarth " +
                                              std::to_string(getLong(h, "shapeOfTheEarth").value_or(-1)) + ")");
    g.radius_m = *radius;
  } else {
    return fail(ErrorCode::Unsupported,
                "grid template 3." + std::to_string(*templ) + " (" + getString(h, "gridType") + ")");
  }
  if (auto v = validate(g); !v) return tl::unexpected(v.error());
  return g;
}

Result<GribMeta> metaOf(codes_handle* h, std::size_t message) {
  GribMeta m;
  m.message = message;
  m.shortName = getString(h, "shortName");
  m.typeOfLevel = getString(h, "typeOfLevel");
  m.units = getString(h, "units");
  for (auto [key, out] : {std::pair{"discipline", &m.discipline}, std::pair{"parameterCategory", &m.category},
                          std::pair{"parameterNumber", &m.number},
                          std::pair{"typeOfFirstFixedSurface", &m.levelType}}) {
    const auto v = getLong(h, key);
    if (!v) return tl::unexpected(v.error());
    *out = *v;
  }
  m.level = std::numeric_limits<double>::quiet_NaN();
  if (!isMissing(h, "scaledValueOfFirstFixedSurface") && !isMissing(h, "scaleFactorOfFirstFixedSurface")) {
    const auto value = getLong(h, "scaledValueOfFirstFixedSurface");
    const auto factor = getLong(h, "scaleFactorOfFirstFixedSurface");
    if (value && factor && *factor >= -20 && *factor <= 20)
      m.level = static_cast<double>(*value) / std::pow(10.0, static_cast<double>(*factor));
  }
  const auto refDate = getLong(h, "dataDate"), refTime = getLong(h, "dataTime");
  const auto validDate = getLong(h, "validityDate"), validTime = getLong(h, "validityTime");
  if (!refDate || !refTime || !validDate || !validTime) return fail(ErrorCode::Malformed, "no date and time");
  const auto ref = unixTime(*refDate, *refTime), valid = unixTime(*validDate, *validTime);
  if (!ref || !valid)
    return fail(ErrorCode::Malformed, "date " + std::to_string(*refDate) + " " + std::to_string(*refTime) + " or " +
                                          std::to_string(*validDate) + " " + std::to_string(*validTime));
  m.reference_unix = *ref;
  m.valid_unix = *valid;
  auto grid = gridOf(h);
  if (!grid) return tl::unexpected(grid.error());
  m.grid = *grid;
  return m;
}

std::uint64_t bigEndian(const std::byte* p, std::size_t n) {
  std::uint64_t v = 0;
  for (std::size_t k = 0; k < n; ++k) v = v << 8 | static_cast<std::uint8_t>(p[k]);
  return v;
}

}  // namespace

namespace {

// Walks the sections of the GRIB2 message at [at, at + length) and appends
// its fields; the reason when they do not add up.
std::optional<std::string> splitFields(std::span<const std::byte> bytes, std::size_t at, std::size_t length,
                                       std::size_t message, std::vector<GribFieldSpan>& out) {
  const std::size_t end = at + length - 4;  // "7777"
  std::size_t p = at + kSection0Bytes;
  std::array<std::optional<GribSection>, 8> latest;  // by section number
  std::optional<GribSection> bitmap;                 // the latest section 6 holding a bitmap
  std::size_t fields = 0;
  while (p < end) {
    if (end - p < 5) return "a section header cut short at byte " + std::to_string(p - at);
    const std::uint64_t len = bigEndian(bytes.data() + p, 4);
    const auto number = static_cast<std::uint8_t>(bytes[p + 4]);
    if (len < 5 || len > end - p)
      return "section " + std::to_string(number) + " at byte " + std::to_string(p - at) + ": length " +
             std::to_string(len) + " runs past the message";
    if (number < 1 || number > 7) return "section number " + std::to_string(number) + " at byte " + std::to_string(p - at);
    if (number == 1 && latest[1]) return "a second section 1";
    if (number != 1 && !latest[1]) return "section " + std::to_string(number) + " before section 1";
    const GribSection here{p, static_cast<std::size_t>(len)};
    if (number == 6) {
      if (len < 6) return "section 6 without its bitmap indicator";
      const auto indicator = static_cast<std::uint8_t>(bytes[p + 5]);
      if (indicator == 0) bitmap = here;
      if (indicator == 254 && !bitmap) return "section 6 refers to a bitmap defined before, and there is none";
      latest[6] = indicator == 254 ? *bitmap : here;
    } else {
      latest[number] = here;
    }
    // A section 3 or 4 starts what the next section 7 closes.
    if (number == 3) latest[4] = latest[5] = latest[6] = std::nullopt;
    if (number == 4) latest[5] = latest[6] = std::nullopt;
    if (number == 7) {
      for (int k : {3, 4, 5, 6})
        if (!latest[k]) return "section 7 at byte " + std::to_string(p - at) + " without a section " + std::to_string(k);
      GribFieldSpan f;
      f.message = message;
      for (int k = 1; k <= 7; ++k) f.sections[k - 1] = latest[k].value_or(GribSection{});
      out.push_back(f);
      ++fields;
      latest[4] = latest[5] = latest[6] = latest[7] = std::nullopt;
    }
    p += len;
  }
  if (fields == 0) return "no field (no section 7)";
  if (latest[4] || latest[5] || latest[6]) return "a field's sections after the last section 7";
  return std::nullopt;
}

}  // namespace

Result<GribSplit> splitGrib(std::span<const std::byte> bytes, std::string_view sourceName, const GribLimits& limits) {
  GribSplit split;
  std::size_t at = 0;
  while (at + kSection0Bytes <= bytes.size()) {
    const std::byte* p = bytes.data() + at;
    if (std::memcmp(p, "GRIB", 4) != 0) {
      ++at;
      continue;
    }
    const std::size_t message = ++split.messages;
    if (split.messages > limits.maxMessages)
      return fail(ErrorCode::TooLarge,
                  std::string(sourceName) + ": more than " + std::to_string(limits.maxMessages) + " GRIB messages");
    const auto edition = static_cast<std::uint8_t>(p[7]);
    if (edition != 2) {
      // GRIB1's length is 3 bytes at offset 4 (without the large-message extension).
      const std::size_t len = edition == 1 ? bigEndian(p + 4, 3) : 0;
      split.skipped.push_back({message, 0, "GRIB edition " + std::to_string(edition) + ", only GRIB2 is read"});
      at += len >= 8 && len <= bytes.size() - at ? len : 4;
      continue;
    }
    const std::uint64_t length = bigEndian(p + 8, 8);
    if (length < kMinMessageBytes || length > bytes.size() - at) {
      split.skipped.push_back({message, 0, "length " + std::to_string(length) + " at byte " + std::to_string(at) +
                                               " runs past the end of the file (" + std::to_string(bytes.size()) +
                                               " bytes)"});
      at += 4;
      continue;
    }
    if (std::memcmp(p + length - 4, "7777", 4) != 0) {
      split.skipped.push_back({message, 0, "no '7777' at the end of its " + std::to_string(length) + " bytes"});
      at += 4;
      continue;
    }
    const std::size_t before = split.fields.size();
    if (auto bad = splitFields(bytes, at, static_cast<std::size_t>(length), message, split.fields)) {
      split.fields.resize(before);
      split.skipped.push_back({message, 0, *bad});
    } else if (split.fields.size() > limits.maxMessages * 16) {
      return fail(ErrorCode::TooLarge, std::string(sourceName) + ": more than " +
                                           std::to_string(limits.maxMessages * 16) + " fields");
    }
    at += length;
  }
  for (std::size_t k = 0; k < split.fields.size(); ++k) split.fields[k].field = k + 1;
  if (split.messages == 0)
    return fail(ErrorCode::Malformed,
                std::string(sourceName) + ": no GRIB message in " + std::to_string(bytes.size()) + " bytes");
  return split;
}

std::vector<std::byte> fieldMessage(std::span<const std::byte> bytes, const GribFieldSpan& field) {
  std::size_t total = kSection0Bytes + 4;
  for (const GribSection& s : field.sections) total += s.length;
  // Filled by offset (GCC 12 at -O3 warns falsely on vector inserts of bytes).
  std::vector<std::byte> out(total);
  // Section 0 ("GRIB", reserved, discipline, edition) as in the file, where
  // it stands right before the message's one section 1; then the new length.
  const std::size_t s0 = field.sections[0].offset - kSection0Bytes;
  std::memcpy(out.data(), bytes.data() + s0, 8);
  for (int k = 0; k < 8; ++k) out[8 + k] = static_cast<std::byte>((total >> (8 * (7 - k))) & 0xff);
  std::size_t at = kSection0Bytes;
  for (const GribSection& s : field.sections) {
    if (s.length > 0) std::memcpy(out.data() + at, bytes.data() + s.offset, s.length);
    at += s.length;
  }
  std::memcpy(out.data() + at, "7777", 4);
  return out;
}

Result<std::optional<GribField>> decodeGribField(std::span<const std::byte> bytes, const GribFieldSpan& span,
                                                 const GribWanted& wanted, const GribLimits& limits,
                                                 std::size_t& kept) {
  codes_context* ctx = context();
  const std::vector<std::byte> message = fieldMessage(bytes, span);
  lastEccodesMessage.clear();
  auto skip = [](std::string why) { return fail(ErrorCode::Malformed, std::move(why)); };
  try {
    Handle h(codes_handle_new_from_message_copy(ctx, message.data(), message.size()));
    if (!h) return skip("ecCodes could not decode it" + (lastEccodesMessage.empty() ? "" : ": " + lastEccodesMessage));
    auto meta = metaOf(h.get(), span.message);
    if (!meta) return skip(meta.error().detail);
    meta->field = span.field;
    if (!wanted(*meta)) return std::optional<GribField>{};
    const std::size_t points = static_cast<std::size_t>(meta->grid.ni) * meta->grid.nj;
    const auto declared = getLong(h.get(), "numberOfDataPoints");
    if (!declared || static_cast<std::size_t>(*declared) != points)
      return skip("numberOfDataPoints differs from the grid's " + std::to_string(points));
    if (points > limits.maxPointsPerMessage)
      return skip(std::to_string(points) + " points, more than " + std::to_string(limits.maxPointsPerMessage));
    if (kept + points > limits.maxValuesKept)
      return fail(ErrorCode::TooLarge,
                  "the wanted fields hold more than " + std::to_string(limits.maxValuesKept) + " values");
    if (int e = codes_set_double(h.get(), "missingValue", kMissingSentinel); e) return skip("missingValue: " + ecError(e));
    std::size_t n = 0;
    if (int e = codes_get_size(h.get(), "values", &n); e || n != points)
      return skip(e ? "values: " + ecError(e) : std::to_string(n) + " values for " + std::to_string(points) + " points");
    std::vector<double> raw(n);
    if (int e = codes_get_double_array(h.get(), "values", raw.data(), &n); e || n != points)
      return skip("values: " + (e ? ecError(e) : std::string("short")));
    GribField out{std::move(*meta), std::vector<float>(n)};
    for (std::size_t k = 0; k < n; ++k)
      out.values[k] = raw[k] >= kMissingSentinel * 0.5 || !std::isfinite(raw[k]) ? std::numeric_limits<float>::quiet_NaN()
                                                                                 : static_cast<float>(raw[k]);
    kept += n;
    return std::optional<GribField>(std::move(out));
  } catch (const EccodesAssertion& e) {
    return skip(e.what());
  }
}

Result<GribFile> readGrib(std::span<const std::byte> bytes, std::string_view sourceName, const GribWanted& wanted,
                          const GribLimits& limits) {
  auto split = splitGrib(bytes, sourceName, limits);
  if (!split) return tl::unexpected(split.error());
  GribFile file;
  file.messages = split->messages;
  file.fieldCount = split->fields.size();
  file.skipped = std::move(split->skipped);
  std::size_t kept = 0;
  for (const GribFieldSpan& f : split->fields) {
    auto r = decodeGribField(bytes, f, wanted, limits, kept);
    if (!r && r.error().code == ErrorCode::TooLarge)
      return fail(ErrorCode::TooLarge, std::string(sourceName) + ": " + r.error().detail);
    if (!r)
      file.skipped.push_back({f.message, f.field, r.error().detail});
    else if (*r)
      file.fields.push_back(std::move(**r));
  }
  std::sort(file.skipped.begin(), file.skipped.end(),
            [](const GribSkip& a, const GribSkip& b) { return std::tie(a.message, a.field) < std::tie(b.message, b.field); });
  return file;
}

}  // namespace sky::server
