// Reading GRIB2 messages with ecCodes (grib.hpp). The file is split into
// messages here, by the lengths GRIB2's section 0 states, so a hostile length
// is refused before ecCodes sees the bytes; ecCodes then decodes each message
// from a copy. ecCodes reports through a logging callback (kept as the last
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
    codes_grib_multi_support_on(codes_context_get_default());
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

Result<GribSplit> splitGrib(std::span<const std::byte> bytes, std::string_view sourceName, const GribLimits& limits) {
  GribSplit split;
  std::size_t at = 0;
  while (at + kSection0Bytes <= bytes.size()) {
    const std::byte* p = bytes.data() + at;
    if (std::memcmp(p, "GRIB", 4) != 0) {
      ++at;
      continue;
    }
    const std::size_t message = ++split.found;
    if (split.found > limits.maxMessages)
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
    split.messages.push_back({message, at, static_cast<std::size_t>(length)});
    at += length;
  }
  if (split.found == 0)
    return fail(ErrorCode::Malformed,
                std::string(sourceName) + ": no GRIB message in " + std::to_string(bytes.size()) + " bytes");
  return split;
}

Result<std::size_t> decodeGribMessage(std::span<const std::byte> bytes, std::size_t messageNumber,
                                      std::size_t firstField, const GribWanted& wanted, const GribLimits& limits,
                                      std::size_t& kept, const std::function<void(GribField&&)>& sink,
                                      const std::function<void(GribSkip&&)>& skip) {
  codes_context* ctx = context();
  // ecCodes reads the fields of a multi-field message in place and advances
  // `data` past the message after its last one; the handles point into this
  // copy, so it outlives them.
  std::vector<std::byte> copy(bytes.begin(), bytes.end());
  void* data = copy.data();
  std::size_t length = copy.size();
  std::size_t fields = 0;
  while (length > 0) {
    lastEccodesMessage.clear();
    const std::size_t field = firstField + fields;
    try {
      int err = 0;
      Handle h(codes_grib_handle_new_from_multi_message(ctx, &data, &length, &err));
      if (!h) {
        if (fields == 0)
          skip({messageNumber, 0, "ecCodes could not decode it: " + ecError(err)});
        else if (err)
          skip({messageNumber, field, "ecCodes stopped in the message: " + ecError(err)});
        break;
      }
      ++fields;
      auto meta = metaOf(h.get(), messageNumber);
      if (!meta) {
        skip({messageNumber, field, meta.error().detail});
        continue;
      }
      meta->field = field;
      if (!wanted(*meta)) continue;
      const std::size_t points = static_cast<std::size_t>(meta->grid.ni) * meta->grid.nj;
      const auto declared = getLong(h.get(), "numberOfDataPoints");
      if (!declared || static_cast<std::size_t>(*declared) != points) {
        skip({messageNumber, field, "numberOfDataPoints differs from the grid's " + std::to_string(points)});
        continue;
      }
      if (points > limits.maxPointsPerMessage) {
        skip({messageNumber, field,
              std::to_string(points) + " points, more than " + std::to_string(limits.maxPointsPerMessage)});
        continue;
      }
      if (kept + points > limits.maxValuesKept)
        return fail(ErrorCode::TooLarge,
                    "the wanted fields hold more than " + std::to_string(limits.maxValuesKept) + " values");
      if (int e = codes_set_double(h.get(), "missingValue", kMissingSentinel); e) {
        skip({messageNumber, field, "missingValue: " + ecError(e)});
        continue;
      }
      std::size_t n = 0;
      if (int e = codes_get_size(h.get(), "values", &n); e || n != points) {
        skip({messageNumber, field,
              e ? "values: " + ecError(e) : std::to_string(n) + " values for " + std::to_string(points) + " points"});
        continue;
      }
      std::vector<double> raw(n);
      if (int e = codes_get_double_array(h.get(), "values", raw.data(), &n); e || n != points) {
        skip({messageNumber, field, "values: " + (e ? ecError(e) : std::string("short"))});
        continue;
      }
      GribField out{std::move(*meta), std::vector<float>(n)};
      for (std::size_t k = 0; k < n; ++k)
        out.values[k] = raw[k] >= kMissingSentinel * 0.5 || !std::isfinite(raw[k])
                            ? std::numeric_limits<float>::quiet_NaN()
                            : static_cast<float>(raw[k]);
      kept += n;
      sink(std::move(out));
    } catch (const EccodesAssertion& e) {
      skip({messageNumber, field, e.what()});
      break;
    }
  }
  return fields;
}

Result<GribFile> readGrib(std::span<const std::byte> bytes, std::string_view sourceName, const GribWanted& wanted,
                          const GribLimits& limits) {
  auto split = splitGrib(bytes, sourceName, limits);
  if (!split) return tl::unexpected(split.error());
  GribFile file;
  file.messages = split->found;
  file.skipped = std::move(split->skipped);
  std::size_t kept = 0;
  for (const GribMessageSpan& m : split->messages) {
    auto n = decodeGribMessage(
        bytes.subspan(m.offset, m.length), m.message, file.fieldCount + 1, wanted, limits, kept,
        [&](GribField&& f) { file.fields.push_back(std::move(f)); },
        [&](GribSkip&& s) { file.skipped.push_back(std::move(s)); });
    if (!n) return fail(n.error().code, std::string(sourceName) + ": " + n.error().detail);
    file.fieldCount += *n;
  }
  std::sort(file.skipped.begin(), file.skipped.end(),
            [](const GribSkip& a, const GribSkip& b) { return std::tie(a.message, a.field) < std::tie(b.message, b.field); });
  return file;
}

}  // namespace sky::server
