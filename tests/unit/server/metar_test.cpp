// METAR decoding and mapping: every report of a real selection (157 METAR/SPECI
// from NOAA and the metaf test data) decodes, its unknown groups skipped and
// named; the share whose sky maps; a list of real-world oddities (as reports
// really arrive from many countries) with what each must map to; the mapping
// per category; the refusals; the batch; inverse-distance interpolation
// between synthetic stations.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <map>
#include <optional>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "sky/geo/geodetic.hpp"
#include "sky/server/metar.hpp"
#include "sky/weather/precipitation.hpp"
#include "sky/weather/query.hpp"

namespace sky::server {
namespace {

using weather::CloudLayer;
using weather::CloudType;

constexpr double kFt = 0.3048;

// The visibility the mapped layers draw at the station: the fog's and the
// precipitation's extinctions (coverage x density x their constant) added.
double drawnVisibility_m(const std::vector<weather::CloudLayer>& layers) {
  double sigma = 0;
  for (const weather::CloudLayer& l : layers) {
    if (l.type == weather::CloudType::Fog) sigma += weather::kCloudExtinctionPerDensity_perm * l.coverage * l.density;
    if (weather::isPrecipitation(l.type))
      sigma += weather::kPrecipitationExtinctionPerDensity_perm * l.coverage * l.density;
  }
  return weather::koschmiederVisibility_m(sigma);
}

struct Row {
  std::string category, source, icao, date, report;
  std::string key() const { return category + " " + icao; }
};

std::vector<Row> loadRows() {
  std::ifstream in(std::string(SKY_METAR_DATA_DIR) + "/metar-coverage-selection.tsv");
  std::vector<Row> rows;
  std::string line;
  std::getline(in, line);  // header
  while (std::getline(in, line)) {
    if (line.empty()) continue;
    std::vector<std::string> cols;
    std::stringstream ss(line);
    std::string col;
    while (std::getline(ss, col, '\t')) cols.push_back(col);
    if (cols.size() != 5) continue;
    rows.push_back({cols[0], cols[1], cols[2], cols[3], cols[4]});
  }
  return rows;
}

Station stationFor(const std::string& icao) { return Station{icao, 45.0, 7.0, 120.0}; }

// Reports whose sky is not observed (they decode; the station's weather
// stays as it was), with the reason.
const std::set<std::string> kExpectedNotObserved = {
    "TS PAYA",         // AUTO report with no sky condition group at all
    "SPECI KMRH",      // "AUTO VCTS RMK": no wind, visibility or sky group
    "cloud//// EHSA",  // "/////////": amount and height unknown
    "cloud//// YBDV",  // "//////"
    "cloud//// YBRK",  // "//////"
    "Q YCAS",          // "//////"
    "AUTO WAOO",       // "//////"
};
// Reports refused by the mapping.
const std::set<std::string> kExpectedMapFailures = {
    "NIL CYSY",  // NIL: no observation (never read as a clear sky)
};

bool has(const std::vector<CloudLayer>& layers, auto pred) {
  return std::any_of(layers.begin(), layers.end(), pred);
}

TEST(MetarRealReports, AllRowsLoaded) { EXPECT_EQ(loadRows().size(), 157u); }

TEST(MetarRealReports, EveryReportDecodesItsUnknownGroupsNamed) {
  std::map<std::string, std::vector<std::string>> skipped, joined;  // by row key: the groups' texts
  for (const Row& row : loadRows()) {
    auto report = parseMetar(row.report);
    ASSERT_TRUE(report) << row.report << ": " << report.error().detail;
    EXPECT_EQ(report->icao, row.icao) << row.report;
    EXPECT_EQ(report->skippedCount, report->skipped.size());
    for (const MetarGroupNote& n : report->skipped) {
      skipped[row.key()].push_back(n.text);
      // The note's position and text are those of a group of the report.
      std::istringstream words(row.report);
      std::string word;
      for (std::size_t i = 0; i < n.position; ++i) words >> word;
      EXPECT_EQ(word, n.text) << row.report;
      EXPECT_FALSE(n.reason.empty());
    }
    for (const MetarGroupNote& n : report->joined) joined[row.key()].push_back(n.text);
  }
  // The two reports the strict decoder refused: "-1004SE" (an intensity sign
  // on a directional visibility) is skipped; "FEW050 CB" reads as FEW050CB.
  using Texts = std::map<std::string, std::vector<std::string>>;
  EXPECT_EQ(skipped, (Texts{{"MPS UKOO", {"-1004SE"}}}));
  EXPECT_EQ(joined, (Texts{{"DS/SS/SA/DU DRRT", {"CB"}}}));
}

TEST(MetarRealReports, MappingPerCategory) {
  std::set<std::string> mapFailures, notObserved;
  int read = 0;
  for (const Row& row : loadRows()) {
    auto report = parseMetar(row.report);
    if (!report) continue;
    SCOPED_TRACE(row.report);
    const Station station = stationFor(row.icao);
    auto sky = skyFromMetar(*report, station);
    if (!sky) {
      mapFailures.insert(row.key());
      EXPECT_EQ(sky.error().code, ErrorCode::InvalidArgument);
      continue;
    }
    if (!sky->observed) {
      notObserved.insert(row.key());
      EXPECT_TRUE(sky->layers.empty());
      continue;
    }
    ++read;
    const std::vector<CloudLayer>* layers = &sky->layers;
    for (std::size_t i = 0; i < layers->size(); ++i) {
      const CloudLayer& l = (*layers)[i];
      EXPECT_EQ(l.id, i + 1);
      EXPECT_TRUE(weather::validate(l).has_value());
      EXPECT_GE(l.base_m, station.elevation_m);
    }
    const std::string& c = row.category;
    auto coverageIs = [](double v) { return [v](const CloudLayer& l) { return l.coverage == v; }; };
    if (c == "FEW") { EXPECT_TRUE(has(*layers, coverageIs(kFewCoverage))); }
    if (c == "SCT") { EXPECT_TRUE(has(*layers, coverageIs(kScatteredCoverage))); }
    if (c == "BKN") { EXPECT_TRUE(has(*layers, coverageIs(kBrokenCoverage))); }
    if (c == "OVC") { EXPECT_TRUE(has(*layers, coverageIs(1.0))); }
    if (c == "CB") {
      EXPECT_TRUE(has(*layers, [](const CloudLayer& l) { return l.type == CloudType::Cumulonimbus; }));
    }
    if (c == "TCU") {
      EXPECT_TRUE(has(*layers, [](const CloudLayer& l) {
        return l.type == CloudType::Cumulus && l.thickness_m == kToweringCumulusThickness_m;
      }));
    }
    // The clear codes say there is no cloud; fog or mist may still be there
    // ("0800 BCFG NSC").
    auto noCloud = [](const std::vector<CloudLayer>& ls) {
      return std::all_of(ls.begin(), ls.end(), [](const CloudLayer& l) { return l.type == CloudType::Fog; });
    };
    if (c == "CAVOK" || c == "SKC" || c == "CLR") { EXPECT_TRUE(noCloud(*layers)); }
    if (c == "NSC") {
      if (row.icao == "LLBG") {  // NSC only in the BECMG trend; the body has VV012
        ASSERT_EQ(layers->size(), 1u);
        EXPECT_EQ((*layers)[0].base_m, station.elevation_m);
      } else {
        EXPECT_TRUE(noCloud(*layers));
      }
    }
    if (c == "NCD") { EXPECT_TRUE(noCloud(*layers)); }
    if (c == "VV") {
      ASSERT_FALSE(layers->empty());
      const CloudLayer& fog = (*layers)[0];
      EXPECT_EQ(fog.type, CloudType::Fog);
      EXPECT_EQ(fog.base_m, station.elevation_m);
      EXPECT_EQ(fog.coverage, 1.0);
      EXPECT_NEAR(fog.thickness_m, std::max(*report->verticalVisibility_ft * kFt, kMinFogThickness_m), 1e-9);
    }
    // A fog layer is first, at most one, and with the precipitation draws the
    // reported visibility (the densest fog the model has for a shorter one).
    for (std::size_t i = 0; i < layers->size(); ++i) {
      const CloudLayer& l = (*layers)[i];
      if (l.type != CloudType::Fog) continue;
      EXPECT_EQ(i, 0u);
      if (report->visibility_m && !report->visibilityAbove && *report->visibility_m < kClearVisibility_m &&
          l.density < 1) {
        EXPECT_NEAR(drawnVisibility_m(*layers), *report->visibility_m, 1e-6 * *report->visibility_m);
      }
    }
    // At most one precipitation layer, from the station up.
    const auto wet = std::count_if(layers->begin(), layers->end(), [](const CloudLayer& l) { return weather::isPrecipitation(l.type); });
    EXPECT_LE(wet, 1);
    for (const CloudLayer& l : *layers) {
      if (weather::isPrecipitation(l.type)) {
        EXPECT_EQ(l.base_m, station.elevation_m);
      }
    }
    if (c == "VRB") {
      EXPECT_TRUE(report->wind && report->wind->variable);
      for (const CloudLayer& l : *layers) EXPECT_EQ(l.wind.fromDirection_deg, 0.0);
    }
    if (row.icao == "UIBB") {  // "///074///": a base seen, no amount: FEW
      ASSERT_EQ(layers->size(), 1u);
      EXPECT_EQ((*layers)[0].coverage, kFewCoverage);
      EXPECT_NEAR((*layers)[0].base_m, station.elevation_m + 7400 * kFt, 1e-9);
    }
    if (row.icao == "DRRT") {  // "3000 SA FEW040 FEW050 CB": sand haze, and the second cloud is a cumulonimbus
      ASSERT_EQ(layers->size(), 3u);
      EXPECT_EQ((*layers)[0].type, CloudType::Fog);
      EXPECT_EQ((*layers)[2].type, CloudType::Cumulonimbus);
    }
    if (c == "gust") { EXPECT_TRUE(report->wind && report->wind->gust_kt); }
    if (c == "var_sector") { EXPECT_TRUE(report->wind && report->wind->variableFrom_deg); }
    if (c == "MPS") { EXPECT_EQ(report->wind->reportedUnit, WindUnit::MetresPerSecond); }
    if (c == "calm") {
      EXPECT_EQ(report->wind->speed_kt, 0.0);
      for (const CloudLayer& l : *layers) EXPECT_EQ(l.wind.speed_mps, 0.0);
    }
    if (c == "neg_temp") { EXPECT_LT(*report->temperature_degC, 0); }
    if (c == "COR") { EXPECT_TRUE(report->corrected); }
    if (c == "AUTO") { EXPECT_TRUE(report->automatic); }
    if (c == "SPECI") { EXPECT_TRUE(report->speci); }
    if (report->qnh_hPa) {
      EXPECT_GT(*report->qnh_hPa, 950.0);
      EXPECT_LT(*report->qnh_hPa, 1060.0);
    }
  }
  EXPECT_EQ(mapFailures, kExpectedMapFailures);
  EXPECT_EQ(notObserved, kExpectedNotObserved);
  const std::size_t rows = loadRows().size();
  // The share of reports taken (sky read, or not observed and so leaving the
  // weather as it is) and the share whose sky is read.
  std::printf("[ METAR    ] %zu reports: %zu taken (%.1f %%), sky read on %d (%.1f %%), not observed %zu, refused %zu\n",
              rows, rows - mapFailures.size(), 100.0 * double(rows - mapFailures.size()) / double(rows), read,
              100.0 * read / double(rows), notObserved.size(), mapFailures.size());
  EXPECT_EQ(read, 149);
}

// ---- decoder, good paths ---------------------------------------------------

TEST(MetarParse, FullReport) {
  auto r = parseMetar(
      "METAR KXYZ 121250Z AUTO 27015G25KT 240V300 1 1/2SM R24/P2000N +TSRAGR VCSH BR "
      "FEW008 SCT020TCU BKN035CB OVC///  M02/M05 A2992 RMK AO2=");
  ASSERT_TRUE(r) << r.error().detail;
  EXPECT_EQ(r->icao, "KXYZ");
  EXPECT_FALSE(r->speci);
  EXPECT_TRUE(r->automatic);
  EXPECT_EQ(r->time->day, 12);
  EXPECT_EQ(r->time->hour, 12);
  EXPECT_EQ(r->time->minute, 50);
  EXPECT_EQ(*r->wind->direction_deg, 270);
  EXPECT_EQ(r->wind->speed_kt, 15);
  EXPECT_EQ(*r->wind->gust_kt, 25);
  EXPECT_EQ(*r->wind->variableFrom_deg, 240);
  EXPECT_EQ(*r->wind->variableTo_deg, 300);
  ASSERT_EQ(r->clouds.size(), 4u);
  EXPECT_EQ(r->clouds[0].amount, CloudAmount::Few);
  EXPECT_EQ(*r->clouds[0].height_ft, 800);
  EXPECT_EQ(r->clouds[1].convective, ConvectiveCloud::ToweringCumulus);
  EXPECT_EQ(r->clouds[2].convective, ConvectiveCloud::Cumulonimbus);
  EXPECT_EQ(r->clouds[3].amount, CloudAmount::Overcast);
  EXPECT_FALSE(r->clouds[3].height_ft);
  EXPECT_EQ(*r->temperature_degC, -2);
  EXPECT_EQ(*r->dewpoint_degC, -5);
  EXPECT_NEAR(*r->qnh_hPa, 1013.2, 0.05);
}

TEST(MetarParse, UnitsCalmVrbAndVisibilityForms) {
  auto mps = parseMetar("UUEE 010000Z 18005MPS 9999NDV OVC010 10/08 Q1013");
  ASSERT_TRUE(mps) << mps.error().detail;
  EXPECT_NEAR(mps->wind->speed_kt, 5 * 3600.0 / 1852.0, 1e-9);
  EXPECT_EQ(*mps->qnh_hPa, 1013);
  auto kmh = parseMetar("ABCD 010000Z 18036KMH P6SM SKC");
  ASSERT_TRUE(kmh) << kmh.error().detail;
  EXPECT_NEAR(kmh->wind->speed_kt, 36 / 1.852, 1e-9);
  EXPECT_EQ(kmh->noCloud, NoCloud::SKC);
  auto calm = parseMetar("ABCD 010000Z 00000KT M1/4SM FG VV000 01/01 Q1000");
  ASSERT_TRUE(calm) << calm.error().detail;
  EXPECT_EQ(calm->wind->speed_kt, 0);
  EXPECT_EQ(*calm->verticalVisibility_ft, 0);
  auto vrb = parseMetar("ABCD 010000Z VRB03KT CAVOK 20/10 Q1020 NOSIG");
  ASSERT_TRUE(vrb) << vrb.error().detail;
  EXPECT_TRUE(vrb->wind->variable);
  EXPECT_FALSE(vrb->wind->direction_deg);
  EXPECT_TRUE(vrb->cavok);
  auto missingWind = parseMetar("ABCD 010000Z /////KT 4000N //// // NCD");
  ASSERT_TRUE(missingWind) << missingWind.error().detail;
  EXPECT_FALSE(missingWind->wind);
}

// Prevailing visibility in every form real reports use, and the present
// weather kept as written.
TEST(MetarParse, VisibilityAndPresentWeather) {
  struct Case {
    const char* body;
    std::optional<double> visibility_m;
    bool above, below;
  };
  const double mile = 1609.344;
  const Case cases[] = {
      {"9999 SCT030", 10000, true, false},
      {"CAVOK", 10000, true, false},
      {"0800 FG", 800, false, false},
      {"0000 FG", 0, false, false},
      {"4000 1200SW BR", 4000, false, false},  // the second group is a sector's minimum
      {"9999NDV", 10000, true, false},
      {"//// //", std::nullopt, false, false},
      {"10SM CLR", 10 * mile, false, false},
      {"P6SM SKC", 6 * mile, true, false},
      {"M1/4SM FG", 0.25 * mile, false, true},
      {"3/4SM BR", 0.75 * mile, false, false},
      {"1 1/2SM -RA", 1.5 * mile, false, false},
      {"1/4 SM FG", 0.25 * mile, false, false},
      {"2 1/4 SM BR", 2.25 * mile, false, false},
      {"1/0SM", std::nullopt, false, false},  // a zero denominator reads as no visibility
      {"SCT030", std::nullopt, false, false},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(c.body);
    auto r = parseMetar(std::string("ABCD 010000Z 00000KT ") + c.body + " 10/08 Q1013");
    ASSERT_TRUE(r) << r.error().detail;
    ASSERT_EQ(r->visibility_m.has_value(), c.visibility_m.has_value());
    if (c.visibility_m) { EXPECT_NEAR(*r->visibility_m, *c.visibility_m, 1e-9); }
    EXPECT_EQ(r->visibilityAbove, c.above);
    EXPECT_EQ(r->visibilityBelow, c.below);
  }
  auto wx = parseMetar("ABCD 010000Z 00000KT 0600 -SHRA BCFG VCTS // RERA NSC 10/08 Q1013");
  ASSERT_TRUE(wx) << wx.error().detail;
  EXPECT_EQ(wx->weather, (std::vector<std::string>{"-SHRA", "BCFG", "VCTS"}));
}

TEST(MetarParse, StopsAtTrendRemarksAndAfterPressure) {
  // Anything after the stop is not decoded, even if it would not parse.
  for (const char* tail : {"TEMPO BKN0x5", "BECMG XX", "NOSIG ???", "RMK BKN0x5", "INTER 1000/1200",
                           "PROB30 TSRA", "FM1300 ZZZ"}) {
    auto r = parseMetar(std::string("ABCD 010000Z 27010KT 9999 FEW020 ") + tail);
    EXPECT_TRUE(r) << tail << ": " << r.error().detail;
    EXPECT_EQ(r->clouds.size(), 1u);
  }
  auto r = parseMetar("ABCD 010000Z 27010KT 9999 FEW020 12/10 Q1013 WS RWY11 BLU R24/290052 BKN0x5");
  EXPECT_TRUE(r) << r.error().detail;
}

TEST(MetarParse, NilAndCorBeforeStation) {
  auto nil = parseMetar("METAR CYSY NIL=");
  ASSERT_TRUE(nil) << nil.error().detail;
  EXPECT_TRUE(nil->nil);
  EXPECT_FALSE(nil->time);
  auto nilTimed = parseMetar("SPECI CYSY 121200Z NIL");
  ASSERT_TRUE(nilTimed);
  EXPECT_TRUE(nilTimed->nil);
  EXPECT_TRUE(nilTimed->speci);
  auto cor = parseMetar("METAR COR GQNO 111900Z VRB03KT 3000 TSRA FEW020 23/23 Q1010");
  ASSERT_TRUE(cor);
  EXPECT_TRUE(cor->corrected);
}

// ---- decoder, refusals and skipped groups -----------------------------------

void expectError(const std::string& report, const std::string& detail) {
  auto r = parseMetar(report);
  ASSERT_FALSE(r) << report;
  EXPECT_EQ(r.error().code, ErrorCode::Malformed) << report;
  EXPECT_EQ(r.error().detail, detail) << report;
}

// Only a report without a readable station is refused.
TEST(MetarParseErrors, OnlyAMissingStationRefusesAReport) {
  expectError("", "empty report");
  expectError(" = ", "empty report");
  expectError("METAR", "report ends early: no station");
  expectError("METAR K1 121200Z", "group 2 'K1': station is not a four-character ICAO code");
  expectError("METAR 1ABC 121200Z", "group 2 '1ABC': station is not a four-character ICAO code");
  expectError("121200Z 27010KT", "group 1 '121200Z': station is not a four-character ICAO code");
}

// Every group the decoder cannot read is skipped with its position, text and
// reason, and the rest of the report still decodes.
TEST(MetarParseErrors, EachBadGroupIsSkippedNamingPositionAndReason) {
  struct Case {
    std::string report;
    std::size_t position;
    std::string text, reason;
  };
  const std::string h = "METAR KXYZ 121200Z 27010KT ";  // groups 1-4
  const std::vector<Case> cases = {
      {h + "BKN0x5 SCT040", 5, "BKN0x5", "height is not three digits"},
      {h + "FEW SCT040", 5, "FEW", "height is not three digits"},
      {h + "FEW020XX SCT040", 5, "FEW020XX", "cloud type is not CB, TCU or ///"},
      {h + "VV0x1 SCT040", 5, "VV0x1", "vertical visibility is not three digits"},
      {h + "CB SCT040", 5, "CB", "cloud type without amount and height"},
      {h + "27010KT SCT040", 5, "27010KT", "second wind group"},
      {h + "12/10 11/09 SCT040", 6, "11/09", "second temperature group"},
      {h + "XYZZY SCT040", 5, "XYZZY", "unrecognised group"},
      {h + "-1004SE SCT040", 5, "-1004SE", "unrecognised group"},
      {h + "///// SCT040", 5, "/////", "unrecognised group"},
      {h + "-VCTSRA SCT040", 5, "-VCTSRA", "unrecognised group"},
      {h + "M SCT040", 5, "M", "unrecognised group"},
      {h + "SCT040 SCT040", 6, "SCT040", "repeats an earlier cloud group"},
      {"KXYZ 1212Z 27010KT SCT040", 2, "1212Z", "time is not DDHHMMZ"},
      {"KXYZ 321200Z 27010KT SCT040", 2, "321200Z", "day outside [1, 31]"},
      {"KXYZ 001200Z 27010KT SCT040", 2, "001200Z", "day outside [1, 31]"},
      {"KXYZ 122400Z 27010KT SCT040", 2, "122400Z", "hour outside [0, 23]"},
      {"KXYZ 121260Z 27010KT SCT040", 2, "121260Z", "minute outside [0, 59]"},
      {"KXYZ 121200Z 37010KT SCT040", 3, "37010KT", "wind direction above 360"},
      {"KXYZ 121200Z ABC10KT SCT040", 3, "ABC10KT", "wind direction is not three digits or VRB"},
      {"KXYZ 121200Z 2701KT SCT040", 3, "2701KT", "wind is not dddff"},
      {"KXYZ 121200Z 2701000KT SCT040", 3, "2701000KT", "wind speed is not two or three digits"},
      {"KXYZ 121200Z 27010G5KT SCT040", 3, "27010G5KT", "gust is not two or three digits"},
      {"KXYZ 121200Z 27010GKT SCT040", 3, "27010GKT", "gust is not two or three digits"},
      {"KXYZ 121200Z 27010KT 370V010 SCT040", 4, "370V010", "variable sector direction above 360"},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(c.report);
    auto r = parseMetar(c.report);
    ASSERT_TRUE(r) << r.error().detail;
    ASSERT_EQ(r->skipped.size(), 1u);
    EXPECT_EQ(r->skippedCount, 1u);
    EXPECT_EQ(r->skipped[0].position, c.position);
    EXPECT_EQ(r->skipped[0].text, c.text);
    EXPECT_EQ(r->skipped[0].reason, c.reason);
    ASSERT_EQ(r->clouds.size(), 1u) << "the sky after the bad group still decodes";
    EXPECT_EQ(*r->clouds[0].height_ft, 4000);
  }
  // NIL: a missing report; anything after it is skipped, nothing decoded.
  auto nil = parseMetar("KXYZ 121200Z NIL OVC010");
  ASSERT_TRUE(nil);
  EXPECT_TRUE(nil->nil);
  EXPECT_TRUE(nil->clouds.empty());
  ASSERT_EQ(nil->skipped.size(), 1u);
  EXPECT_EQ(nil->skipped[0].reason, "group after NIL");
}

// Whatever the input, the notes are bounded: kMaxNotedGroups of them, each
// cut to kMaxNotedGroupBytes; the count goes on.
TEST(MetarParseErrors, NotesAreBounded) {
  std::string report = "KXYZ 121200Z 27010KT";
  for (int i = 0; i < 1000; ++i) report += " " + std::string(100, 'X');
  auto r = parseMetar(report);
  ASSERT_TRUE(r);
  EXPECT_EQ(r->skipped.size(), kMaxNotedGroups);
  EXPECT_EQ(r->skippedCount, 1000u);
  for (const MetarGroupNote& n : r->skipped) EXPECT_EQ(n.text.size(), kMaxNotedGroupBytes);
}

// ---- mapping --------------------------------------------------------------

// The layers of a report's sky; an error when it does not map or its sky is
// not observed.
Result<std::vector<CloudLayer>> mapped(const std::string& body, double elevation_m = 500) {
  auto r = parseMetar("ABCD 010000Z " + body);
  if (!r) return tl::unexpected(r.error());
  auto sky = skyFromMetar(*r, Station{"ABCD", 10, 20, elevation_m});
  if (!sky) return tl::unexpected(sky.error());
  if (!sky->observed) return fail(ErrorCode::InvalidArgument, "not observed");
  return sky->layers;
}

TEST(MetarLayers, TypeCoverageBaseAndThicknessByRule) {
  auto layers = mapped("36020KT 9999 FEW010 BKN010 OVC005 OVC015 SCT100 OVC100 BKN250 M50/M60 Q1000");
  ASSERT_TRUE(layers) << layers.error().detail;
  ASSERT_EQ(layers->size(), 7u);
  const CloudType expected[] = {CloudType::Cumulus,      CloudType::Stratocumulus, CloudType::Stratus,
                                CloudType::Stratocumulus, CloudType::Altocumulus,   CloudType::Altostratus,
                                CloudType::Cirrus};
  const double thickness[] = {kCumulusThickness_m,  kStratocumulusThickness_m, kStratusThickness_m,
                              kStratocumulusThickness_m, kAltocumulusThickness_m,
                              kAltostratusThickness_m, kCirrusThickness_m};
  const int heights_ft[] = {1000, 1000, 500, 1500, 10000, 10000, 25000};
  const double coverage[] = {1.5 / 8, 6.0 / 8, 1, 1, 3.5 / 8, 1, 6.0 / 8};
  for (std::size_t i = 0; i < 7; ++i) {
    const CloudLayer& l = (*layers)[i];
    EXPECT_EQ(l.id, i + 1);
    EXPECT_EQ(l.type, expected[i]) << i;
    EXPECT_EQ(l.thickness_m, thickness[i]) << i;
    EXPECT_NEAR(l.base_m, 500 + heights_ft[i] * kFt, 1e-9) << i;
    EXPECT_EQ(l.coverage, coverage[i]) << i;
    EXPECT_NEAR(l.wind.speed_mps, 20 * 1852.0 / 3600.0, 1e-9);
    EXPECT_EQ(l.wind.fromDirection_deg, 0.0);  // 360 -> 0
    EXPECT_NEAR(l.transitionBand_m, kTransitionFraction * l.thickness_m, 1e-9);
  }
}

TEST(MetarLayers, ConvectiveFogAndUnknownGroups) {
  auto layers = mapped("VRB05KT 0200 FG VV003 FEW030CB SCT040TCU //////CB BKN///  ///050 FEW060///");
  ASSERT_TRUE(layers) << layers.error().detail;
  ASSERT_EQ(layers->size(), 5u);  // VV, CB, TCU, ///050 (as FEW), FEW060///; the two without height dropped
  EXPECT_EQ((*layers)[0].type, CloudType::Fog);
  EXPECT_NEAR(weather::cloudVisibility_m((*layers)[0].density), 200, 1e-9);
  EXPECT_EQ((*layers)[0].base_m, 500);
  EXPECT_NEAR((*layers)[0].thickness_m, 300 * kFt, 1e-9);
  EXPECT_EQ((*layers)[0].coverage, 1);
  EXPECT_EQ((*layers)[1].type, CloudType::Cumulonimbus);
  EXPECT_NEAR((*layers)[1].base_m + (*layers)[1].thickness_m, kCumulonimbusTop_m, 1e-9);
  EXPECT_EQ((*layers)[2].type, CloudType::Cumulus);
  EXPECT_EQ((*layers)[2].thickness_m, kToweringCumulusThickness_m);
  EXPECT_EQ((*layers)[3].coverage, kFewCoverage);  // a base without an amount: FEW
  EXPECT_NEAR((*layers)[3].base_m, 500 + 5000 * kFt, 1e-9);
  EXPECT_EQ((*layers)[4].type, CloudType::Cumulus);  // unknown type: from the height
  for (const CloudLayer& l : *layers) {
    EXPECT_EQ(l.wind.fromDirection_deg, 0.0);  // VRB
    EXPECT_NEAR(l.wind.speed_mps, 5 * 1852.0 / 3600.0, 1e-9);
  }
  // VV000: less than 100 ft, at least kMinFogThickness_m deep.
  auto vv0 = mapped("00000KT 0050 FG VV000");
  ASSERT_TRUE(vv0) << vv0.error().detail;
  EXPECT_EQ((*vv0)[0].thickness_m, kMinFogThickness_m);
  // A CB based above the nominal top keeps a minimum depth.
  auto highCb = mapped("00000KT FEW400CB", 0);
  ASSERT_TRUE(highCb);
  EXPECT_EQ((*highCb)[0].thickness_m, kCumulonimbusMinThickness_m);
}

// Obscuration -> a fog layer first, drawing the reported visibility, as deep
// as its kind, over the part of the area it covers.
TEST(MetarLayers, ObscurationIsAFogLayerOfTheReportedVisibility) {
  struct Case {
    const char* body;
    double visibility_m, thickness_m, coverage;
  };
  const Case cases[] = {
      {"0300 FG OVC002", 300, kFogThickness_m, 1.0},
      {"0600 BCFG NSC", 600, kFogThickness_m, kFogPatchesCoverage},
      {"0900 PRFG SCT010", 900, kFogThickness_m, kPartialFogCoverage},
      {"0200 MIFG NSC", 200, kShallowFogThickness_m, 1.0},
      {"2500 BR BKN008", 2500, kMistThickness_m, 1.0},
      {"4000 HZ NSC", 4000, kHazeThickness_m, 1.0},
      {"3000 FU NSC", 3000, kHazeThickness_m, 1.0},
      {"FG NSC", kFogDefaultVisibility_m, kFogThickness_m, 1.0},  // no visibility group: FG's default
      {"2000 +RA BKN015", 2000, 1500 * kFt, 1.0},                 // rain: from the lowest base down
      {"0300 FG VV002", 300, 200 * kFt, 1.0},
      {"0050 FG VV001", weather::kMinFogVisibility_m, 100 * kFt, 1.0},  // denser than the model draws
      {"0000 FG VV///", weather::kMinFogVisibility_m, 100 * kFt, 1.0},  // under 50 m: the densest
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(c.body);
    auto layers = mapped(std::string("00000KT ") + c.body);
    ASSERT_TRUE(layers) << layers.error().detail;
    ASSERT_FALSE(layers->empty());
    const CloudLayer& fog = (*layers)[0];
    EXPECT_EQ(fog.type, CloudType::Fog);
    EXPECT_EQ(fog.id, 1u);
    EXPECT_EQ(fog.base_m, 500);
    EXPECT_NEAR(fog.thickness_m, c.thickness_m, 1e-9);
    EXPECT_EQ(fog.coverage, c.coverage);
    // With the precipitation's (drawn beside it) the reported visibility.
    EXPECT_NEAR(drawnVisibility_m(*layers), c.visibility_m, 1e-9 * c.visibility_m);
    for (std::size_t i = 1; i < layers->size(); ++i) EXPECT_NE((*layers)[i].type, CloudType::Fog);
  }
  // Nothing to draw: 10 km or more, rain that leaves 5 km, fog in the vicinity.
  for (const char* body : {"9999 BR NSC", "P6SM HZ SKC", "6000 -RA BKN020", "9999 VCFG NSC", "9999 BCFG NSC", "CAVOK"}) {
    auto layers = mapped(std::string("00000KT ") + body);
    ASSERT_TRUE(layers) << body;
    for (const CloudLayer& l : *layers) EXPECT_NE(l.type, CloudType::Fog) << body;
  }
}

// Precipitation -> a layer of its type from the station up into the cloud
// that drops it, at the intensity's rate unless the visibility says less.
TEST(MetarLayers, PrecipitationIsALayerFromTheStationIntoItsCloud) {
  struct Case {
    const char* body;
    CloudType type;
    double rate_mmph;   // expected rate (coverage 1 where the cap binds)
    double carrierBase_ft;  // the cloud it falls from (its base); < 0: none, kPrecipitationObscurationTop_m deep
    double coverage;
  };
  // The rule's cap: the rate whose extinction over the covered part gives
  // the reported visibility (a 9999: 10 km), less an obscured sky's fog's
  // least (a 10 km visibility's extinction).
  auto capped = [](CloudType t, double rate, double visibility_m, double coverage, bool obscured = false) {
    const double allowed = 3.912 / visibility_m - (obscured ? 3.912 / 10000 : 0.0);
    return std::min(rate, weather::precipitationRate_mmph(t, allowed / coverage));
  };
  const double bkn = kBrokenCoverage;
  const Case cases[] = {
      // Steady rain from the lowest ceiling, 1000 m into it; 8 km caps the
      // moderate rate at 2.9 mm/h.
      {"8000 RA FEW008 OVC015", CloudType::Rain, capped(CloudType::Rain, weather::kModerateRain_mmph, 8000, 1), 1500, 1.0},
      // Light rain under a broken deck: its coverage, the light rate (21 km).
      {"9999 -RA BKN030", CloudType::Rain, weather::kLightRain_mmph, 3000, bkn},
      // Showers fall from the cumulonimbus, not the lower deck.
      {"4000 +TSRA SCT010 BKN025CB", CloudType::Rain, capped(CloudType::Rain, weather::kHeavyRain_mmph, 4000, bkn), 2500, bkn},
      // Snow at its own rates.
      {"1200 SN OVC010", CloudType::Snow, capped(CloudType::Snow, weather::kModerateSnow_mmph, 1200, 1), 1000, 1.0},
      {"0600 +SN VV005", CloudType::Snow, capped(CloudType::Snow, weather::kHeavySnow_mmph, 600, 1, true), -1, 1.0},
      // Rain and snow together, and ice pellets: sleet; hail.
      {"3000 RASN BKN008", CloudType::Sleet, capped(CloudType::Sleet, weather::kModerateRain_mmph, 3000, bkn), 800, bkn},
      {"5000 -PL OVC020", CloudType::Sleet, capped(CloudType::Sleet, weather::kLightRain_mmph, 5000, 1), 2000, 1.0},
      {"3000 TSGR BKN030CB", CloudType::Hail, weather::kModerateRain_mmph, 3000, bkn},
      // Drizzle: a tenth of rain's rate.
      {"5000 DZ OVC004", CloudType::Rain, weather::kModerateRain_mmph * weather::kDrizzleFactor, 400, 1.0},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(c.body);
    auto layers = mapped(std::string("00000KT ") + c.body);
    ASSERT_TRUE(layers) << layers.error().detail;
    const auto wet = std::find_if(layers->begin(), layers->end(), [](const CloudLayer& l) { return weather::isPrecipitation(l.type); });
    ASSERT_NE(wet, layers->end());
    EXPECT_EQ(wet->type, c.type);
    EXPECT_EQ(wet->base_m, 500);
    double depth_m = kPrecipitationObscurationTop_m;
    if (c.carrierBase_ft >= 0) {
      const auto carrier = std::find_if(layers->begin(), layers->end(), [&](const CloudLayer& l) {
        return !weather::isPrecipitation(l.type) && std::abs(l.base_m - (500 + c.carrierBase_ft * kFt)) < 1e-6;
      });
      ASSERT_NE(carrier, layers->end());
      depth_m = carrier->base_m - 500 + std::min(kPrecipitationInCloud_m, carrier->thickness_m);
      EXPECT_EQ(wet->coverage, carrier->coverage);
    }
    EXPECT_NEAR(wet->thickness_m, depth_m, 1e-6);
    EXPECT_EQ(wet->coverage, c.coverage);
    EXPECT_NEAR(weather::precipitationRateForDensity(c.type, wet->density), c.rate_mmph, 1e-6 * c.rate_mmph);
    // What the layers draw at the station is never clearer than reported.
    const auto report = parseMetar(std::string("ABCD 010000Z 00000KT ") + c.body);
    ASSERT_TRUE(report);
    // (Under 5 km, where the rest is drawn as mist: a 5000 DZ draws the
    // drizzle alone.)
    if (report->visibility_m && *report->visibility_m < kHazeDefaultVisibility_m) {
      EXPECT_NEAR(drawnVisibility_m(*layers), *report->visibility_m, 1e-6 * *report->visibility_m);
    }
  }
  // The deck steady rain falls from is nimbostratus, deeper and darker
  // than the same group without rain; drizzle falls from stratus as it is.
  {
    auto wet = mapped("00000KT 8000 RA OVC015");
    auto dry = mapped("00000KT 9999 OVC015");
    auto drizzle = mapped("00000KT 5000 DZ OVC004");
    ASSERT_TRUE(wet && dry && drizzle);
    EXPECT_EQ(dry->front().type, CloudType::Stratocumulus);
    EXPECT_EQ(wet->front().type, CloudType::Nimbostratus);
    EXPECT_EQ(wet->front().thickness_m, kNimbostratusThickness_m);
    EXPECT_EQ(wet->front().base_m, dry->front().base_m);
    EXPECT_EQ(drizzle->front().type, CloudType::Stratus);
  }
  // Not at the station, or not falling: no precipitation layer.
  for (const char* body : {"9999 VCSH FEW030", "9999 BLSN BKN010", "9999 DRSN SCT020", "9999 TS FEW030CB", "9999 BR NSC"}) {
    auto layers = mapped(std::string("00000KT ") + body);
    ASSERT_TRUE(layers) << body;
    for (const CloudLayer& l : *layers) EXPECT_FALSE(weather::isPrecipitation(l.type)) << body;
  }
  // Rain under a sky the report does not give: not observed (the station
  // replaces every layer or none).
  EXPECT_FALSE(mapped("00000KT 5000 RA //////"));
}

TEST(MetarLayers, ClearCodesGiveNoLayers) {
  for (const char* body : {"00000KT CAVOK", "00000KT 9999 NSC", "00000KT 9999 NCD", "00000KT 10SM SKC",
                           "00000KT 10SM CLR"}) {
    auto layers = mapped(body);
    ASSERT_TRUE(layers) << body << ": " << layers.error().detail;
    EXPECT_TRUE(layers->empty()) << body;
  }
}

TEST(MetarLayers, VerticalVisibilityNotMeasuredIsFog) {
  auto fog = mapped("00000KT 0100 FG VV///");
  ASSERT_TRUE(fog) << fog.error().detail;
  ASSERT_EQ(fog->size(), 1u);
  EXPECT_EQ((*fog)[0].type, CloudType::Fog);
  EXPECT_EQ((*fog)[0].base_m, 500);
  EXPECT_NEAR((*fog)[0].thickness_m, kUnknownVerticalVisibility_ft * kFt, 1e-9);
}

TEST(MetarLayers, ASkyNotObservedIsNotAClearSky) {
  // Nothing about the sky: an empty sky is never inferred.
  for (const char* body : {"00000KT 9999 10/05 Q1010", "00000KT 9999 //////", "00000KT 9999 ///////// 10/05",
                           "00000KT 9999 FEW/// 10/05", "00000KT //// // ////// 25/18 Q1016"}) {
    auto r = parseMetar(std::string("ABCD 010000Z AUTO ") + body);
    ASSERT_TRUE(r);
    auto sky = skyFromMetar(*r, Station{"ABCD", 10, 20, 0});
    ASSERT_TRUE(sky) << body << ": " << sky.error().detail;
    EXPECT_FALSE(sky->observed) << body;
    EXPECT_TRUE(sky->layers.empty()) << body;
  }
}

TEST(MetarLayers, Errors) {
  // Out of the model's ranges: weather::validate's message.
  auto high = mapped("00000KT BKN999");
  ASSERT_FALSE(high);
  EXPECT_NE(high.error().detail.find("base_m"), std::string::npos) << high.error().detail;
  auto deepFog = mapped("00000KT VV999");
  ASSERT_FALSE(deepFog);
  EXPECT_NE(deepFog.error().detail.find("thickness_m"), std::string::npos) << deepFog.error().detail;
  auto storm = mapped("270999KT BKN020");  // 999 kt = 514 m/s
  ASSERT_FALSE(storm);
  EXPECT_NE(storm.error().detail.find("speed"), std::string::npos) << storm.error().detail;

  auto report = parseMetar("ABCD 010000Z 00000KT BKN020");
  ASSERT_TRUE(report);
  EXPECT_FALSE(skyFromMetar(*report, Station{"WXYZ", 0, 0, 0}));
  EXPECT_FALSE(skyFromMetar(*report, Station{"ABCD", std::nan(""), 0, 0}));
  EXPECT_FALSE(skyFromMetar(*report, Station{"ABCD", 0, 0, INFINITY}));
  auto nil = parseMetar("ABCD NIL");
  ASSERT_TRUE(nil);
  auto nilSky = skyFromMetar(*nil, Station{"ABCD", 0, 0, 0});
  ASSERT_FALSE(nilSky);
  EXPECT_NE(nilSky.error().detail.find("NIL"), std::string::npos);
}

// ---- real-world oddities ----------------------------------------------------

// The sky a report maps to, written back as groups: "FEW025 SCT045CB VV001",
// "clear", "not observed", or "refused: <reason>". Heights above the station
// in hundreds of feet, rounded; amounts from the coverage; a fog layer under
// no VV as "FOG" and the visibility it draws in metres ("FOG0800").
std::string skyText(const std::string& report, double elevation_m) {
  auto r = parseMetar(report);
  if (!r) return "refused: " + r.error().detail;
  auto sky = skyFromMetar(*r, Station{r->icao, 45, 7, elevation_m});
  if (!sky) return "refused: " + sky.error().detail;
  if (!sky->observed) return "not observed";
  if (sky->layers.empty()) return "clear";
  std::string out;
  char buf[32];
  for (std::size_t i = 0; i < sky->layers.size(); ++i) {
    const CloudLayer& l = sky->layers[i];
    if (l.type == CloudType::Fog && !r->verticalVisibility) {
      std::snprintf(buf, sizeof buf, "%sFOG%04ld", out.empty() ? "" : " ", std::lround(weather::cloudVisibility_m(l.density)));
      out += buf;
      continue;
    }
    if (weather::isPrecipitation(l.type)) {
      std::string name(weather::toString(l.type));
      for (char& ch : name) ch = static_cast<char>(std::toupper(static_cast<unsigned char>(ch)));
      std::snprintf(buf, sizeof buf, "%s%s%.1f", out.empty() ? "" : " ", name.c_str(),
                    weather::precipitationRateForDensity(l.type, l.density));
      out += buf;
      continue;
    }
    const bool fog = i == 0 && r->verticalVisibility;
    const int hundreds = static_cast<int>(std::lround((fog ? l.thickness_m : l.base_m - elevation_m) / kFt / 100));
    const char* amount = fog                              ? "VV"
                         : l.coverage == kFewCoverage       ? "FEW"
                         : l.coverage == kScatteredCoverage ? "SCT"
                         : l.coverage == kBrokenCoverage    ? "BKN"
                                                            : "OVC";
    const char* type = l.type == CloudType::Cumulonimbus ? "CB"
                       : l.type == CloudType::Cumulus && l.thickness_m == kToweringCumulusThickness_m ? "TCU"
                                                                                                        : "";
    std::snprintf(buf, sizeof buf, "%s%s%03d%s", out.empty() ? "" : " ", amount, hundreds, type);
    out += buf;
  }
  return out;
}

std::string notes(const std::vector<MetarGroupNote>& n) {
  std::string out;
  for (const MetarGroupNote& g : n) out += (out.empty() ? "" : " ") + g.text;
  return out;
}

// Reports written as they really arrive from many countries, with what each
// must map to and which groups are skipped or joined. Counted: the share
// whose sky is read.
TEST(MetarOddities, EachMapsToWhatItSays) {
  struct Case {
    const char* report;
    const char* sky;
    const char* skipped = "";
    const char* joined = "";
  };
  const Case cases[] = {
      // Automatic stations: "//////" is a sky not observed, NCD a sky clear.
      {"METAR EDDF 221150Z AUTO 24008KT 9999 ////// 12/06 Q1018", "not observed"},
      {"METAR EDDF 221150Z AUTO 24008KT 9999 NCD 12/06 Q1018", "clear"},
      {"METAR EHAM 221155Z AUTO 24012KT 9999 FEW/// BKN020/// 12/08 Q1015", "BKN020"},
      {"METAR ENGM 221150Z AUTO 00000KT 0150 FG VV/// M02/M02 Q1020", "VV001"},
      {"METAR YBBN 221130Z AUTO 12010KT 9999 // ///074/// 26/18 Q1015", "FEW074"},
      {"METAR PAYA 131653Z AUTO 00000KT 10SM M03/M04 A2992 RMK AO2 SLP133 I1/// T10331044 TSNO $=",
       "not observed"},
      // Statute miles, as the US and Canada write them.
      {"METAR KBOS 221154Z 04012KT M1/4SM FG VV001 05/05 A2992 RMK AO2", "VV001"},
      {"METAR KDEN 221153Z 25012KT P6SM FEW080 SCT150 BKN250 10/M05 A3012 RMK AO2 SLP187",
       "FEW080 SCT150 BKN250"},
      {"METAR KJFK 221151Z 31012KT 1/4 SM FG OVC002 08/08 A2990", "FOG0402 OVC002", "", "SM"},
      {"METAR KSEA 221153Z 18010KT 1 1/4 SM -RA BR OVC008 10/09 A2985", "FOG2308 OVC008 RAIN1.0", "", "1/4 SM"},
      {"METAR KOKC 221153Z 20025G35KT 1/2SM +FC BKN020CB 25/20 A2980", "BKN020CB"},
      {"METAR CYYZ 221200Z 27015G25KT 15SM FEW040 SCT250 M05/M12 A2990 RMK SC1CI3", "FEW040 SCT250"},
      {"METAR KORD 221151Z 27010KT 10SM BKN045 10/02 A2992 RMK AO2 SLP133 $", "BKN045"},
      {"METAR KMIA 221153Z 09010KT 10SM VCSH FEW025 SCT045 28/22 A3001 RMK AO2", "FEW025 SCT045"},
      // Supplementary groups after the pressure, and before it.
      {"METAR YSSY 221130Z 18015KT 9999 -SHRA FEW020 BKN035 15/12 Q1015 RERA", "FEW020 BKN035 RAIN1.0"},
      {"METAR YSSY 221130Z 18015KT 9999 RERA FEW020 BKN035 15/12 Q1015", "FEW020 BKN035"},
      {"METAR EGLL 221150Z 27015KT 9999 SCT030 14/08 Q1013 WS R27L NOSIG", "SCT030"},
      {"METAR LFPG 221200Z 27015KT 9999 WS R27 SCT030 14/08 Q1013", "SCT030", "", "R27"},
      {"METAR EGLL 221150Z 27010KT 0800 R24/P1500N FG BKN002 09/09 Q1018", "FOG0800 BKN002"},
      {"METAR LGAV 221150Z 36012KT 9999 FEW025 22/14 Q1013=", "FEW025"},
      // Metres per second, NDV, CAVOK, NSC.
      {"METAR UUEE 221130Z 18003MPS 9999 BKN020 08/04 Q1013=", "BKN020"},
      {"METAR LIRF 221150Z 24008KT 9999NDV SCT030CB 20/15 Q1012", "SCT030CB"},
      {"METAR ZBAA 221200Z 36004MPS CAVOK M05/M20 Q1030 NOSIG", "clear"},
      {"METAR OMDB 221200Z 33012KT 5000 DU NSC 32/10 Q1008", "FOG5000"},
      {"METAR VIDP 221200Z 00000KT 0800 FG NSC 12/11 Q1019 NOSIG", "FOG0800"},
      {"METAR SBGR 221200Z 16008KT CAVOK 25/14 Q1018", "clear"},
      {"METAR FAOR 221200Z 32008KT 9999 SCT080TCU 24/08 Q1022", "SCT080TCU"},
      {"METAR EGPD 221150Z 22015KT 9999 FEW012 SCT018 BKN025 OVC040 10/08 Q1005", "FEW012 SCT018 BKN025 OVC040"},
      {"METAR RJTT 221200Z 34005KT 9999 FEW030 SCT100 BKN/// 15/08 Q1022", "FEW030 SCT100"},
      // Groups no standard has: skipped, the sky still read.
      {"METAR LJLJ 221150Z 24008KT 9999 -VCTSRA FEW025 SCT045 12/06 Q1018", "FEW025 SCT045", "-VCTSRA"},
      {"METAR DRRT 131600Z 12018KT 3000 SA FEW040 FEW050 CB 36/18 Q1009=", "FOG3000 FEW040 FEW050CB", "", "CB"},
      {"METAR KLAX 221153Z 25008KT 10SM M FEW015 18/12 A2995", "FEW015", "M"},
      {"METAR LOWW 221150Z 30010KT 9999 BKN030 BKN030 08/03 Q1020", "BKN030", "BKN030"},
      {"METAR LOWI 221150Z 27005KT 9999 BKN0x5 SCT080 10/02 Q1020", "SCT080", "BKN0x5"},
      {"METAR LEMD 221200Z 9999 27010KT SCT040 18/05 Q1020", "SCT040"},
      {"METAR UKOO 141235Z 02002MPS 340V080 4200 -1004SE R34/////N -SHRA SCT012 SCT018CB 20/16 Q1013",
       "FOG4759 SCT012 SCT018CB RAIN1.0", "-1004SE"},
      {"metar lszh 221150z 24005kt 9999 few040 12/06 q1018", "FEW040"},
      {"2018/09/14 12:35 UKOO 141235Z 02002MPS 9999 SCT012 20/16 Q1013", "SCT012", "2018/09/14 12:35"},
      {"METAR: LJLJ 221150Z 24008KT 9999 BKN030 12/06 Q1018", "BKN030", "METAR:"},
      {"metar lszh 221150z 24005kt 9999 few040 xyz 12/06 q1018", "FEW040", "xyz"},  // quoted as written
      {"SPECI KXYZ 221210Z 27010KT 3SM -TSRA BR SCT008 BKN020CB OVC050 20/18 A2992 RMK", "FOG6282 SCT008 BKN020CB OVC050 RAIN1.0"},
      {"METAR CYSY NIL=", "refused: CYSY: NIL report (no observation)"},
      // Runs of digits longer than any real group (found by fuzz_metar: they
      // overflowed the integer read): not a visibility, skipped.
      {"METAR KNKT 061200Z 13030G40KT 1/88888888888888882SM FEW003 OVC005 24/24 A2967", "FEW003 OVC005",
       "1/88888888888888882SM"},
      {"METAR KNKT 061200Z 13030G40KT 2 1/88888888888888882SM FEW003 OVC005 24/24 A2967", "FEW003 OVC005",
       "2 1/88888888888888882SM"},
      {"METAR KNKT 061200Z 13030G40KT 1 15/16SM FEW003 OVC005 24/24 A2967", "FEW003 OVC005"},
  };
  int read = 0;
  for (const Case& c : cases) {
    SCOPED_TRACE(c.report);
    EXPECT_EQ(skyText(c.report, 300), c.sky);
    auto r = parseMetar(c.report);
    ASSERT_TRUE(r);
    EXPECT_EQ(notes(r->skipped), c.skipped);
    EXPECT_EQ(notes(r->joined), c.joined);
    const std::string sky = c.sky;
    read += sky != "not observed" && sky.rfind("refused", 0) != 0;
  }
  // Sixteenths, the finest fraction reported, still read after the limit on
  // a fraction's digits.
  auto sixteenths = parseMetar("METAR KNKT 061200Z 13030G40KT 1 15/16SM FEW003 OVC005 24/24 A2967");
  ASSERT_TRUE(sixteenths && sixteenths->visibility_m);
  EXPECT_NEAR(*sixteenths->visibility_m, (1 + 15.0 / 16) * 1609.344, 1e-6);
  const int n = static_cast<int>(std::size(cases));
  std::printf("[ METAR    ] oddities: %d reports, sky read on %d (%.1f %%)\n", n, read, 100.0 * read / n);
}

// The fuzz target's checks, here on mutations of the real reports (bytes
// changed, groups cut, duplicated and swapped) so that every ASan test run
// tries a few thousand: decoding and mapping never fail but by their Result,
// the notes stay bounded, a sky not observed has no layers.
TEST(MetarOddities, MutatedRealReportsDecodeOrRefuseCleanly) {
  std::uint32_t seed = 2024;
  auto rnd = [&](std::uint32_t n) {
    seed = seed * 1664525u + 1013904223u;
    return (seed >> 8) % n;
  };
  const std::string alphabet = "ABCKTSMVRP/0123456789 +-=$G";
  std::size_t decoded = 0, read = 0;
  for (const Row& row : loadRows())
    for (int k = 0; k < 30; ++k) {
      std::string text = row.report;
      for (int m = 0, n = 1 + static_cast<int>(rnd(4)); m < n && !text.empty(); ++m) {
        const std::size_t at = rnd(static_cast<std::uint32_t>(text.size()));
        switch (rnd(4)) {
          case 0: text[at] = alphabet[rnd(static_cast<std::uint32_t>(alphabet.size()))]; break;
          case 1: text.erase(at, 1 + rnd(6)); break;
          case 2: text.insert(at, text.substr(at, 1 + rnd(12))); break;
          default: text[at] = static_cast<char>(rnd(256)); break;
        }
      }
      auto report = parseMetar(text);
      if (!report) {
        EXPECT_EQ(report.error().code, ErrorCode::Malformed) << text;
        continue;
      }
      ++decoded;
      EXPECT_LE(report->skipped.size(), kMaxNotedGroups);
      EXPECT_LE(report->joined.size(), kMaxNotedGroups);
      EXPECT_GE(report->skippedCount, report->skipped.size());
      auto sky = skyFromMetar(*report, Station{report->icao, 45, 7, 300});
      if (!sky) continue;
      if (!sky->observed) {
        EXPECT_TRUE(sky->layers.empty()) << text;
        continue;
      }
      ++read;
      for (const CloudLayer& l : sky->layers) EXPECT_TRUE(weather::validate(l)) << text;
    }
  std::printf("[ METAR    ] mutated: %zu reports, %zu decode, %zu with a sky read\n", loadRows().size() * 30, decoded,
              read);
  // A mutation that garbles the station refuses the report (measured: 87 %
  // decode, and 73 % of all keep a readable sky).
  EXPECT_GT(decoded, loadRows().size() * 30 * 8 / 10) << "most mutations leave the station readable";
}

// ---- batch and interpolation -----------------------------------------------

TEST(MetarBatch, BadReportsDoNotStopGoodOnes) {
  const std::vector<std::string> reports = {
      "METAR AAAA 010000Z 27010KT 9999 OVC010 10/05 Q1010",
      "METAR BBBB 010000Z 27010KT 9999 BKN0x5 10/05 Q1010",
      "METAR B1 010000Z 27010KT 9999 FEW020 10/05 Q1010",
      "METAR ZZZZ 010000Z 27010KT 9999 FEW020 10/05 Q1010",
      "METAR CCCC NIL",
      "METAR CCCC 010000Z 27010KT CAVOK 10/05 Q1010",
  };
  const std::vector<Station> stations = {
      {"AAAA", 45, 7, 100}, {"BBBB", 46, 7, 200}, {"CCCC", 45, 8, 300}};
  auto results = layersFromMetarBatch(reports, stations);
  ASSERT_EQ(results.size(), 6u);
  ASSERT_TRUE(results[0]) << results[0].error().detail;
  EXPECT_EQ(results[0]->station.icao, "AAAA");
  ASSERT_EQ(results[0]->layers.size(), 1u);
  EXPECT_NEAR(results[0]->layers[0].base_m, 100 + 1000 * kFt, 1e-9);
  ASSERT_TRUE(results[1]) << "a bad group is skipped";
  EXPECT_FALSE(results[1]->skyObserved) << "its only sky group was the bad one";
  EXPECT_EQ(results[1]->report.skipped.at(0).text, "BKN0x5");
  ASSERT_FALSE(results[2]);
  EXPECT_EQ(results[2].error().detail, "report 3: group 2 'B1': station is not a four-character ICAO code");
  ASSERT_FALSE(results[3]);
  EXPECT_EQ(results[3].error().detail, "report 4: station ZZZZ is not in the station table");
  ASSERT_FALSE(results[4]);
  EXPECT_EQ(results[4].error().detail, "report 5: CCCC: NIL report (no observation)");
  ASSERT_TRUE(results[5]);
  EXPECT_TRUE(results[5]->skyObserved);
  EXPECT_TRUE(results[5]->layers.empty());
  EXPECT_TRUE(layersFromMetarBatch({}, stations).empty());
}

StationWeather withCover(const std::string& icao, double lat, double lon, double coverage) {
  StationWeather s;
  s.station = Station{icao, lat, lon, 0};
  if (coverage > 0) {
    CloudLayer l;
    l.coverage = coverage;
    s.layers.push_back(l);
    CloudLayer lower;  // the total is the largest layer cover, not a sum
    lower.coverage = coverage / 2;
    s.layers.push_back(lower);
  }
  return s;
}

TEST(MetarCoverageAt, InverseDistanceWeightingOnGeodesicDistance) {
  EXPECT_FALSE(coverageAt(0, 0, {}));
  const std::vector<StationWeather> two = {withCover("AAAA", 0, 0, 1.0), withCover("BBBB", 0, 2, 0.0)};
  EXPECT_EQ(*coverageAt(0, 0, two), 1.0);  // at a station: its value
  EXPECT_EQ(*coverageAt(0, 2, two), 0.0);
  // Equidistant on the equator: the mean.
  EXPECT_NEAR(*coverageAt(0, 1, two), 0.5, 1e-9);
  // A quarter of the way: weights 1/d^2 with d from geodesicDistance_m.
  const double d1 = geo::geodesicDistance_m(0, 0.5, 0, 0), d2 = geo::geodesicDistance_m(0, 0.5, 0, 2);
  const double w1 = 1 / (d1 * d1), w2 = 1 / (d2 * d2);
  EXPECT_NEAR(*coverageAt(0, 0.5, two), w1 / (w1 + w2), 1e-12);
  EXPECT_NEAR(w1 / (w1 + w2), 0.9, 1e-3);  // d2 = 3 d1 on the equator: 9/10

  const std::vector<StationWeather> three = {withCover("AAAA", 45, 7, 0.75), withCover("BBBB", 46, 7, 0.25),
                                             withCover("CCCC", 45, 8, 0.5)};
  for (double lat : {44.0, 45.3, 45.9, 47.0})
    for (double lon : {6.0, 7.4, 7.9, 9.0}) {
      const double c = *coverageAt(lat, lon, three);
      EXPECT_GE(c, 0.25);
      EXPECT_LE(c, 0.75);
    }
  EXPECT_EQ(*coverageAt(46, 7, three), 0.25);
  // Near a station its value dominates.
  EXPECT_NEAR(*coverageAt(45.001, 7.001, three), 0.75, 1e-3);
  // Same cover everywhere: that cover.
  const std::vector<StationWeather> same = {withCover("AAAA", 45, 7, 0.5), withCover("BBBB", -30, 120, 0.5)};
  EXPECT_NEAR(*coverageAt(10, 50, same), 0.5, 1e-12);
}

}  // namespace
}  // namespace sky::server
