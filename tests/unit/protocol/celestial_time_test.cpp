// CIGI Celestial Sphere Control date/time <-> UTC, against instants computed
// independently (Python's datetime, calendar.timegm), and the dates the
// decoder must drop.
#include <gtest/gtest.h>

#include "sky/cigi/celestial_time.hpp"
#include "sky/cigi/codec.hpp"

namespace sky::cigi {
namespace {

TEST(CelestialTime, ConvertsUtcToCigiDateAndTime) {
  auto c = celestialAt(0);
  EXPECT_EQ(c.dateMmddyyyy, 1011970u);
  EXPECT_EQ(c.hour, 0);
  // 2026-11-21 22:21:24 UTC (the FlightGear capture's cur_time).
  c = celestialAt(1795299684);
  EXPECT_EQ(c.dateMmddyyyy, 11212026u);
  EXPECT_EQ(c.hour, 22);
  EXPECT_EQ(c.minute, 21);
  // 2000-02-29 23:59:59: a leap day of a century year divisible by 400.
  c = celestialAt(951782400 + 86399);
  EXPECT_EQ(c.dateMmddyyyy, 2292000u);
  EXPECT_EQ(c.hour, 23);
  EXPECT_EQ(c.minute, 59);
  EXPECT_TRUE(c.dateTimeValid);
}

TEST(CelestialTime, ConvertsCigiDateAndTimeToUtc) {
  CelestialSphereControl c;
  // 2016-11-08 01:37 UTC: calendar.timegm((2016, 11, 8, 1, 37, 0)) = 1478569020.
  c.dateMmddyyyy = 11082016;
  c.hour = 1;
  c.minute = 37;
  EXPECT_EQ(celestialUtc(c), 1478569020);
  // 1900-03-01 00:00 (before 1970, after the skipped 1900 leap day): -2203891200.
  c.dateMmddyyyy = 3011900;
  c.hour = c.minute = 0;
  EXPECT_EQ(celestialUtc(c), -2203891200);
  // Round trip, to the minute, over a spread of instants 1970-2100.
  for (std::int64_t t = 0; t < 4102444800; t += 86400 * 37 + 3671) {
    const auto back = celestialUtc(celestialAt(t));
    ASSERT_TRUE(back) << t;
    EXPECT_EQ(*back, t - t % 60) << t;
  }
}

TEST(CelestialTime, RejectsDatesThatAreNotDates) {
  CelestialSphereControl c;
  // Month 13, day 0, 30 February, 29 February of a common year, 31 April,
  // years 1899, 2101 and 9999, and 0.
  for (std::uint32_t date : {13012020u, 1002020u, 2302020u, 2292019u, 4312020u, 1011899u, 1012101u, 1019999u, 0u}) {
    c.dateMmddyyyy = date;
    EXPECT_FALSE(celestialUtc(c)) << date;
  }
  c.dateMmddyyyy = 2292020u;  // a leap day
  EXPECT_TRUE(celestialUtc(c));
  c.hour = 24;
  EXPECT_FALSE(celestialUtc(c));
}

// The decoder drops a datagram whose valid date is not a date, and keeps one
// whose date it was told to ignore.
TEST(CelestialTime, DecoderDropsInvalidDatesOnlyWhenMarkedValid) {
  for (const ByteOrder order : {ByteOrder::Big, ByteOrder::Little}) {
    CelestialSphereControl c = celestialAt(1478569020);
    c.dateMmddyyyy = 2302016;  // 30 February
    auto bytes = DatagramWriter(order).add(IgControl{}).add(c).bytes();
    const auto bad = decodeDatagram(bytes);
    ASSERT_FALSE(bad);
    EXPECT_EQ(bad.error().code, ErrorCode::InvalidArgument);
    c.dateTimeValid = false;
    bytes = DatagramWriter(order).add(IgControl{}).add(c).bytes();
    EXPECT_TRUE(decodeDatagram(bytes));
  }
}

}  // namespace
}  // namespace sky::cigi
