// METAR decoding and mapping: every report of a real selection (157 METAR/SPECI
// from NOAA and the metaf test data) parses or is rejected naming a group,
// with the failures listed; the mapping per category; every error path by hand;
// the batch; inverse-distance interpolation between synthetic stations.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "sky/geo/geodetic.hpp"
#include "sky/server/metar.hpp"

namespace sky::server {
namespace {

using weather::CloudLayer;
using weather::CloudType;

constexpr double kFt = 0.3048;

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

// Reports the decoder rejects, by "category icao", with the reason.
const std::set<std::string> kExpectedParseFailures = {
    "DS/SS/SA/DU DRRT",  // "FEW050 CB": CB as its own group, not attached to a cloud group
    "MPS UKOO",          // "-1004SE": an intensity sign on a directional visibility
};
// Reports that parse but give no layers, with the reason.
const std::set<std::string> kExpectedMapFailures = {
    "NIL CYSY",        // NIL: no observation (never read as a clear sky)
    "TS PAYA",         // AUTO report with no sky condition group at all
    "SPECI KMRH",      // "AUTO VCTS RMK": no wind, visibility or sky group
    "cloud//// EHSA",  // "/////////": amount and height unknown
    "cloud//// YBDV",  // "//////"
    "cloud//// YBRK",  // "//////"
    "Q YCAS",          // "//////"
    "AUTO WAOO",       // "//////"
    "var_sector UIBB", // "///074///": height known, amount unknown: no coverage
};

bool has(const std::vector<CloudLayer>& layers, auto pred) {
  return std::any_of(layers.begin(), layers.end(), pred);
}

TEST(MetarRealReports, AllRowsLoaded) { EXPECT_EQ(loadRows().size(), 157u); }

TEST(MetarRealReports, EveryReportParsesOrIsRejectedNamingAGroup) {
  std::set<std::string> failures;
  int parsed = 0;
  for (const Row& row : loadRows()) {
    auto report = parseMetar(row.report);
    if (report) {
      ++parsed;
      EXPECT_EQ(report->icao, row.icao) << row.report;
      continue;
    }
    failures.insert(row.key());
    // "group N 'text': reason", and the text is a group of the report.
    const std::string& d = report.error().detail;
    ASSERT_EQ(d.rfind("group ", 0), 0u) << d;
    const auto open = d.find('\''), close = d.find('\'', open + 1);
    ASSERT_NE(close, std::string::npos) << d;
    const std::string group = d.substr(open + 1, close - open - 1);
    EXPECT_NE((" " + row.report + " ").find(" " + group + " "), std::string::npos) << d;
    EXPECT_GT(d.size(), close + 3) << "no reason: " << d;
  }
  EXPECT_EQ(failures, kExpectedParseFailures);
  EXPECT_EQ(parsed, 155);
}

TEST(MetarRealReports, MappingPerCategory) {
  std::set<std::string> mapFailures;
  for (const Row& row : loadRows()) {
    auto report = parseMetar(row.report);
    if (!report) continue;
    SCOPED_TRACE(row.report);
    const Station station = stationFor(row.icao);
    auto layers = layersFromMetar(*report, station);
    if (!layers) {
      mapFailures.insert(row.key());
      EXPECT_EQ(layers.error().code, ErrorCode::InvalidArgument);
      continue;
    }
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
    if (c == "CAVOK" || c == "SKC" || c == "CLR") { EXPECT_TRUE(layers->empty()); }
    if (c == "NSC") {
      if (row.icao == "LLBG") {  // NSC only in the BECMG trend; the body has VV012
        ASSERT_EQ(layers->size(), 1u);
        EXPECT_EQ((*layers)[0].base_m, station.elevation_m);
      } else {
        EXPECT_TRUE(layers->empty());
      }
    }
    if (c == "NCD") { EXPECT_TRUE(layers->empty()); }
    if (c == "VV") {
      ASSERT_FALSE(layers->empty());
      const CloudLayer& fog = (*layers)[0];
      EXPECT_EQ(fog.type, CloudType::Stratus);
      EXPECT_EQ(fog.base_m, station.elevation_m);
      EXPECT_EQ(fog.coverage, 1.0);
      EXPECT_NEAR(fog.thickness_m, std::max(*report->verticalVisibility_ft * kFt, kMinFogThickness_m), 1e-9);
    }
    if (c == "VRB") {
      EXPECT_TRUE(report->wind && report->wind->variable);
      for (const CloudLayer& l : *layers) EXPECT_EQ(l.wind.fromDirection_deg, 0.0);
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

// ---- decoder, every error path ---------------------------------------------

void expectError(const std::string& report, ErrorCode code, const std::string& detail) {
  auto r = parseMetar(report);
  ASSERT_FALSE(r) << report;
  EXPECT_EQ(r.error().code, code) << report;
  EXPECT_EQ(r.error().detail, detail) << report;
}

TEST(MetarParseErrors, EachPathNamesTheGroupAndTheReason) {
  const std::string h = "METAR KXYZ 121200Z 27010KT ";  // groups 1-4
  expectError(h + "BKN0x5", ErrorCode::Malformed, "group 5 'BKN0x5': height is not three digits");
  expectError(h + "FEW", ErrorCode::Malformed, "group 5 'FEW': height is not three digits");
  expectError(h + "FEW020XX", ErrorCode::Malformed,
              "group 5 'FEW020XX': cloud type is not CB, TCU or ///");
  expectError(h + "VV0x1", ErrorCode::Malformed,
              "group 5 'VV0x1': vertical visibility is not three digits");
  expectError(h + "FEW050 CB", ErrorCode::Malformed,
              "group 6 'CB': cloud type without amount and height");
  expectError(h + "12/10 FEW020", ErrorCode::Malformed,
              "group 6 'FEW020': expected QNH after temperature");
  expectError(h + "27010KT", ErrorCode::Malformed, "group 5 '27010KT': wind group out of place");
  expectError(h + "XYZZY", ErrorCode::Malformed, "group 5 'XYZZY': unrecognised group");
  expectError(h + "-1004SE", ErrorCode::Malformed, "group 5 '-1004SE': unrecognised group");
  expectError(h + "/////", ErrorCode::Malformed, "group 5 '/////': unrecognised group");
  expectError("", ErrorCode::Malformed, "empty report");
  expectError(" = ", ErrorCode::Malformed, "empty report");
  expectError("METAR", ErrorCode::Malformed, "report ends early: no station");
  expectError("METAR K1 121200Z", ErrorCode::Malformed,
              "group 2 'K1': station is not a four-character ICAO code");
  expectError("METAR 1ABC 121200Z", ErrorCode::Malformed,
              "group 2 '1ABC': station is not a four-character ICAO code");
  expectError("KXYZ 1212Z", ErrorCode::Malformed, "group 2 '1212Z': time is not DDHHMMZ");
  expectError("KXYZ 321200Z", ErrorCode::InvalidArgument, "group 2 '321200Z': day outside [1, 31]");
  expectError("KXYZ 001200Z", ErrorCode::InvalidArgument, "group 2 '001200Z': day outside [1, 31]");
  expectError("KXYZ 122400Z", ErrorCode::InvalidArgument, "group 2 '122400Z': hour outside [0, 23]");
  expectError("KXYZ 121260Z", ErrorCode::InvalidArgument, "group 2 '121260Z': minute outside [0, 59]");
  expectError("KXYZ 121200Z NIL OVC010", ErrorCode::Malformed, "group 4 'OVC010': group after NIL");
  expectError("KXYZ 121200Z 37010KT", ErrorCode::InvalidArgument,
              "group 3 '37010KT': wind direction above 360");
  expectError("KXYZ 121200Z ABC10KT", ErrorCode::Malformed,
              "group 3 'ABC10KT': wind direction is not three digits or VRB");
  expectError("KXYZ 121200Z 2701KT", ErrorCode::Malformed, "group 3 '2701KT': wind is not dddff");
  expectError("KXYZ 121200Z 2701000KT", ErrorCode::Malformed,
              "group 3 '2701000KT': wind speed is not two or three digits");
  expectError("KXYZ 121200Z 27010G5KT", ErrorCode::Malformed,
              "group 3 '27010G5KT': gust is not two or three digits");
  expectError("KXYZ 121200Z 27010GKT", ErrorCode::Malformed,
              "group 3 '27010GKT': gust is not two or three digits");
  expectError("KXYZ 121200Z 27010KT 370V010", ErrorCode::InvalidArgument,
              "group 4 '370V010': variable sector direction above 360");
}

// ---- mapping --------------------------------------------------------------

Result<std::vector<CloudLayer>> mapped(const std::string& body, double elevation_m = 500) {
  auto r = parseMetar("ABCD 010000Z " + body);
  if (!r) return tl::unexpected(r.error());
  return layersFromMetar(*r, Station{"ABCD", 10, 20, elevation_m});
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
  ASSERT_EQ(layers->size(), 4u);  // VV, CB, TCU, FEW060///; the three unknowns dropped
  EXPECT_EQ((*layers)[0].type, CloudType::Stratus);
  EXPECT_EQ((*layers)[0].base_m, 500);
  EXPECT_NEAR((*layers)[0].thickness_m, 300 * kFt, 1e-9);
  EXPECT_EQ((*layers)[0].coverage, 1);
  EXPECT_EQ((*layers)[1].type, CloudType::Cumulonimbus);
  EXPECT_NEAR((*layers)[1].base_m + (*layers)[1].thickness_m, kCumulonimbusTop_m, 1e-9);
  EXPECT_EQ((*layers)[2].type, CloudType::Cumulus);
  EXPECT_EQ((*layers)[2].thickness_m, kToweringCumulusThickness_m);
  EXPECT_EQ((*layers)[3].type, CloudType::Cumulus);  // unknown type: from the height
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

TEST(MetarLayers, ClearCodesGiveNoLayers) {
  for (const char* body : {"00000KT CAVOK", "00000KT 9999 NSC", "00000KT 9999 NCD", "00000KT 10SM SKC",
                           "00000KT 10SM CLR"}) {
    auto layers = mapped(body);
    ASSERT_TRUE(layers) << body << ": " << layers.error().detail;
    EXPECT_TRUE(layers->empty()) << body;
  }
}

TEST(MetarLayers, Errors) {
  // Nothing about the sky: an empty sky is never inferred.
  auto none = mapped("00000KT 9999 10/05 Q1010");
  ASSERT_FALSE(none);
  EXPECT_NE(none.error().detail.find("no usable sky condition"), std::string::npos);
  EXPECT_FALSE(mapped("00000KT 9999 //////"));
  EXPECT_FALSE(mapped("00000KT VV///"));
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
  EXPECT_FALSE(layersFromMetar(*report, Station{"WXYZ", 0, 0, 0}));
  EXPECT_FALSE(layersFromMetar(*report, Station{"ABCD", std::nan(""), 0, 0}));
  EXPECT_FALSE(layersFromMetar(*report, Station{"ABCD", 0, 0, INFINITY}));
  auto nil = parseMetar("ABCD NIL");
  ASSERT_TRUE(nil);
  auto nilLayers = layersFromMetar(*nil, Station{"ABCD", 0, 0, 0});
  ASSERT_FALSE(nilLayers);
  EXPECT_NE(nilLayers.error().detail.find("NIL"), std::string::npos);
}

// ---- batch and interpolation -----------------------------------------------

TEST(MetarBatch, BadReportsDoNotStopGoodOnes) {
  const std::vector<std::string> reports = {
      "METAR AAAA 010000Z 27010KT 9999 OVC010 10/05 Q1010",
      "METAR BBBB 010000Z 27010KT 9999 BKN0x5 10/05 Q1010",
      "METAR ZZZZ 010000Z 27010KT 9999 FEW020 10/05 Q1010",
      "METAR CCCC NIL",
      "METAR CCCC 010000Z 27010KT CAVOK 10/05 Q1010",
  };
  const std::vector<Station> stations = {
      {"AAAA", 45, 7, 100}, {"BBBB", 46, 7, 200}, {"CCCC", 45, 8, 300}};
  auto results = layersFromMetarBatch(reports, stations);
  ASSERT_EQ(results.size(), 5u);
  ASSERT_TRUE(results[0]) << results[0].error().detail;
  EXPECT_EQ(results[0]->station.icao, "AAAA");
  ASSERT_EQ(results[0]->layers.size(), 1u);
  EXPECT_NEAR(results[0]->layers[0].base_m, 100 + 1000 * kFt, 1e-9);
  ASSERT_FALSE(results[1]);
  EXPECT_EQ(results[1].error().detail, "report 2: group 6 'BKN0x5': height is not three digits");
  ASSERT_FALSE(results[2]);
  EXPECT_EQ(results[2].error().detail, "report 3: station ZZZZ is not in the station table");
  ASSERT_FALSE(results[3]);
  EXPECT_EQ(results[3].error().detail, "report 4: CCCC: NIL report (no observation)");
  ASSERT_TRUE(results[4]);
  EXPECT_TRUE(results[4]->layers.empty());
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
