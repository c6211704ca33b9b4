// skyshell-conformance's readers (conformance_track.hpp): a replay's
// frames.jsonl sampled along the flight, refusals that say where, and the
// server's answer reduced to the table's columns, with what a hostile server
// could put in it kept out of the table.
#include <sstream>

#include <gtest/gtest.h>

#include "sky/sim/conformance_track.hpp"

namespace sky::sim {
namespace {

std::string frameLine(int frame, double t, double lat, double lon, double clock) {
  char text[256];
  std::snprintf(text, sizeof text,
                R"({"frame":%d,"host_time_s":%.3f,"lat_deg":%.6f,"lon_deg":%.6f,"alt_m":1500,"weather_clock_s":%.3f,"preset":"medium"})",
                frame, t, lat, lon, clock);
  return text;
}

TEST(ConformanceTrack, KeepsAPointEveryIntervalOfFlightTime) {
  std::ostringstream text;
  for (int i = 0; i < 100; ++i) text << frameLine(i, 1000 + i * 0.5, 46 + i * 1e-3, 13, 5000 + i * 0.5) << '\n';
  std::istringstream in(text.str());
  const auto track = sampleTrack(in, "frames.jsonl", {10.0, 500});
  ASSERT_TRUE(track) << track.error().detail;
  // 0, 10, 20, 30, 40 s into the 49.5 s of frames.
  ASSERT_EQ(track->size(), 5u);
  for (std::size_t k = 0; k < track->size(); ++k) {
    EXPECT_EQ((*track)[k].frame, 20 * k);
    EXPECT_DOUBLE_EQ((*track)[k].flight_s, 1000 + 10.0 * k);
    EXPECT_DOUBLE_EQ((*track)[k].weatherClock_s, 5000 + 10.0 * k);
    EXPECT_NEAR((*track)[k].lat_deg, 46 + 0.02 * k, 1e-9);
  }
  std::istringstream again(text.str());
  EXPECT_EQ(sampleTrack(again, "frames.jsonl", {10.0, 2})->size(), 2u);
}

TEST(ConformanceTrack, RefusalsNameTheLineAndTheField) {
  auto refusal = [](const std::string& text) {
    std::istringstream in(text);
    const auto track = sampleTrack(in, "f.jsonl", {});
    return track ? std::string("accepted") : track.error().detail;
  };
  const std::string good = frameLine(0, 0, 46, 13, 0) + "\n";
  EXPECT_EQ(refusal(good + "{\"frame\":1}\n"), "f.jsonl:2: host_time_s: missing");
  EXPECT_EQ(refusal(good + "not json\n"), "f.jsonl:2: not a JSON object");
  EXPECT_NE(refusal(good + frameLine(1, 1, 95, 13, 0)).find("f.jsonl:2: lat_deg: 95 is outside [-90, 90]"),
            std::string::npos);
  EXPECT_NE(refusal(frameLine(0, 10, 46, 13, 0) + "\n" + frameLine(1, 5, 46, 13, 0)).find("f.jsonl:2: host_time_s 5.000 goes back"),
            std::string::npos);
  EXPECT_EQ(refusal(good + "\n  \n" + frameLine(1, 1, 46, 13, 0)), "accepted");  // blank lines are skipped
  EXPECT_NE(refusal(good + std::string(kMaxTrackLine_bytes + 10, 'x')).find("f.jsonl:2: line longer than"), std::string::npos);
  // A longitude past the antimeridian is brought into [-180, 180].
  std::istringstream in(frameLine(0, 0, 46, 190, 0));
  EXPECT_NEAR(sampleTrack(in, "f", {})->front().lon_deg, -170, 1e-9);
}

TEST(ConformanceTrack, TheTargetAsksAtTheFramesClockAndPlace) {
  const TrackPoint p{3, 12, 46.25, -13.5, 900, 123456.5};
  EXPECT_EQ(conformanceTarget(p, {50000, 5, 2}),
            "/api/conformance?lat_deg=46.2500000&lon_deg=-13.5000000&radius_m=50000.0&clock_s=123456.500&stations=5&grid_points=2");
}

TEST(ConformanceTrack, AnAnswerBecomesTheTablesRows) {
  const TrackPoint at{7, 30, 46.0, 13.0, 1500, 5000};
  const std::string body = R"({"stations":[
      {"region_id":100,"icao":"LIPQ","lat_deg":45.8275,"lon_deg":13.4722,"reported":{"ceiling_m":null,"visibility_m":800},
       "drawn":{"ceiling_m":null,"visibility_m":795.5},"oktas_off":0,"ok":true},
      {"region_id":101,"icao":"L|P*\nA","lat_deg":46.0,"lon_deg":13.0,"reported":{"ceiling_m":800},
       "drawn":{"ceiling_m":860,"visibility_m":-5},"oktas_off":2,"ok":false},
      {"region_id":102,"icao":null,"lat_deg":46.0,"lon_deg":13.1,"oktas_off":0,"ok":true}],
    "grid":[{"oktas_off":0,"ok":true},{"oktas_off":3,"ok":false},{"oktas_off":1,"ok":true}]})";
  const auto c = readPointCheck(at, body, 20);
  ASSERT_TRUE(c) << c.error().detail;
  ASSERT_EQ(c->stations.size(), 3u);
  EXPECT_EQ(c->stations[0].name, "LIPQ");
  // 45.8275 N 13.4722 E from 46 N 13 E: 19.2 km south, 36.6 km east.
  EXPECT_NEAR(c->stations[0].distance_km, 41.35, 0.05);
  EXPECT_EQ(c->stations[1].name, "L?P??A");            // nothing that could break a table or a terminal
  EXPECT_FALSE(c->stations[1].ok);
  EXPECT_EQ(c->stations[1].oktasOff, 2);
  EXPECT_EQ(*c->stations[1].ceilingDrawn_m, 860);
  EXPECT_EQ(*c->stations[0].visibilityReported_m, 800);
  EXPECT_EQ(*c->stations[0].visibilityDrawn_m, 795.5);
  EXPECT_FALSE(c->stations[1].visibilityDrawn_m) << "a negative range is not shown";
  EXPECT_EQ(c->stations[2].name, "region 102");
  EXPECT_EQ(c->gridPoints, 3u);
  EXPECT_EQ(c->gridOk, 2u);
  EXPECT_EQ(c->worstGridOktasOff, 3);
  // A server that sends more stations than were asked for is not followed.
  EXPECT_EQ(readPointCheck(at, body, 2)->stations.size(), 2u);

  const std::vector<PointCheck> all{*c};
  const auto j = trackJson(all, {});
  EXPECT_EQ(j["summary"]["station_checks"], 3);
  EXPECT_EQ(j["summary"]["station_checks_ok"], 2);
  EXPECT_EQ(j["summary"]["stations_failed"], nlohmann::json::array({"L?P??A"}));
  EXPECT_DOUBLE_EQ(j["summary"]["worst_ceiling_off_m"].get<double>(), 60);
  EXPECT_DOUBLE_EQ(j["summary"]["worst_visibility_off_m"].get<double>(), 4.5);
  EXPECT_EQ(j["points"][0]["stations"][0]["visibility_drawn_m"], 795.5);
  const std::string md = trackMarkdown(all, {});
  EXPECT_NE(md.find("| 30 | 46.000, 13.000 | LIPQ (41: none / none, 0; visibility 800 / 796); **L?P??A (0: 800 / 860, 2) FAILS**; region 102"),
            std::string::npos)
      << md;
  EXPECT_NE(md.find("checks passed: 2 of 3"), std::string::npos) << md;
}

TEST(ConformanceTrack, AnswersNotAsTheApiGivesThemAreRefused) {
  const TrackPoint at{};
  EXPECT_FALSE(readPointCheck(at, "[]", 20));
  EXPECT_FALSE(readPointCheck(at, R"({"grid":[]})", 20));
  EXPECT_FALSE(readPointCheck(at, R"({"stations":[{"lat_deg":1,"lon_deg":2,"oktas_off":9,"ok":true}]})", 20));
  EXPECT_FALSE(readPointCheck(at, R"({"stations":[{"lat_deg":1,"lon_deg":2,"oktas_off":0,"ok":"yes"}]})", 20));
  EXPECT_FALSE(readPointCheck(at, R"({"stations":[],"grid":{}})", 20));
  EXPECT_TRUE(readPointCheck(at, R"({"stations":[]})", 20));
  EXPECT_NE(trackMarkdown({*readPointCheck(at, R"({"stations":[]})", 20)}, {}).find("No station or forecast grid point"),
            std::string::npos);
}

}  // namespace
}  // namespace sky::sim
