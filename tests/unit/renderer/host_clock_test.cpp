// A channel's time of day (issue 19): the clock alone (a packet then host
// frames advancing it, pause, 10x, the timestamp's wrap, jumps, --utc), then
// through the real CIGI decoder in both byte orders (Celestial Sphere
// Control's valid bit, dates that are not dates, Atmosphere Control, IG
// Reset/Standby, packets counted by id) and FlightGear's cur_time.
// No GPU, no sockets: the listeners are handed datagrams.
#include <chrono>
#include <cmath>
#include <vector>

#include <gtest/gtest.h>

#include "sky/app/cigi_listener.hpp"
#include "sky/app/fdm_listener.hpp"
#include "sky/app/host_clock.hpp"
#include "sky/cigi/celestial_time.hpp"
#include "sky/fgfdm/net_fdm.hpp"

namespace sky::app {
namespace {

using Steady = std::chrono::steady_clock;
const Steady::time_point kT0 = Steady::now();
Steady::time_point at(double t_s) {
  return kT0 + std::chrono::duration_cast<Steady::duration>(std::chrono::duration<double>(t_s));
}
std::uint32_t ticks(double t_s) { return static_cast<std::uint32_t>(std::llround(t_s * 1e5) & 0xffffffffLL); }

// 2016-11-08 01:37:00 UTC (the New Zealand glider flight's date).
constexpr double kMinute_s = 1478569020;

TEST(HostClock, APacketThenHostFramesAdvanceIt) {
  HostClock c;
  EXPECT_FALSE(c.utc_s());
  EXPECT_EQ(c.source(), TimeSource::Fixed);
  c.advanceTo(100);
  c.set(kMinute_s, 60, TimeSource::Cigi);
  EXPECT_EQ(c.utc_s(), kMinute_s);
  EXPECT_EQ(c.source(), TimeSource::Cigi);
  c.advanceTo(130);
  EXPECT_DOUBLE_EQ(*c.utc_s(), kMinute_s + 30);
  // The host repeats the same minute: the seconds keep running, no jump back.
  c.set(kMinute_s, 60, TimeSource::Cigi);
  EXPECT_DOUBLE_EQ(*c.utc_s(), kMinute_s + 30);
  c.advanceTo(170);
  EXPECT_DOUBLE_EQ(*c.utc_s(), kMinute_s + 70);
  c.set(kMinute_s + 60, 60, TimeSource::Cigi);  // the next minute, which 70 s is in
  EXPECT_DOUBLE_EQ(*c.utc_s(), kMinute_s + 70);
}

// A host that starts mid-minute: the first packet gives the minute's start
// (up to 60 s behind); its first minute change sets the clock to the second.
TEST(HostClock, TheFirstMinuteChangeSetsTheSeconds) {
  HostClock c;
  c.advanceTo(0);  // true time kMinute_s + 10
  c.set(kMinute_s, 60, TimeSource::Cigi);
  c.advanceTo(50);  // true time kMinute_s + 60: the host sends the new minute
  EXPECT_DOUBLE_EQ(*c.utc_s(), kMinute_s + 50);
  c.set(kMinute_s + 60, 60, TimeSource::Cigi);
  EXPECT_DOUBLE_EQ(*c.utc_s(), kMinute_s + 60);
  // A host that sets another day altogether is followed (to the nearer end
  // of its minute).
  c.set(kMinute_s - 86400 * 30, 60, TimeSource::Cigi);
  EXPECT_DOUBLE_EQ(*c.utc_s(), kMinute_s - 86400 * 30 + 60);
  c.set(kMinute_s + 86400, 60, TimeSource::Cigi);
  EXPECT_DOUBLE_EQ(*c.utc_s(), kMinute_s + 86400);
}

TEST(HostClock, CommandLineStartRunsFromTheFirstHostTime) {
  const auto start = parseUtc("2016-11-08T01:37:25Z");
  ASSERT_TRUE(start);
  EXPECT_DOUBLE_EQ(*start, kMinute_s + 25);
  HostClock c(start);
  EXPECT_EQ(c.source(), TimeSource::CommandLine);
  c.advanceTo(5000);
  EXPECT_DOUBLE_EQ(*c.utc_s(), kMinute_s + 25);
  c.advanceTo(5010);
  EXPECT_DOUBLE_EQ(*c.utc_s(), kMinute_s + 35);
  for (const char* bad : {"2016-13-08T01:37:25Z", "2016-02-30T01:37:25Z", "2016-11-08T24:00:00Z", "2016-11-08 01:37:25",
                          "2016-11-08T01:37:25Zjunk", "3016-11-08T01:37:25Z", "", "2016-11-08T01:37:60Z"})
    EXPECT_FALSE(parseUtc(bad)) << bad;
}

// The time line from IG Control timestamps: paused, at 10x, across the
// 32-bit counter's wrap, a jump (restart) held, and arrival time without
// timestamps.
TEST(HostTimeline, FollowsTheHostsTimestampsElseArrivalTime) {
  HostTimeline line;
  HostClock c;
  c.advanceTo(line.advance(true, ticks(20), at(0)));
  c.set(kMinute_s, 60, TimeSource::Cigi);
  // Paused: 100 datagrams over 10 s of wall time with the same timestamp.
  for (int i = 1; i <= 100; ++i) c.advanceTo(line.advance(true, ticks(20), at(0.1 * i)));
  EXPECT_DOUBLE_EQ(*c.utc_s(), kMinute_s);
  // 10x: 1 s of host time per 0.1 s of wall time, for 3 s of wall time.
  for (int i = 1; i <= 30; ++i) c.advanceTo(line.advance(true, ticks(20 + i), at(10 + 0.1 * i)));
  EXPECT_NEAR(*c.utc_s(), kMinute_s + 30, 1e-4);
  // Across the wrap of the 10 us counter (2^32 ticks = 42949.67296 s).
  const double wrap_s = 4294967296.0 * 1e-5;
  HostTimeline w;
  w.advance(true, ticks(wrap_s - 0.5), at(0));
  EXPECT_NEAR(w.advance(true, ticks(wrap_s + 0.5), at(1)), 1.0, 1e-5);
  // A restart (timestamp back to 0 from hours): held, then runs again.
  const double before = w.now_s();
  w.advance(true, ticks(7200), at(2));
  EXPECT_DOUBLE_EQ(w.now_s(), before);
  EXPECT_NEAR(w.advance(true, ticks(7201), at(3)), before + 1, 1e-5);
  // Timestamps not valid: the arrival times.
  EXPECT_NEAR(w.advance(false, 0, at(5.5)), before + 3.5, 1e-9);
  EXPECT_NEAR(w.advance(false, 123, at(6)), before + 4, 1e-9);
}

// --- through the CIGI listener ------------------------------------------------

namespace asio = boost::asio;
const asio::ip::udp::endpoint kHost(asio::ip::make_address("127.0.0.1"), 40001);

// One host datagram: IG Control (timestamp = hostTime_s), the ownship (or
// entity `entityId`), then `extra`.
std::vector<std::uint8_t> datagram(cigi::ByteOrder order, double hostTime_s, const std::vector<cigi::Packet>& extra = {},
                                   cigi::IgMode mode = cigi::IgMode::Operate, std::uint16_t entityId = 0) {
  cigi::IgControl ig;
  ig.mode = mode;
  ig.timestampValid = true;
  ig.timestamp_10us = ticks(hostTime_s);
  cigi::EntityControl own;
  own.entityId = entityId;
  own.lat_deg = -44.0;
  own.lon_deg = 169.5;
  own.alt_m = 2000;
  cigi::DatagramWriter w(order);
  w.add(ig).add(own);
  for (const auto& p : extra) w.add(p);
  return w.bytes();
}

cigi::CelestialSphereControl celestial(double utc_s, bool valid = true) {
  auto c = cigi::celestialAt(static_cast<std::int64_t>(utc_s));
  c.dateTimeValid = valid;
  return c;
}

TEST(CigiTime, CelestialSphereControlSetsTheUtcInBothByteOrders) {
  for (const cigi::ByteOrder order : {cigi::ByteOrder::Big, cigi::ByteOrder::Little}) {
    asio::io_context io;
    SharedState state;
    CigiListener cigi(io, state, "127.0.0.1", 0);
    // Before any Celestial Sphere Control: the fixed sun.
    ASSERT_FALSE(cigi.handleDatagram(datagram(order, 10.0), kHost).empty());
    EXPECT_FALSE(state.pose()->utc_s);
    EXPECT_EQ(state.pose()->timeSource, TimeSource::Fixed);
    // One with the valid bit clear changes nothing.
    cigi.handleDatagram(datagram(order, 10.1, {celestial(kMinute_s, false)}), kHost);
    EXPECT_FALSE(state.pose()->utc_s);
    // With it: the minute, then the host's seconds (timestamps) on top.
    cigi.handleDatagram(datagram(order, 10.2, {celestial(kMinute_s)}), kHost);
    ASSERT_TRUE(state.pose()->utc_s);
    EXPECT_DOUBLE_EQ(*state.pose()->utc_s, kMinute_s);
    EXPECT_EQ(state.pose()->timeSource, TimeSource::Cigi);
    for (int i = 1; i <= 90; ++i) cigi.handleDatagram(datagram(order, 10.2 + i * 0.5), kHost);
    EXPECT_NEAR(*state.pose()->utc_s, kMinute_s + 45, 1e-4);
    // The same minute again: no jump back to its start.
    cigi.handleDatagram(datagram(order, 55.7, {celestial(kMinute_s)}), kHost);
    EXPECT_NEAR(*state.pose()->utc_s, kMinute_s + 45.5, 1e-4);
    // A date that is not a date (30 February) drops the datagram, counted.
    auto bad = celestial(kMinute_s);
    bad.dateMmddyyyy = 2302016;
    EXPECT_TRUE(cigi.handleDatagram(datagram(order, 56.0, {bad}), kHost).empty());
    EXPECT_EQ(cigi.drops().of(DropReason::OutOfRange), 1u);
    EXPECT_NEAR(*state.pose()->utc_s, kMinute_s + 45.5, 1e-4);
  }
}

TEST(CigiTime, CommandLineStartUntilTheHostSendsADate) {
  asio::io_context io;
  SharedState state;
  CigiListener cigi(io, state, "127.0.0.1", 0);
  cigi.setStartUtc(kMinute_s + 25);
  cigi.handleDatagram(datagram(cigi::ByteOrder::Big, 300.0), kHost);
  EXPECT_DOUBLE_EQ(*state.pose()->utc_s, kMinute_s + 25);
  EXPECT_EQ(state.pose()->timeSource, TimeSource::CommandLine);
  cigi.handleDatagram(datagram(cigi::ByteOrder::Big, 302.0), kHost);
  EXPECT_NEAR(*state.pose()->utc_s, kMinute_s + 27, 1e-4);
  cigi.handleDatagram(datagram(cigi::ByteOrder::Big, 303.0, {celestial(kMinute_s + 3600)}),
                      kHost);
  EXPECT_DOUBLE_EQ(*state.pose()->utc_s, kMinute_s + 3600);
  EXPECT_EQ(state.pose()->timeSource, TimeSource::Cigi);
}

TEST(CigiTime, AtmosphereControlIsTheChannelsAtmosphere) {
  asio::io_context io;
  SharedState state;
  CigiListener cigi(io, state, "127.0.0.1", 0);
  EXPECT_EQ(state.atmosphere().source, AtmosphereSource::Default);
  EXPECT_FALSE(state.atmosphere().hazeVisibility_m());
  cigi::AtmosphereControl a;
  a.humidity_pct = 80;
  a.airTemperature_c = 30;
  a.visibility_m = 8000;
  a.horizontalWind_mps = 7;
  a.windDirection_deg = 270;
  a.pressure_hpa = 990;
  cigi.handleDatagram(datagram(cigi::ByteOrder::Little, 1.0, {a}), kHost);
  const HostAtmosphere got = state.atmosphere();
  EXPECT_EQ(got.source, AtmosphereSource::Cigi);
  EXPECT_EQ(got.humidity_pct, 80);
  EXPECT_DOUBLE_EQ(got.seaLevelTemperature_c, 30);
  EXPECT_DOUBLE_EQ(got.seaLevelPressure_hpa, 990);
  EXPECT_DOUBLE_EQ(got.windSpeed_mps, 7);
  EXPECT_EQ(got.hazeVisibility_m(), 8000.0);
  // Visibility 0 (in the decoder's range) is the thickest fog we draw, not
  // an infinite extinction; a NaN one drops the datagram.
  a.visibility_m = 0;
  cigi.handleDatagram(datagram(cigi::ByteOrder::Big, 2.0, {a}), kHost);
  EXPECT_EQ(state.atmosphere().hazeVisibility_m(), kMinVisibility_m);
  a.visibility_m = std::nanf("");
  EXPECT_TRUE(cigi.handleDatagram(datagram(cigi::ByteOrder::Big, 3.0, {a}), kHost).empty());
  EXPECT_EQ(cigi.drops().of(DropReason::OutOfRange), 1u);
  EXPECT_EQ(state.atmosphere().hazeVisibility_m(), kMinVisibility_m);
}

cigi::IgMode sofMode(const std::vector<std::uint8_t>& reply) {
  const auto d = cigi::decodeDatagram(reply);
  EXPECT_TRUE(d);
  return d ? std::get<cigi::StartOfFrame>(d->packets.front()).mode : cigi::IgMode::OfflineMaintenance;
}

TEST(CigiIgMode, ResetStandbyForgetsThePoseAndIsReported) {
  asio::io_context io;
  SharedState state;
  CigiListener cigi(io, state, "127.0.0.1", 0);
  EXPECT_EQ(sofMode(cigi.handleDatagram(datagram(cigi::ByteOrder::Big, 1.0), kHost)), cigi::IgMode::Operate);
  const auto before = state.pose()->sequence;
  EXPECT_EQ(state.resets(), 0u);
  // Standby: the pose is gone and stays gone while in it (entity packets
  // counted as ignored), the Start of Frame says Standby, one reset counted.
  for (int i = 0; i < 3; ++i)
    EXPECT_EQ(sofMode(cigi.handleDatagram(datagram(cigi::ByteOrder::Big, 2.0 + i, {}, cigi::IgMode::ResetStandby),
                                          kHost)),
              cigi::IgMode::ResetStandby);
  EXPECT_FALSE(state.pose());
  EXPECT_TRUE(cigi.standby());
  EXPECT_EQ(state.resets(), 1u);
  EXPECT_EQ(cigi.ignored().of(cigi::EntityControl::kId), 3u);
  // Operate again: the next pose is new (its sequence is past the forgotten one's).
  EXPECT_EQ(sofMode(cigi.handleDatagram(datagram(cigi::ByteOrder::Big, 6.0), kHost)), cigi::IgMode::Operate);
  ASSERT_TRUE(state.pose());
  EXPECT_GT(state.pose()->sequence, before);
  EXPECT_EQ(state.resets(), 1u);
}

// What a host may send that the channel does not use is accepted and
// counted by id, never dropped: Component Control and Rate Control (not
// decoded, skipped by size), another entity, Weather Control.
TEST(CigiIgnored, UnusedPacketsAreCountedById) {
  asio::io_context io;
  SharedState state;
  CigiListener cigi(io, state, "127.0.0.1", 0);
  auto bytes = datagram(cigi::ByteOrder::Little, 1.0, {cigi::WeatherControl{}});
  for (const std::uint8_t id : {std::uint8_t{4}, std::uint8_t{8}}) {
    std::vector<std::uint8_t> p(32, 0);
    p[0] = id;
    p[1] = 32;
    bytes.insert(bytes.end(), p.begin(), p.end());
  }
  EXPECT_FALSE(cigi.handleDatagram(bytes, kHost).empty());
  EXPECT_FALSE(cigi.handleDatagram(datagram(cigi::ByteOrder::Little, 1.1, {}, cigi::IgMode::Operate, 7), kHost)
                   .empty());
  EXPECT_EQ(cigi.datagramsDropped(), 0u);
  EXPECT_EQ(cigi.ignored().of(4), 1u);
  EXPECT_EQ(cigi.ignored().of(8), 1u);
  EXPECT_EQ(cigi.ignored().of(cigi::WeatherControl::kId), 1u);
  EXPECT_EQ(cigi.ignored().of(cigi::EntityControl::kId), 1u);
  EXPECT_EQ(cigi.ignored().total(), 4u);
  EXPECT_EQ(cigi.ignoredSummary(),
            "Entity Control (2) 1, Component Control (4) 1, Rate Control (8) 1, Weather Control (12) 1");
}

// The host's camera exposure component: one for this channel's view (0)
// or every view (65535) is held in the shared state until the next, one
// for another view is counted and changes nothing, in both byte orders.
TEST(CigiExposure, TheHostsSettingForThisViewOrEveryViewIsHeld) {
  for (const cigi::ByteOrder order : {cigi::ByteOrder::Big, cigi::ByteOrder::Little}) {
    asio::io_context io;
    SharedState state;
    CigiListener cigi(io, state, "127.0.0.1", 0);
    cigi::CameraExposureControl fixed{cigi::CameraExposureControl::kAllViews, cigi::ExposureMode::Fixed, 13.0f, 0.5f};
    EXPECT_FALSE(cigi.handleDatagram(datagram(order, 1.0, {fixed}), kHost).empty());
    ASSERT_TRUE(state.hostExposure());
    EXPECT_EQ(*state.hostExposure(), fixed);
    cigi::CameraExposureControl other{7, cigi::ExposureMode::Fixed, 3.0f, 0.0f};
    EXPECT_FALSE(cigi.handleDatagram(datagram(order, 1.1, {other}), kHost).empty());
    EXPECT_EQ(*state.hostExposure(), fixed) << "another view's setting changed this channel's";
    cigi::CameraExposureControl metered{0, cigi::ExposureMode::Auto, 0.0f, -1.0f};
    EXPECT_FALSE(cigi.handleDatagram(datagram(order, 1.2, {metered}), kHost).empty());
    EXPECT_EQ(*state.hostExposure(), metered);
    EXPECT_EQ(cigi.hostExposures(), 2u);
    EXPECT_EQ(cigi.otherViewExposures(), 1u);
    EXPECT_EQ(cigi.otherViewPackets(), 1u);
    EXPECT_EQ(cigi.ignored().total(), 0u) << cigi.ignoredSummary();
    EXPECT_EQ(cigi.datagramsDropped(), 0u);
  }
}

// --- FlightGear ------------------------------------------------------------------

// cur_time is FlightGear's simulated time, the warp already added in
// (SimGear's SGTime::update: cur_time = time + warp; found with FlightGear
// 2020.3 at --timeofday=morning, where cur_time + warp put the sun 67
// degrees under the horizon): the frame's UTC within the second it is sent
// to (plus the smoother's delay, under 1 s), and its visibility the haze.
TEST(FdmTime, CurTimeIsTheSimulatedTimeAndVisibilityTheHaze) {
  asio::io_context io;
  FdmListener fdm(io, "127.0.0.1", 0);
  fgfdm::NetFdm f;
  f.lat_rad = -0.768;
  f.lon_rad = 2.958;
  f.alt_m = 1500;
  const std::uint32_t simulated = 1795299684 - 3 * 3600;  // 2026-11-21 22:21:24 UTC moved three hours back
  f.warp_s = -3 * 3600;
  f.visibility_m = 12000;
  for (int i = 0; i < 60; ++i) {  // 2 s at 30 Hz; cur_time ticks once a second
    f.curTime_unix = simulated + std::uint32_t(i / 30);
    fdm.handleDatagram(fgfdm::encodeNetFdm(f), at(i / 30.0));
  }
  const auto pose = fdm.poseAt(at(2.0));
  ASSERT_TRUE(pose);
  ASSERT_TRUE(pose->utc_s);
  EXPECT_EQ(pose->timeSource, TimeSource::FlightGear);
  // The newest datagram said second simulated + 1 at t = 59/30 s; the render
  // time is at most that, at least 1 s before it.
  EXPECT_GE(*pose->utc_s, simulated + 0.0);
  EXPECT_LE(*pose->utc_s, simulated + 2.0);
  EXPECT_EQ(fdm.atmosphere().source, AtmosphereSource::FlightGear);
  EXPECT_EQ(fdm.atmosphere().hazeVisibility_m(), 12000.0);
}

}  // namespace
}  // namespace sky::app
