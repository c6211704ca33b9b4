// CIGI date and time of day <-> UTC (see celestial_time.hpp).
#include "sky/cigi/celestial_time.hpp"

namespace sky::cigi {

namespace {
constexpr std::int64_t kSecondsPerDay = 86400;

// Days since 1970-01-01 of a proleptic Gregorian date (H. Hinnant,
// "chrono-Compatible Low-Level Date Algorithms", days_from_civil).
std::int64_t daysFromCivil(std::int64_t y, std::int64_t m, std::int64_t d) {
  y -= m <= 2 ? 1 : 0;
  const std::int64_t era = (y >= 0 ? y : y - 399) / 400;
  const std::int64_t yoe = y - era * 400;
  const std::int64_t doy = (153 * (m > 2 ? m - 3 : m + 9) + 2) / 5 + d - 1;
  const std::int64_t doe = yoe * 365 + yoe / 4 - yoe / 100 + doy;
  return era * 146097 + doe - 719468;
}

bool isLeap(std::int64_t y) { return (y % 4 == 0 && y % 100 != 0) || y % 400 == 0; }

std::int64_t daysInMonth(std::int64_t y, std::int64_t m) {
  constexpr int kDays[12] = {31, 28, 31, 30, 31, 30, 31, 31, 30, 31, 30, 31};
  return m == 2 && isLeap(y) ? 29 : kDays[m - 1];
}
}  // namespace

CelestialSphereControl celestialAt(std::int64_t utc_s) {
  // Civil date from days since 1970-01-01 (Hinnant's civil_from_days).
  const std::int64_t days = utc_s >= 0 ? utc_s / kSecondsPerDay : (utc_s - (kSecondsPerDay - 1)) / kSecondsPerDay;
  const std::int64_t secs = utc_s - days * kSecondsPerDay;
  const std::int64_t z = days + 719468;
  const std::int64_t era = (z >= 0 ? z : z - 146096) / 146097;
  const std::int64_t doe = z - era * 146097;
  const std::int64_t yoe = (doe - doe / 1460 + doe / 36524 - doe / 146096) / 365;
  const std::int64_t doy = doe - (365 * yoe + yoe / 4 - yoe / 100);
  const std::int64_t mp = (5 * doy + 2) / 153;
  const std::int64_t day = doy - (153 * mp + 2) / 5 + 1;
  const std::int64_t month = mp < 10 ? mp + 3 : mp - 9;
  const std::int64_t year = yoe + era * 400 + (month <= 2 ? 1 : 0);
  CelestialSphereControl c;
  c.hour = static_cast<std::uint8_t>(secs / 3600);
  c.minute = static_cast<std::uint8_t>(secs / 60 % 60);
  c.dateTimeValid = true;
  c.ephemerisEnable = true;
  c.dateMmddyyyy = static_cast<std::uint32_t>(month * 1000000 + day * 10000 + year);
  return c;
}

std::optional<std::int64_t> celestialUtc(const CelestialSphereControl& c) {
  const std::int64_t month = c.dateMmddyyyy / 1000000;
  const std::int64_t day = c.dateMmddyyyy / 10000 % 100;
  const std::int64_t year = c.dateMmddyyyy % 10000;
  if (year < kCelestialMinYear || year > kCelestialMaxYear || month < 1 || month > 12 || day < 1 ||
      day > daysInMonth(year, month) || c.hour > 23 || c.minute > 59)
    return std::nullopt;
  return daysFromCivil(year, month, day) * kSecondsPerDay + c.hour * 3600 + c.minute * 60;
}

}  // namespace sky::cigi
