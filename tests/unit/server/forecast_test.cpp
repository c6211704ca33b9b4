// GRIB2 decoded in decoder processes (grib_isolated.hpp), damaged files
// included, and the forecast's layers (forecast.hpp) checked at named grid
// points against grib_get_data's values of the fields they come from.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>

#include "grib_tools.hpp"
#include "sky/server/forecast.hpp"
#include "sky/server/forecast_files.hpp"
#include "sky/server/grib_isolated.hpp"
#include "sky/weather/precipitation.hpp"

namespace sky::server {
namespace {

GribDecoder decoder() {
  GribDecoder d;
  d.executable = SKY_GRIB_DECODER;
  return d;
}

GribFile isolated(const std::string& path, GribSelection selection = GribSelection::All) {
  auto r = readGribIsolated(path, std::filesystem::path(path).filename().string(), selection, decoder());
  EXPECT_TRUE(r) << (r ? "" : r.error().detail);
  return r ? *r : GribFile{};
}

TEST(GribIsolated, ReadsWhatTheInProcessReaderReads) {
  for (const std::string& path : {kGfs, kNam}) {
    const GribFile child = isolated(path);
    auto own = readGrib(readBytes(path), "own", [](const GribMeta&) { return true; });
    ASSERT_TRUE(own);
    EXPECT_EQ(child.messages, own->messages);
    EXPECT_EQ(child.fieldCount, own->fieldCount);
    ASSERT_EQ(child.fields.size(), own->fields.size());
    for (std::size_t k = 0; k < own->fields.size(); ++k) {
      EXPECT_EQ(child.fields[k].meta.field, own->fields[k].meta.field);
      EXPECT_EQ(child.fields[k].meta.shortName, own->fields[k].meta.shortName);
      EXPECT_TRUE(child.fields[k].meta.grid == own->fields[k].meta.grid);
      EXPECT_EQ(0, std::memcmp(child.fields[k].values.data(), own->fields[k].values.data(),
                               own->fields[k].values.size() * sizeof(float)));
    }
  }
  // The forecast's selection keeps the cover and wind, not the total cover.
  const GribFile gfs = isolated(kGfs, GribSelection::Forecast);
  EXPECT_EQ(gfs.fields.size(), 7u);
}

// Damage in every section of the first messages: the decoder may die on a
// message (ecCodes reads out of bounds on some of these), the server's side
// never does, and every other message is still read.
TEST(GribIsolated, DamagedMessagesCostThemselvesOnly) {
  const auto gfs = readBytes(kGfs);
  const auto dir = std::filesystem::temp_directory_path() / ("sky_grib_damage_" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  int died = 0, skippedOther = 0, runs = 0;
  // Each byte of the first message's sections 1 to 5 set to 0xff in turn
  // (section 5 holds the packing's parameters: ecCodes read out of bounds on
  // some of these in this process before it had a decoder process).
  // Byte 198 at 0xff makes ecCodes 2.28 read out of bounds (SIGSEGV when it
  // ran in the reader's process: found by setting each of the first 1200
  // bytes to 0x00, 0x7f, 0x80 and 0xff; bytes 198 and 199 crash it).
  std::vector<std::size_t> bytes{198, 199};
  for (std::size_t at = 16; at < 190; at += 3) bytes.push_back(at);
  for (std::size_t at : bytes) {
    std::vector<std::byte> bad = gfs;
    bad[at] = std::byte{0xff};
    const auto path = dir / "bad.grib2";
    std::ofstream(path, std::ios::binary).write(reinterpret_cast<const char*>(bad.data()), static_cast<std::streamsize>(bad.size()));
    auto r = readGribIsolated(path, "bad.grib2", GribSelection::All, decoder());
    ASSERT_TRUE(r) << "byte " << at << ": " << r.error().detail;
    ++runs;
    // Messages 2-8 are untouched: all read.
    EXPECT_EQ(std::count_if(r->fields.begin(), r->fields.end(), [](const GribField& f) { return f.meta.message >= 2; }), 7)
        << "byte " << at;
    for (const GribSkip& s : r->skipped) {
      EXPECT_EQ(s.message, 1u) << s.reason;
      if (s.reason.find("decoder died") != std::string::npos) ++died;
      else ++skippedOther;
    }
  }
  std::filesystem::remove_all(dir);
  EXPECT_GE(died, 2);  // 198 and 199: the decoder died, the server did not
  std::printf("[ damage ] %d files with one damaged byte: the decoder died on %d, %d skipped with ecCodes' reason\n",
              runs, died, skippedOther);
}

TEST(GribIsolated, MissingDecoderOrFileIsAClearError) {
  GribDecoder none;
  none.executable = "/nonexistent/skyshell-grib-decode";
  auto r = readGribIsolated(kGfs, "gfs", GribSelection::All, none);
  ASSERT_FALSE(r);
  EXPECT_NE(r.error().detail.find("cannot start"), std::string::npos) << r.error().detail;
  auto missing = readGribIsolated("/nonexistent.grib2", "x.grib2", GribSelection::All, decoder());
  ASSERT_FALSE(missing);
  EXPECT_EQ(missing.error().code, ErrorCode::Io);
  GribDecoder small = decoder();
  small.maxFileBytes = 1000;
  auto big = readGribIsolated(kGfs, "gfs", GribSelection::All, small);
  ASSERT_FALSE(big);
  EXPECT_EQ(big.error().code, ErrorCode::TooLarge);
}

const ForecastLayer* layerOf(const Forecast& f, std::uint32_t id) {
  for (const auto& l : f.layers())
    if (l.layer.id == id) return &l;
  return nullptr;
}

TEST(Forecast, GfsLayersAreTheCoverOfTheirMessages) {
  const GribFile file = isolated(kGfs, GribSelection::Forecast);
  auto fc = Forecast::fromGrib({&file}, "gfs.grib2");
  ASSERT_TRUE(fc) << fc.error().detail;
  ASSERT_EQ(fc->layers().size(), 5u);
  EXPECT_EQ(fc->stepCount(), 1u);
  EXPECT_EQ(fc->firstValid_unix(), 1294660800 + 120 * 3600);
  // Layer slot -> the field (grib_get_data's count) its cover is.
  const std::map<std::uint32_t, std::size_t> fieldOf = {{kForecastLowSlot, 1}, {kForecastMiddleSlot, 2},
                                                        {kForecastHighSlot, 3}, {kForecastConvectiveSlot, 5},
                                                        {kForecastBoundarySlot, 6}};
  for (const auto& [slot, field] : fieldOf) {
    const ForecastLayer* l = layerOf(*fc, slot);
    ASSERT_NE(l, nullptr) << slot;
    const auto truth = gribGetData(kGfs, field);
    ASSERT_EQ(truth.size(), 144u * 73u);
    double worst = 0;
    int cloudy = 0;
    for (std::size_t k = 0; k < truth.size(); k += 7) {
      const Point& p = truth[k];
      const float c = fc->coverage(*l, p.lat, p.lon, fc->firstValid_unix());
      worst = std::max(worst, std::abs(c - p.value / 100));
      cloudy += p.value > 50;
    }
    EXPECT_LT(worst, 1e-5) << "layer " << slot;
    EXPECT_GT(cloudy, 10) << "layer " << slot;  // the named field is not all clear
    EXPECT_EQ(l->layer.coverage, 0);
  }
  EXPECT_EQ(layerOf(*fc, kForecastHighSlot)->layer.type, weather::CloudType::Cirrus);
  // No layer limits in this file: typical heights, said so.
  EXPECT_NE(layerOf(*fc, kForecastLowSlot)->heightFrom.find("typical"), std::string::npos);
  // The convective layer blends to cumulonimbus where its cover is large.
  const auto conv = gribGetData(kGfs, 5);
  const auto big = std::max_element(conv.begin(), conv.end(), [](const Point& a, const Point& b) { return a.value < b.value; });
  ASSERT_GT(big->value, 70);
  const auto t = fc->tileAt(*layerOf(*fc, kForecastConvectiveSlot), big->lat, big->lon, fc->firstValid_unix());
  EXPECT_EQ(t.blendType, weather::CloudType::Cumulonimbus);
  EXPECT_FLOAT_EQ(t.blend, 1.0f);
  const std::string src = fc->sourceAt(*layerOf(*fc, kForecastLowSlot), 45, 10, fc->firstValid_unix());
  EXPECT_NE(src.find("gfs.grib2: tcc lowCloudLayer, field 1, grid point (4, 18) at 45.00, 10.00"), std::string::npos) << src;
}

// Sundqvist's cover from relative humidity, written out here from the formula.
double sundqvist(double rhPercent) {
  const double u = std::clamp(rhPercent / 100, 0.0, 1.0);
  return u <= 0.8 ? 0 : 1 - std::sqrt((1 - u) / 0.2);
}

TEST(Forecast, NamCoverIsDerivedFromHumidityOnItsPressureLevels) {
  const GribFile file = isolated(kNam, GribSelection::Forecast);
  auto fc = Forecast::fromGrib({&file}, "nam.grib2");
  ASSERT_TRUE(fc) << fc.error().detail;
  const ForecastLayer* low = layerOf(*fc, kForecastLowSlot);
  const ForecastLayer* mid = layerOf(*fc, kForecastMiddleSlot);
  ASSERT_NE(low, nullptr);
  ASSERT_NE(mid, nullptr);
  // Relative humidity's fields by level (hPa), from grib_get_data.
  std::map<double, std::vector<Point>> rh;
  for (const GribField& f : file.fields)
    if (f.meta.shortName == "r" && f.meta.typeOfLevel == "isobaricInhPa") rh[f.meta.level / 100] = gribGetData(kNam, f.meta.field);
  ASSERT_GE(rh.size(), 15u);
  double worstLow = 0, worstMid = 0;
  int cloudyLow = 0;
  for (std::size_t k = 0; k < 93 * 65; k += 13) {
    double lowC = 0, midC = 0;
    for (const auto& [hpa, pts] : rh) {
      if (hpa > 642) lowC = std::max(lowC, sundqvist(pts[k].value));
      else if (hpa > 350) midC = std::max(midC, sundqvist(pts[k].value));
    }
    const Point& p = rh.begin()->second[k];
    worstLow = std::max(worstLow, std::abs(fc->coverage(*low, p.lat, p.lon, fc->firstValid_unix()) - lowC));
    worstMid = std::max(worstMid, std::abs(fc->coverage(*mid, p.lat, p.lon, fc->firstValid_unix()) - midC));
    cloudyLow += lowC > 0.5;
  }
  EXPECT_LT(worstLow, 1e-3);  // grid points found by locate() from grib_get_data's 6-decimal positions
  EXPECT_LT(worstMid, 1e-3);
  EXPECT_GT(cloudyLow, 5);
  // The low layer's base from NAM's cloud-base height.
  EXPECT_NE(low->heightFrom.find("gh cloudBase"), std::string::npos) << low->heightFrom;
  EXPECT_GT(low->layer.base_m, 0);
  EXPECT_LT(low->layer.base_m, 3000);
  EXPECT_GT(mid->layer.base_m, low->layer.base_m);
  // Outside the Lambert grid: no cover, not 0.
  EXPECT_TRUE(std::isnan(fc->coverage(*low, 48, 11, fc->firstValid_unix())));
}

TEST(Forecast, EcmwfLowMediumHighCoverAreLayersToo) {
  // GFS's low, middle and high cover re-coded as ECMWF codes them (lcc, mcc,
  // hcc: discipline 0, category 6, numbers 3, 4, 5, on the surface) with
  // ecCodes' grib_set.
  const auto dir = std::filesystem::temp_directory_path() / ("sky_ecmwf_" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  std::string cat;
  for (int k = 0; k < 3; ++k) {
    const auto part = dir / ("part" + std::to_string(k) + ".grib2");
    // grib_set keeps the messages -w does not pick: grib_copy picks first.
    const auto one = dir / ("one" + std::to_string(k) + ".grib2");
    const std::string cmd = std::string(SKY_GRIB_COPY) + " -w count=" + std::to_string(k + 1) + " '" + kGfs + "' '" +
                            one.string() + "' && " + SKY_GRIB_SET + " -s centre=98,typeOfFirstFixedSurface=1,paramId=" +
                            std::to_string(3073 + k) + " '" + one.string() + "' '" + part.string() + "'";
    ASSERT_EQ(std::system(cmd.c_str()), 0) << cmd;
    std::ifstream in(part, std::ios::binary);
    cat += std::string(std::istreambuf_iterator<char>(in), {});
  }
  std::ofstream(dir / "ecmwf.grib2", std::ios::binary) << cat;
  const GribFile file = isolated((dir / "ecmwf.grib2").string(), GribSelection::Forecast);
  std::filesystem::remove_all(dir);
  ASSERT_EQ(file.fields.size(), 3u);
  EXPECT_EQ(file.fields[0].meta.shortName, "lcc");
  auto fc = Forecast::fromGrib({&file}, "ecmwf.grib2");
  ASSERT_TRUE(fc) << fc.error().detail;
  ASSERT_EQ(fc->layers().size(), 3u);
  const std::uint32_t slots[] = {kForecastLowSlot, kForecastMiddleSlot, kForecastHighSlot};
  for (int k = 0; k < 3; ++k) {
    const ForecastLayer* l = layerOf(*fc, slots[k]);
    ASSERT_NE(l, nullptr);
    const auto truth = gribGetData(kGfs, k + 1);
    for (std::size_t p = 0; p < truth.size(); p += 97)
      EXPECT_NEAR(fc->coverage(*l, truth[p].lat, truth[p].lon, fc->firstValid_unix()), truth[p].value / 100, 1e-5);
  }
}

TEST(Forecast, StepsAreInterpolatedInTime) {
  // Two steps of the GFS file: the second its values halved, 6 h later.
  GribFile a = isolated(kGfs, GribSelection::Forecast);
  GribFile b = a;
  for (GribField& f : b.fields) {
    f.meta.valid_unix += 6 * 3600;
    for (float& v : f.values) v *= 0.5f;
  }
  auto fc = Forecast::fromGrib({&a, &b}, "two steps");
  ASSERT_TRUE(fc);
  EXPECT_EQ(fc->stepCount(), 2u);
  const ForecastLayer& low = *layerOf(*fc, kForecastLowSlot);
  const double t0 = static_cast<double>(fc->firstValid_unix());
  const float c0 = fc->coverage(low, 50, 10, t0);
  ASSERT_GT(c0, 0.1f);
  EXPECT_FLOAT_EQ(fc->coverage(low, 50, 10, t0 + 3 * 3600), c0 * 0.75f);
  EXPECT_FLOAT_EQ(fc->coverage(low, 50, 10, t0 + 6 * 3600), c0 * 0.5f);
  EXPECT_FLOAT_EQ(fc->coverage(low, 50, 10, t0 + 48 * 3600), c0 * 0.5f);  // after the last: the last
  EXPECT_FLOAT_EQ(fc->coverage(low, 50, 10, t0 - 3600), c0);              // before the first: the first
}

TEST(Forecast, AFileWithoutCloudIsRefusedByName) {
  GribFile wind = isolated(kGfs, GribSelection::Forecast);
  std::erase_if(wind.fields, [](const GribField& f) { return f.meta.category == 6; });
  auto fc = Forecast::fromGrib({&wind}, "wind-only.grib2");
  ASSERT_FALSE(fc);
  EXPECT_NE(fc.error().detail.find("wind-only.grib2: no field gives cloud cover"), std::string::npos);
}

}  // namespace
}  // namespace sky::server

namespace sky::server {
namespace {

// A GFS surface precipitation rate (prate) with its categorical snow: made
// from the sample's low-cloud message by grib_set (the samples have no
// precipitation), its values scaled to kg m-2 s-1 (cover % x 1e-5: up to
// 3.6 mm/h), next to the sample's cloud layers. The precipitation layer's
// tiles cover the points with at least 0.1 mm/h at the density of their
// rate (grib_get_data's value x 3600, through precipitation.hpp's law), it
// reaches from the ground into the lowest cloud layer, and it is snow where
// the categorical field says snow at most raining points.
TEST(Forecast, PrecipitationRateIsALayerOfItsRate) {
  const auto dir = std::filesystem::temp_directory_path() / ("sky-prate-" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  const auto one = dir / "one.grib2", prate = dir / "prate.grib2", csnow = dir / "csnow.grib2";
  const std::string cmd =
      std::string(SKY_GRIB_COPY) + " -w count=1 '" + kGfs + "' '" + one.string() + "' && " + SKY_GRIB_SET +
      " -s discipline=0,parameterCategory=1,parameterNumber=7,typeOfFirstFixedSurface=1,"
      "typeOfSecondFixedSurface=255,scaleValuesBy=0.00001 '" + one.string() + "' '" + prate.string() + "' && " +
      SKY_GRIB_SET + " -s discipline=0,parameterCategory=1,parameterNumber=195,typeOfFirstFixedSurface=1,"
      "typeOfSecondFixedSurface=255,scaleValuesBy=0.02 '" + one.string() + "' '" + csnow.string() + "'";
  ASSERT_EQ(std::system(cmd.c_str()), 0) << cmd;
  const GribFile rate = isolated(prate.string(), GribSelection::Forecast);
  const GribFile cloud = isolated(kGfs, GribSelection::Forecast);
  ASSERT_EQ(rate.fields.size(), 1u) << "the decoder keeps prate";
  auto fc = Forecast::fromGrib({&cloud, &rate}, "gfs+prate");
  ASSERT_TRUE(fc) << fc.error().detail;
  const ForecastLayer* p = layerOf(*fc, kForecastPrecipitationSlot);
  ASSERT_NE(p, nullptr);
  EXPECT_EQ(p->layer.type, weather::CloudType::Rain) << "no categorical field: rain";
  EXPECT_EQ(p->layer.base_m, 0.0);
  double lowest = 1e9;
  for (const auto& l : fc->layers())
    if (l.layer.id != kForecastPrecipitationSlot) lowest = std::min(lowest, l.layer.base_m);
  EXPECT_EQ(p->layer.thickness_m, lowest + 500.0) << "into the lowest cloud layer";
  const auto truth = gribGetData(prate.string(), 1);  // kg m-2 s-1, as ecCodes decodes them
  ASSERT_EQ(truth.size(), 144u * 73u);
  int raining = 0, dry = 0;
  for (std::size_t k = 0; k < truth.size(); k += 5) {
    const double mmph = truth[k].value * 3600;
    const weather::CoverageTile t = fc->tileAt(*p, truth[k].lat, truth[k].lon, fc->firstValid_unix());
    if (mmph >= kMinForecastPrecipitation_mmph + 1e-3) {
      ++raining;
      EXPECT_EQ(t.coverage, 1.0f);
      EXPECT_NEAR(t.density, weather::precipitationDensityForRate(weather::CloudType::Rain, mmph), 1e-4) << mmph;
    } else if (mmph < kMinForecastPrecipitation_mmph - 1e-3) {
      ++dry;
      EXPECT_EQ(t.coverage, 0.0f) << mmph;
    }
  }
  EXPECT_GT(raining, 100);
  EXPECT_GT(dry, 100);
  // With csnow (the cover's % x 0.02: 1 where the low cloud covers more
  // than half, which is most raining points), the layer is snow.
  const GribFile snow = isolated(csnow.string(), GribSelection::Forecast);
  ASSERT_EQ(snow.fields.size(), 1u) << "the decoder keeps csnow";
  auto wintry = Forecast::fromGrib({&cloud, &rate, &snow}, "gfs+prate+csnow");
  ASSERT_TRUE(wintry) << wintry.error().detail;
  const ForecastLayer* s = layerOf(*wintry, kForecastPrecipitationSlot);
  ASSERT_NE(s, nullptr);
  std::size_t snowy = 0, wet = 0;
  const auto cover = gribGetData(kGfs, 1);  // csnow is this cover (%) x 0.02
  for (std::size_t k = 0; k < cover.size(); ++k)
    if (truth[k].value * 3600 >= kMinForecastPrecipitation_mmph) (cover[k].value * 0.02 > 0.5 ? snowy : wet)++;
  EXPECT_EQ(s->layer.type, snowy > wet ? weather::CloudType::Snow : weather::CloudType::Rain)
      << snowy << " snowy, " << wet << " wet points";
  EXPECT_GT(snowy, wet) << "the sample's low cloud is mostly over half where it is over 3 %";
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace sky::server

namespace sky::test {
namespace {

// A saved forecast naming more files than a load takes (a NATS entry from
// elsewhere) is refused before any file is fetched.
TEST(ForecastLoader, MoreFilesThanALoadTakesAreRefusedUnread) {
  std::size_t fetched = 0;
  const auto load = server::forecastLoader(
      [&](const std::string&) -> Result<std::vector<std::byte>> {
        ++fetched;
        return fail(ErrorCode::Io, "not here");
      },
      server::GribDecoder{});
  nlohmann::json saved = {{"name", "many"}, {"anchor_clock_s", 0.0}, {"anchor_valid_unix", 0}};
  for (std::size_t k = 0; k <= server::kMaxGribFiles; ++k)
    saved["files"].push_back({{"key", "0123abcd-1"}, {"name", "f.grib2"}});
  const auto refused = load(saved);
  ASSERT_FALSE(refused);
  EXPECT_EQ(refused.error().code, ErrorCode::TooLarge) << refused.error().detail;
  EXPECT_EQ(fetched, 0u);
  saved["files"].erase(saved["files"].begin());  // kMaxGribFiles: fetched, and refused at the first
  EXPECT_EQ(load(saved).error().code, ErrorCode::Io);
  EXPECT_EQ(fetched, 1u);
}

}  // namespace
}  // namespace sky::test
