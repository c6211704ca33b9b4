// The GRIB2 reader and grid geometry (server/src/grib*.cpp) against ecCodes'
// own command-line decode (grib_get_data) on the real GFS and NAM samples,
// and against messages encoded here with ecCodes from its samples: both
// scanning directions, columns consecutive, a bitmap of missing points,
// simple, JPEG 2000, CCSDS and IEEE packing (complex packing: the GFS
// sample), the 0/360 seam and the poles. Hostile files are skipped
// or refused with a reason.
#include <eccodes.h>
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <iterator>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

#include "grib_tools.hpp"
#include "sky/server/grib.hpp"

namespace sky::server {
namespace {

GribFile readAll(const std::vector<std::byte>& bytes) {
  auto file = readGrib(bytes, "test", [](const GribMeta&) { return true; });
  EXPECT_TRUE(file) << (file ? "" : file.error().detail);
  return file ? *file : GribFile{};
}

TEST(Grib, GfsEveryValueAndPointMatchesGribGetData) {
  const GribFile file = readAll(readBytes(kGfs));
  ASSERT_EQ(file.fields.size(), 8u);
  EXPECT_TRUE(file.skipped.empty());
  for (const GribField& f : file.fields) {
    SCOPED_TRACE("field " + std::to_string(f.meta.field) + " " + f.meta.shortName + " " + f.meta.typeOfLevel);
    const GribGrid& g = f.meta.grid;
    EXPECT_EQ(g.projection, GribGrid::Projection::LatLon);
    EXPECT_EQ(g.ni, 144);
    EXPECT_EQ(g.nj, 73);
    EXPECT_TRUE(isGlobalInLongitude(g));
    const auto truth = gribGetData(kGfs, f.meta.field);
    ASSERT_EQ(truth.size(), f.values.size());
    double worstValue = 0, worstPos = 0;
    for (int j = 0; j < g.nj; ++j)
      for (int i = 0; i < g.ni; ++i) {
        const std::size_t k = valueIndex(g, i, j);
        const Point& t = truth[k];
        worstValue = std::max(worstValue, std::abs(f.values[k] - t.value));
        const LatLon at = gridLatLon(g, i, j);
        worstPos = std::max({worstPos, std::abs(at.lat_deg - t.lat), t.lat == 90 || t.lat == -90 ? 0 : lonDiff(at.lon_deg, t.lon)});
        // At a grid point the field reads its own value.
        ASSERT_NEAR(sampleField(g, f.values, t.lat, t.lon), t.value, 1e-3) << "at " << t.lat << ", " << t.lon;
      }
    EXPECT_LT(worstValue, 1e-4 * 100);  // % and m/s, printed with 6 decimals
    EXPECT_LT(worstPos, 1e-6);
  }
  // The named cases: 2011-01-10 12Z + 120 h, cloud cover in %.
  const GribField& low = file.fields[0];
  EXPECT_EQ(low.meta.shortName, "tcc");
  EXPECT_EQ(low.meta.levelType, 214);
  EXPECT_EQ(low.meta.units, "%");
  EXPECT_EQ(low.meta.reference_unix, 1294660800);        // 2011-01-10T12:00Z
  EXPECT_EQ(low.meta.valid_unix, 1294660800 + 120 * 3600);
  const auto truth = gribGetData(kGfs, 1);
  auto value = [&](double lat, double lon) {
    for (const Point& p : truth)
      if (std::abs(p.lat - lat) < 1e-6 && lonDiff(p.lon, lon) < 1e-6) return p.value;
    ADD_FAILURE() << "no grid point " << lat << ", " << lon;
    return 0.0;
  };
  // Across the 0/360 seam: halfway between 357.5 E and 0 E, from either side.
  const double seam = (value(45, 357.5) + value(45, 0)) / 2;
  EXPECT_NEAR(sampleField(low.meta.grid, low.values, 45, 358.75), seam, 1e-3);
  EXPECT_NEAR(sampleField(low.meta.grid, low.values, 45, -1.25), seam, 1e-3);
  // At the poles every longitude reads the pole row.
  for (double lon : {0.0, 33.3, -170.0, 179.99})
    EXPECT_NEAR(sampleField(low.meta.grid, low.values, 90, lon), value(90, 0), 1e-3);
  EXPECT_NEAR(sampleField(low.meta.grid, low.values, -90, 12), value(-90, 0), 1e-3);
  // Between rows and columns: bilinear.
  const double mid = (value(50, 10) + value(50, 12.5) + value(47.5, 10) + value(47.5, 12.5)) / 4;
  EXPECT_NEAR(sampleField(low.meta.grid, low.values, 48.75, 11.25), mid, 1e-3);
}

TEST(Grib, NamLambertGridMatchesGribGetDataEverywhere) {
  const GribFile file = readAll(readBytes(kNam));
  EXPECT_EQ(file.messages, 154u);
  EXPECT_EQ(file.fieldCount, 181u);  // some messages hold several fields
  ASSERT_FALSE(file.fields.empty());
  for (const GribSkip& s : file.skipped) ADD_FAILURE() << "message " << s.message << ": " << s.reason;
  const GribField* base = nullptr;
  for (const GribField& f : file.fields)
    if (f.meta.shortName == "gh" && f.meta.typeOfLevel == "cloudBase") base = &f;
  ASSERT_NE(base, nullptr);
  const GribGrid& g = base->meta.grid;
  EXPECT_EQ(g.projection, GribGrid::Projection::Lambert);
  EXPECT_EQ(g.ni, 93);
  EXPECT_EQ(g.nj, 65);
  EXPECT_DOUBLE_EQ(g.radius_m, 6371229);
  const auto truth = gribGetData(kNam, base->meta.field);
  ASSERT_EQ(truth.size(), base->values.size());
  double worstPos = 0, worstIndex = 0, worstValue = 0;
  for (int j = 0; j < g.nj; ++j)
    for (int i = 0; i < g.ni; ++i) {
      const Point& t = truth[valueIndex(g, i, j)];
      const LatLon at = gridLatLon(g, i, j);
      worstPos = std::max({worstPos, std::abs(at.lat_deg - t.lat), lonDiff(at.lon_deg, t.lon)});
      const auto p = locate(g, t.lat, t.lon);
      ASSERT_TRUE(p) << i << ", " << j;
      worstIndex = std::max({worstIndex, std::abs(p->i - i), std::abs(p->j - j)});
      worstValue = std::max(worstValue, std::abs(base->values[valueIndex(g, i, j)] - t.value));
    }
  // ecCodes and Snyder's formulas here agree within 0.0005 degree (about
  // 50 m, 0.1 % of the 81 km step) at the far corner: a relative difference
  // of about 1e-5 in the scale, far below anything a cloud layer shows.
  EXPECT_LT(worstPos, 1e-3);
  EXPECT_LT(worstIndex, 2e-3);
  EXPECT_LT(worstValue, 1e-3);
  // Outside the grid (Europe, the south pole): nothing.
  EXPECT_FALSE(locate(g, 48, 11));
  EXPECT_FALSE(locate(g, -90, 0));
  EXPECT_TRUE(std::isnan(sampleField(g, base->values, 48, 11)));
}

// A message made with ecCodes' encoder from its regular_ll sample.
struct Made {
  int ni = 6, nj = 5;
  double lat1 = 50, lat2 = 30, lon1 = 350, lon2 = 15;  // 5 degree steps across the seam
  bool iNegative = false, jPositive = false, jConsecutive = false;
  std::string packing = "grid_simple";
  std::vector<double> values;  // in the message's order; 9999 marks missing
};

std::vector<std::byte> encode(const Made& m) {
  codes_handle* h = codes_grib_handle_new_from_samples(nullptr, "regular_ll_sfc_grib2");
  EXPECT_NE(h, nullptr);
  auto setL = [&](const char* k, long v) { EXPECT_EQ(codes_set_long(h, k, v), 0) << k; };
  auto setD = [&](const char* k, double v) { EXPECT_EQ(codes_set_double(h, k, v), 0) << k; };
  setL("Ni", m.ni);
  setL("Nj", m.nj);
  setL("iScansNegatively", m.iNegative);
  setL("jScansPositively", m.jPositive);
  setL("jPointsAreConsecutive", m.jConsecutive);
  setD("latitudeOfFirstGridPointInDegrees", m.lat1);
  setD("latitudeOfLastGridPointInDegrees", m.lat2);
  setD("longitudeOfFirstGridPointInDegrees", m.lon1);
  setD("longitudeOfLastGridPointInDegrees", m.lon2);
  setD("iDirectionIncrementInDegrees", 5);
  setD("jDirectionIncrementInDegrees", 5);
  setL("bitmapPresent", 1);
  setD("missingValue", 9999);
  EXPECT_EQ(codes_set_double_array(h, "values", m.values.data(), m.values.size()), 0);
  // Repacked from simple packing. Complex packing is not among them: ecCodes
  // 2.28 encodes a field this small wrongly (its own grib_get_data reads
  // other values back), so the real GFS sample above stands for it.
  std::size_t len = m.packing.size();
  EXPECT_EQ(codes_set_string(h, "packingType", m.packing.c_str(), &len), 0);
  EXPECT_EQ(codes_set_double_array(h, "values", m.values.data(), m.values.size()), 0);
  const void* msg = nullptr;
  std::size_t size = 0;
  EXPECT_EQ(codes_get_message(h, &msg, &size), 0);
  std::vector<std::byte> out(size);
  std::memcpy(out.data(), msg, size);
  codes_handle_delete(h);
  return out;
}

// Value of grid point (i, j) in `made`: 10 i + j, or missing at (2, 1).
double madeValue(int i, int j) { return i == 2 && j == 1 ? 9999 : 10.0 * i + j + 0.25; }

TEST(Grib, EveryScanningOrderAndPackingReadsTheSameField) {
  for (bool iNegative : {false, true})
    for (bool jPositive : {false, true})
      for (bool jConsecutive : {false, true})
        for (const char* packing : {"grid_simple", "grid_jpeg", "grid_ccsds", "grid_ieee"}) {
          Made m;
          m.iNegative = iNegative;
          m.jPositive = jPositive;
          m.jConsecutive = jConsecutive;
          m.packing = packing;
          if (iNegative) std::swap(m.lon1, m.lon2);
          if (jPositive) std::swap(m.lat1, m.lat2);
          m.values.resize(m.ni * m.nj);
          // (i, j) in geographic terms: i east from 350 E, j south from 50 N.
          auto geoOf = [&](int i, int j) { return std::pair{iNegative ? m.ni - 1 - i : i, jPositive ? m.nj - 1 - j : j}; };
          for (int j = 0; j < m.nj; ++j)
            for (int i = 0; i < m.ni; ++i) {
              const auto [gi, gj] = geoOf(i, j);
              const std::size_t k = jConsecutive ? static_cast<std::size_t>(i) * m.nj + j : static_cast<std::size_t>(j) * m.ni + i;
              m.values[k] = madeValue(gi, gj);
            }
          SCOPED_TRACE(std::string(packing) + (iNegative ? " i-" : " i+") + (jPositive ? " j+" : " j-") +
                       (jConsecutive ? " columns" : " rows"));
          const GribFile file = readAll(encode(m));
          ASSERT_EQ(file.fields.size(), 1u);
          const GribField& f = file.fields[0];
          EXPECT_FALSE(isGlobalInLongitude(f.meta.grid));
          for (int gj = 0; gj < m.nj; ++gj)
            for (int gi = 0; gi < m.ni; ++gi) {
              const double lat = 50 - 5 * gj, lon = 350 + 5 * gi;
              const float v = sampleField(f.meta.grid, f.values, lat, lon);
              if (madeValue(gi, gj) == 9999) {
                EXPECT_TRUE(std::isnan(v)) << "missing at " << lat << ", " << lon << " read " << v;
              } else {
                EXPECT_NEAR(v, madeValue(gi, gj), 1e-3) << lat << ", " << lon;
              }
            }
          // Beside the missing point (2, 1) = (45 N, 0 E): the other three
          // of its square carry the value, weighted as they were.
          const double a = madeValue(1, 1), c = madeValue(1, 2), d = madeValue(2, 2);
          const double w1 = 0.8 * 0.6, w3 = 0.8 * 0.4, w4 = 0.2 * 0.4;  // at 43 N, 356 E
          EXPECT_NEAR(sampleField(f.meta.grid, f.values, 43, -4), (w1 * a + w3 * c + w4 * d) / (w1 + w3 + w4), 1e-3);
          // Mostly missing: nothing.
          EXPECT_TRUE(std::isnan(sampleField(f.meta.grid, f.values, 45.5, 0.5)));
          // Outside: nothing; within half a step of the edge: the edge.
          EXPECT_TRUE(std::isnan(sampleField(f.meta.grid, f.values, 45, 20)));
          EXPECT_NEAR(sampleField(f.meta.grid, f.values, 51, 350), madeValue(0, 0), 1e-3);
          EXPECT_NEAR(sampleField(f.meta.grid, f.values, 50, 348), madeValue(0, 0), 1e-3);
        }
}

TEST(Grib, HostileFilesAreSkippedOrRefusedWithTheReason) {
  const auto gfs = readBytes(kGfs);
  // Not GRIB at all.
  const std::vector<std::byte> text(100, std::byte{'x'});
  auto none = readGrib(text, "notes.txt", [](const GribMeta&) { return true; });
  ASSERT_FALSE(none);
  EXPECT_NE(none.error().detail.find("notes.txt: no GRIB message"), std::string::npos);
  // Cut in the middle of the third message: two read, the third skipped.
  {
    const GribFile whole = readAll(gfs);
    ASSERT_EQ(whole.messages, 8u);
  }
  std::vector<std::byte> truncated(gfs.begin(), gfs.begin() + gfs.size() / 3);
  const GribFile part = readAll(truncated);
  ASSERT_FALSE(part.skipped.empty());
  EXPECT_NE(part.skipped[0].reason.find("runs past the end"), std::string::npos) << part.skipped[0].reason;
  EXPECT_GE(part.fields.size(), 1u);
  // A GRIB1 header, and a message whose stated length is huge.
  std::vector<std::byte> odd = gfs;
  odd[7] = std::byte{1};
  const GribFile grib1 = readAll(odd);
  ASSERT_FALSE(grib1.skipped.empty());
  EXPECT_NE(grib1.skipped[0].reason.find("GRIB edition 1"), std::string::npos);
  std::vector<std::byte> huge = gfs;
  huge[8] = std::byte{0x7f};
  const GribFile h = readAll(huge);
  ASSERT_FALSE(h.skipped.empty());
  EXPECT_EQ(h.skipped[0].message, 1u);
  EXPECT_EQ(h.fields.size(), 7u);  // the others are still read
  // Past the limits.
  GribLimits small;
  small.maxValuesKept = 20000;
  auto tooMuch = readGrib(gfs, "gfs", [](const GribMeta&) { return true; }, small);
  ASSERT_FALSE(tooMuch);
  EXPECT_EQ(tooMuch.error().code, ErrorCode::TooLarge);
  small = {};
  small.maxPointsPerMessage = 1000;
  const auto few = readGrib(gfs, "gfs", [](const GribMeta&) { return true; }, small);
  ASSERT_TRUE(few);
  EXPECT_EQ(few->skipped.size(), 8u);
}

}  // namespace
}  // namespace sky::server
