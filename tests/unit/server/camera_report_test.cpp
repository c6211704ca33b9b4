// Camera reports on a real loopback socket: the server says in its Hello that
// it takes them, keeps the newest per subscriber (with the area it
// subscribed to) for the console, ignores message kinds it does not know,
// and answers a report out of range like any bad message (Error, close,
// counted as stream_malformed) while other subscribers go on.
#include <gtest/gtest.h>

#include <thread>

#include "sky/server/scenario.hpp"
#include "sky/server/server.hpp"
#include "stream_test_client.hpp"

namespace sky::server {
namespace {

class CameraReportTest : public ::testing::Test {
 protected:
  void SetUp() override {
    auto scenario = loadScenario(SKY_SOURCE_DIR "/deploy/scenarios/skeleton-cumulus.toml");
    ASSERT_TRUE(scenario) << scenario.error().detail;
    ServerOptions options;
    options.heartbeatInterval = 50ms;
    options.handleSignals = false;
    auto server = Server::create(options, WeatherState(*scenario, WallClock::now()));
    ASSERT_TRUE(server) << server.error().detail;
    server_ = std::move(*server);
    server_->onRenderersChanged([this] { ++changes_; });
    thread_ = std::thread([this] { server_->run(); });
  }
  void TearDown() override {
    server_->stop();
    thread_.join();
  }
  std::vector<RendererInfo> renderers() {
    return onIo(server_->io(), [this] { return server_->renderers(); });
  }
  // Polls until pred(renderers()) holds (the server reads asynchronously).
  template <class Pred>
  std::vector<RendererInfo> waitFor(Pred pred) {
    auto r = renderers();
    for (int i = 0; i < 250 && !pred(r); ++i) {
      std::this_thread::sleep_for(20ms);
      r = renderers();
    }
    return r;
  }

  std::unique_ptr<Server> server_;
  std::thread thread_;
  std::atomic<int> changes_{0};
};

stream::CameraReport report(const std::string& channel, double lat_deg, double lon_deg) {
  stream::CameraReport r;
  r.channel = channel;
  r.lat_deg = lat_deg;
  r.lon_deg = lon_deg;
  r.alt_m = 1200;
  r.heading_deg = 270;
  r.pitch_deg = 5;
  r.roll_deg = -10;
  r.frame = 42;
  r.weatherVersion = 3;
  r.weatherClock_s = 100;
  return r;
}

TEST_F(CameraReportTest, HelloSaysReportsAreTakenAndTheNewestIsKeptPerSubscriber) {
  TestClient left(server_->port()), right(server_->port());
  auto hello = left.readNext<stream::Hello>();
  ASSERT_TRUE(hello) << hello.error().detail;
  EXPECT_NE(hello->features & stream::kFeatureCameraReports, 0u);
  ASSERT_TRUE(right.readNext<stream::Hello>());

  // Connected, nothing said yet: listed without area or report.
  auto list = waitFor([](const auto& r) { return r.size() == 2; });
  ASSERT_EQ(list.size(), 2u);
  EXPECT_FALSE(list[0].area);
  EXPECT_FALSE(list[0].report);
  EXPECT_EQ(list[0].peer.rfind("127.0.0.1:", 0), 0u) << list[0].peer;

  stream::Subscribe s;
  s.area = {46.2, 12.8, 60000};
  left.send(s);
  ASSERT_TRUE(left.readNext<weather::WeatherSnapshot>());
  left.send(report("left", 46.1, 12.7));
  left.send(report("left", 46.3, 12.9));  // the newer one replaces it
  right.send(report("right", -33.9, 151.2));
  list = waitFor([](const auto& r) {
    return r.size() == 2 && r[0].report && r[0].report->lat_deg == 46.3 && r[1].report;
  });
  ASSERT_EQ(list.size(), 2u);
  ASSERT_TRUE(list[0].report && list[1].report);
  EXPECT_EQ(list[0].report->channel, "left");
  EXPECT_DOUBLE_EQ(list[0].report->lon_deg, 12.9);
  EXPECT_DOUBLE_EQ(list[0].report->alt_m, 1200);
  EXPECT_DOUBLE_EQ(list[0].report->heading_deg, 270);
  EXPECT_EQ(list[0].report->frame, 42u);
  EXPECT_EQ(list[0].report->weatherVersion, 3u);
  ASSERT_TRUE(list[0].area);
  EXPECT_DOUBLE_EQ(list[0].area->radius_m, 60000);
  EXPECT_GE(list[0].lastReportAge_s, 0.0);
  EXPECT_LT(list[0].lastReportAge_s, 30.0);
  EXPECT_EQ(list[1].report->channel, "right");
  EXPECT_FALSE(list[1].area) << "the right channel never subscribed";
  EXPECT_GE(changes_.load(), 5) << "connects, a subscribe and reports each notify the console";

  // Gone: off the list.
  right.close();
  list = waitFor([](const auto& r) { return r.size() == 1; });
  ASSERT_EQ(list.size(), 1u);
  EXPECT_EQ(list[0].report->channel, "left");
}

// A newer client may send kinds this server does not know: ignored, and the
// session goes on being served.
TEST_F(CameraReportTest, AnUnknownKindIsIgnored) {
  TestClient client(server_->port());
  ASSERT_TRUE(client.readNext<stream::Hello>());
  client.send(stream::UnknownKind{200});
  stream::Subscribe s;
  s.area = {46.2, 12.8, 60000};
  client.send(s);
  auto snapshot = client.readNext<weather::WeatherSnapshot>();
  ASSERT_TRUE(snapshot) << snapshot.error().detail;
  EXPECT_EQ(server_->rejections().get(RejectReason::StreamMalformed), 0u);
}

TEST_F(CameraReportTest, AReportOutOfRangeIsAnErrorAndIsCounted) {
  TestClient good(server_->port()), bad(server_->port());
  ASSERT_TRUE(good.readNext<stream::Hello>());
  ASSERT_TRUE(bad.readNext<stream::Hello>());
  bad.send(report("bad", 91.0, 0));
  auto error = bad.readNext<stream::StreamError>();
  ASSERT_TRUE(error) << error.error().detail;
  EXPECT_EQ(error->code, static_cast<std::uint16_t>(ErrorCode::InvalidArgument));
  EXPECT_NE(error->detail.find("CameraReport.lat_deg"), std::string::npos) << error->detail;
  EXPECT_EQ(bad.read().error().detail, "eof");
  EXPECT_EQ(server_->rejections().get(RejectReason::StreamMalformed), 1u);
  good.send(report("good", 45, 7));
  auto list = waitFor([](const auto& r) { return r.size() == 1 && r[0].report; });
  ASSERT_EQ(list.size(), 1u);
  EXPECT_EQ(list[0].report->channel, "good");
}

}  // namespace
}  // namespace sky::server
