// The replay's environmental conditions probe: requests at the set rate of
// flight time, carried in the host's datagram; answers joined with where and
// when they were asked; strays and unanswered requests counted; the CSV.
#include <gtest/gtest.h>

#include "sky/sim/cigi_host.hpp"
#include "sky/sim/conditions_probe.hpp"

namespace sky::sim {
namespace {

cigi::WeatherConditionsResponse answer(std::uint8_t id, float wind, float from) {
  cigi::WeatherConditionsResponse w;
  w.requestId = id;
  w.horizontalWind_mps = wind;
  w.windDirection_deg = from;
  w.verticalWind_mps = -1.5f;
  w.humidity_pct = 70;
  w.airTemperature_c = 5.25f;
  w.visibility_m = 9000;
  w.pressure_hpa = 900.5f;
  return w;
}

TEST(ConditionsProbe, AsksAtTheRateAndJoinsAnswers) {
  ConditionsProbe probe(2.0);  // every 0.5 s of flight
  std::vector<cigi::EnvironmentalConditionsRequest> asked;
  for (int frame = 0; frame <= 60; ++frame) {  // 1 s at 60 Hz
    if (auto r = probe.due(frame / 60.0, {46.0, 190.0, 1500})) asked.push_back(*r);
  }
  ASSERT_EQ(asked.size(), 3u);  // at 0, 0.5 and 1.0 s
  EXPECT_EQ(asked[0].requestId, 0);
  EXPECT_EQ(asked[2].requestId, 2);
  EXPECT_EQ(asked[0].requestType, cigi::kRequestWeather | cigi::kRequestAerosol);
  EXPECT_DOUBLE_EQ(asked[0].lon_deg, -170.0);  // CIGI's range
  EXPECT_DOUBLE_EQ(asked[0].alt_m, 1500.0);

  // One IG datagram answers request 1 (weather + two cloud layers) and carries
  // a stray answer to a request never made.
  cigi::AerosolConcentrationResponse cloud1{1, cigi::LayerId::CloudLayer1, 0.25f};
  cigi::AerosolConcentrationResponse cloud3{1, cigi::LayerId::CloudLayer3, 0.0f};
  std::vector<cigi::Packet> packets = {cloud1, answer(1, 12.5f, 270), cloud3, answer(77, 1, 1)};
  auto rows = probe.onIgPackets(packets, 1.25);
  ASSERT_EQ(rows.size(), 1u);
  EXPECT_EQ(rows[0].requestId, 1);
  EXPECT_DOUBLE_EQ(rows[0].flightTime_s, 0.5);
  EXPECT_DOUBLE_EQ(rows[0].answeredAfter_s, 0.75);
  ASSERT_TRUE(rows[0].weather);
  EXPECT_FLOAT_EQ(rows[0].weather->horizontalWind_mps, 12.5f);
  ASSERT_EQ(rows[0].aerosols.size(), 2u);
  EXPECT_EQ(probe.stray(), 1u);
  EXPECT_EQ(probe.answered(), 1u);
  // The same answer again is a stray: request 1 is done.
  EXPECT_TRUE(probe.onIgPackets({answer(1, 12.5f, 270)}, 1.3).empty());
  EXPECT_EQ(probe.stray(), 2u);

  EXPECT_EQ(ConditionsProbe::csvHeader(),
            "flight_time_s,lat_deg,lon_deg,alt_m,answered_after_s,wind_mps,wind_from_deg,vertical_wind_mps,"
            "humidity_pct,temperature_c,visibility_m,pressure_hpa,cloud1_gpm3,cloud2_gpm3,cloud3_gpm3");
  EXPECT_EQ(ConditionsProbe::csvLine(rows[0]),
            "0.500,46.0000000,-170.0000000,1500.0,0.750,12.50,270.0,-1.50,70,5.2,9000,900.50,0.2500,,0.0000");
}

TEST(ConditionsProbe, CountsRequestsNeverAnswered) {
  ConditionsProbe probe(10.0);
  for (int i = 0; i < 300; ++i) ASSERT_TRUE(probe.due(i * 0.1, {0, 0, 0}));
  // Ids wrap at 256: the first 44 were replaced before any answer came.
  EXPECT_EQ(probe.asked(), 300u);
  EXPECT_EQ(probe.unanswered(), 44u);
}

TEST(ConditionsProbe, TheHostCarriesTheRequestAndHandsBackTheReplies) {
  CigiHost host;
  ConditionsProbe probe(1.0);
  geo::GeodeticPose pose{{46.2, 12.8, 900}, 90, 0, 0};
  auto d = cigi::decodeDatagram(host.nextFrame(pose, 0.0, probe.due(0.0, pose.position)));
  ASSERT_TRUE(d) << d.error().detail;
  ASSERT_TRUE(std::holds_alternative<cigi::EnvironmentalConditionsRequest>(d->packets.back()));
  EXPECT_DOUBLE_EQ(std::get<cigi::EnvironmentalConditionsRequest>(d->packets.back()).lat_deg, 46.2);

  cigi::StartOfFrame sof;
  sof.igFrame = 7;
  cigi::DatagramWriter w(cigi::ByteOrder::Little);
  w.add(sof).add(answer(0, 3.0f, 180));
  ASSERT_TRUE(host.onIgDatagram(w.bytes()));
  ASSERT_EQ(host.lastReplies().size(), 1u);
  const auto rows = probe.onIgPackets(host.lastReplies(), 0.1);
  ASSERT_EQ(rows.size(), 1u);
  EXPECT_FLOAT_EQ(rows[0].weather->windDirection_deg, 180.0f);
}

}  // namespace
}  // namespace sky::sim
