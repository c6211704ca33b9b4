// The HTTP API's request handling (HttpExchange) fed whole requests as
// bytes, through the same Beast parser and checks as the socket path, on a
// real HttpApi and LiveWeather: the route table's rules, the two crashes of
// issue 18, Host and Origin, the token before the body, and the caps.
#include <gtest/gtest.h>

#include <boost/asio/io_context.hpp>
#include <nlohmann/json.hpp>

#include "sky/core/utf8.hpp"
#include "sky/server/http_api.hpp"
#include "sky/server/http_exchange.hpp"

namespace sky::server {
namespace {

const char* kToken = "t0ken";

const char* kAddStratus = R"({"changes": [{"op": "set_layer", "layer": {
  "id": 2, "type": "stratus", "base_m": 400, "thickness_m": 300, "transition_band_m": 50, "coverage": 0.8,
  "density": 0.7, "wind": {"speed_mps": 5, "from_deg": 200, "vertical_mps": 0}}}]})";

struct Answer {
  HttpExchange::Next next;
  int status = 0;
  std::string body;
  HttpExchange::Response response;
};

class HttpExchangeTest : public testing::Test {
 protected:
  HttpExchangeTest()
      : weather_(scenario_, WallClock::now(), [] { return WallClock::now(); }, [] { return std::int64_t{0}; }) {
    HttpApiOptions options;
    options.token = kToken;
    HttpApiHooks hooks;
    hooks.rejections = &rejections_;
    auto api = HttpApi::create(io_, options, weather_, hooks);
    EXPECT_TRUE(api) << api.error().detail;
    api_ = std::move(*api);
    host_ = "127.0.0.1:" + std::to_string(api_->port());
  }

  Answer send(const std::string& bytes) {
    HttpExchange exchange(*api_);
    Answer a;
    a.next = exchange.feed(bytes);
    if (a.next == HttpExchange::Next::Answer) {
      a.response = exchange.response();
      a.status = static_cast<int>(a.response.result_int());
      a.body = a.response.body();
    }
    return a;
  }
  // A request with this server's Host; `headers` end with "\r\n" each.
  Answer request(const std::string& method, const std::string& target, const std::string& body = "",
                 const std::string& headers = "") {
    std::string r = method + " " + target + " HTTP/1.1\r\nHost: " + host_ + "\r\n" + headers;
    if (!body.empty()) r += "Content-Length: " + std::to_string(body.size()) + "\r\n";
    return send(r + "\r\n" + body);
  }
  std::string bearer() const { return std::string("Authorization: Bearer ") + kToken + "\r\n"; }

  boost::asio::io_context io_;
  Scenario scenario_;
  LiveWeather weather_;
  Rejections rejections_;
  std::unique_ptr<HttpApi> api_;
  std::string host_;
};

// Every answer's body is JSON (or the health text) and valid UTF-8.
void expectValidJson(const Answer& a) {
  EXPECT_TRUE(utf8::valid(a.body)) << a.body;
  EXPECT_FALSE(nlohmann::json::parse(a.body, nullptr, false).is_discarded()) << a.body;
}

TEST(HttpRoutes, EveryRouteThatTakesABodyNeedsTheToken) {
  for (const Route& r : httpRoutes()) {
    if (r.methods & kPost) {
      EXPECT_NE(r.token, TokenRule::None) << r.path << ": a POST that changes without the token";
    }
    if (r.bodyLimit_bytes > 0) {
      EXPECT_TRUE(r.methods & kPost) << r.path;
    }
    EXPECT_EQ(findRoute(r.path), &r);
  }
  ASSERT_NE(findRoute("/api/metar"), nullptr);
  EXPECT_EQ(findRoute("/api/metar")->token, TokenRule::WhenApplying);
  EXPECT_EQ(findRoute("/api/changes")->token, TokenRule::Always);
  EXPECT_EQ(findRoute("/api/scenario")->bodyLimit_bytes, 1024u * 1024u);
  // The largest body is a GRIB2 upload, and only the token reads it.
  ASSERT_NE(findRoute("/api/grib"), nullptr);
  EXPECT_EQ(findRoute("/api/grib")->token, TokenRule::Always);
  EXPECT_EQ(maxBodyBytes(), findRoute("/api/grib")->bodyLimit_bytes);
  EXPECT_EQ(maxBodyBytes(), 32u * 1024u * 1024u);
  EXPECT_EQ(findRoute("/api/changes?x"), nullptr) << "paths, not targets";
  EXPECT_EQ(findRoute("/nowhere"), nullptr);
}

// Issue 18, crash 1: "GET /nowhere\xff" aborted the process (exit 134).
TEST_F(HttpExchangeTest, InvalidUtf8InTheTargetIsRefusedNotEchoed) {
  for (const char* target : {"/nowhere\xff", "/api/events?limit=\xff", "/api/conditions?lat_deg=\xc3",
                             "/api/state?\xed\xa0\x80"}) {
    const Answer a = request("GET", target);
    EXPECT_EQ(a.status, 400) << target;
    expectValidJson(a);
    EXPECT_NE(a.body.find("not valid UTF-8"), std::string::npos) << a.body;
  }
  // Valid UTF-8 that is no route: 404, quoted back as it came.
  const Answer a = request("GET", "/nowh\xc3\xa9re");
  EXPECT_EQ(a.status, 404);
  EXPECT_NE(a.body.find("/nowh\xc3\xa9re"), std::string::npos);
  EXPECT_GE(rejections_.get(RejectReason::HttpMalformed), 4u);
  // Percent-encoded bytes are not decoded: echoed as ASCII.
  const Answer limit = request("GET", "/api/events?limit=%FF");
  EXPECT_EQ(limit.status, 400);
  expectValidJson(limit);
}

TEST_F(HttpExchangeTest, InvalidUtf8InAHeaderIsRefused) {
  const Answer a = request("GET", "/api/state", "", "X-Name: caf\xe9\r\n");
  EXPECT_EQ(a.status, 400);
  expectValidJson(a);
  EXPECT_EQ(nlohmann::json::parse(a.body)["field"], "header X-Name");
}

// Issue 18, crash 2: a 199-byte author plus "é" was cut inside the "é" and
// every later GET /api/events aborted.
TEST_F(HttpExchangeTest, AnAuthorIsCutOnACharacterBoundary) {
  nlohmann::json change = nlohmann::json::parse(kAddStratus);
  change["author"] = std::string(199, 'a') + "\xc3\xa9";
  ASSERT_EQ(request("POST", "/api/changes", change.dump(), bearer()).status, 200);
  const Answer events = request("GET", "/api/events");
  ASSERT_EQ(events.status, 200);
  expectValidJson(events);
  EXPECT_EQ(nlohmann::json::parse(events.body)["events"][0]["author"], std::string(199, 'a'));
}

// An author already stored broken (by an older version, in its database) is
// shown with U+FFFD, not a crash.
TEST_F(HttpExchangeTest, ABrokenStoredAuthorIsReplacedWhenShown) {
  ChangeRequest broken{{SetClock{1.0, std::nullopt}}, std::string(199, 'a') + "\xc3", "api"};
  ASSERT_TRUE(weather_.submit(broken));
  const Answer events = request("GET", "/api/events?limit=1");
  ASSERT_EQ(events.status, 200);
  expectValidJson(events);
  EXPECT_EQ(nlohmann::json::parse(events.body)["events"][0]["author"], std::string(199, 'a') + "\xef\xbf\xbd");
}

TEST_F(HttpExchangeTest, TheTokenIsCheckedBeforeTheBody) {
  // A declared 60 kB body that never comes: answered 401 from the header.
  const std::string header = "POST /api/changes HTTP/1.1\r\nHost: " + host_ + "\r\nContent-Length: 60000\r\n\r\n";
  const Answer a = send(header);
  EXPECT_EQ(a.next, HttpExchange::Next::Answer) << "waited for the body";
  EXPECT_EQ(a.status, 401);
  EXPECT_EQ(a.response["WWW-Authenticate"], "Bearer");
  EXPECT_EQ(request("POST", "/api/changes", kAddStratus, "Authorization: Bearer t0keN\r\n").status, 401);
  EXPECT_EQ(request("POST", "/api/scenario", "x").status, 401);
  EXPECT_EQ(request("POST", "/api/changes", kAddStratus, bearer()).status, 200);
  EXPECT_EQ(api_->counters().unauthorized, 3u);
}

// POST /api/metar: TokenRule::WhenApplying. A preview needs no token;
// "apply": true does, decided once the body is parsed.
TEST_F(HttpExchangeTest, MetarNeedsTheTokenOnlyWhenApplying) {
  const std::string preview = R"({"reports": ["LIPQ 201150Z 24008KT 9999 BKN030 15/08 Q1015"],
    "stations": [{"icao": "LIPQ", "lat_deg": 45.8, "lon_deg": 13.5, "elevation_m": 12}]})";
  std::string apply = preview;
  apply.insert(1, R"("apply": true, )");
  const Answer p = request("POST", "/api/metar", preview);
  EXPECT_EQ(p.status, 200) << p.body;
  EXPECT_EQ(request("POST", "/api/metar", apply).status, 401);
  const Answer applied = request("POST", "/api/metar", apply, bearer());
  EXPECT_EQ(applied.status, 200) << applied.body;
  EXPECT_EQ(api_->counters().unauthorized, 1u);
}

// GET /api/metar/stations (issue 23: the console's station markers): an
// applied report is listed with its station, its text and the layers it
// became; a preview is not; a station whose region is gone has no report;
// "remove" forgets it.
TEST_F(HttpExchangeTest, MetarStationsListTheLatestAppliedReport) {
  const auto stations = [&] {
    const Answer a = request("GET", "/api/metar/stations");
    EXPECT_EQ(a.status, 200) << a.body;
    return nlohmann::json::parse(a.body)["stations"];
  };
  EXPECT_TRUE(stations().empty()) << "no --metar-stations table in this fixture, nothing applied";
  const std::string body = R"({"reports": ["METAR LIPQ 201150Z 24008KT 1500 BR OVC004 15/08 Q1015"],
    "stations": [{"icao": "LIPQ", "lat_deg": 45.8, "lon_deg": 13.5, "elevation_m": 12}]})";
  ASSERT_EQ(request("POST", "/api/metar", body).status, 200);
  EXPECT_TRUE(stations().empty()) << "a preview is not applied";
  std::string apply = body;
  apply.insert(1, R"("apply": true, )");
  const Answer applied = request("POST", "/api/metar", apply, bearer());
  ASSERT_EQ(applied.status, 200) << applied.body;
  const auto list = stations();
  ASSERT_EQ(list.size(), 1u) << list;
  EXPECT_EQ(list[0]["icao"], "LIPQ");
  EXPECT_DOUBLE_EQ(list[0]["lat_deg"].get<double>(), 45.8);
  const auto& report = list[0]["report"];
  ASSERT_TRUE(report.is_object()) << list;
  EXPECT_EQ(report["text"], "METAR LIPQ 201150Z 24008KT 1500 BR OVC004 15/08 Q1015");
  EXPECT_EQ(report["sequence"], nlohmann::json::parse(applied.body)["applied"]["sequence"]);
  EXPECT_EQ(report["sky"], "read");
  // The layers it became: its region's, the overcast at 400 ft in its slot
  // (40 and up, metar_changes.hpp) at 8/8.
  const auto regionId = report["region_id"].get<std::uint32_t>();
  const auto state = nlohmann::json::parse(request("GET", "/api/state").body);
  for (const auto& r : state["regions"]) {
    if (r["id"] == regionId) {
      EXPECT_EQ(report["layers"], r["layers"]);
    }
  }
  ASSERT_FALSE(report["layers"].empty());
  bool overcast = false;
  for (const auto& l : report["layers"])
    overcast = overcast || (l["id"].get<int>() >= 40 && l["coverage"].get<double>() == 1.0);
  EXPECT_TRUE(overcast) << report["layers"];
  // The region removed by another change: the station stays, its report goes.
  const std::string removeRegion = R"({"changes": [{"op": "remove_region", "id": )" + std::to_string(regionId) + "}]}";
  ASSERT_EQ(request("POST", "/api/changes", removeRegion, bearer()).status, 200);
  EXPECT_TRUE(stations()[0]["report"].is_null()) << stations();
  // "remove" forgets a station a request brought.
  ASSERT_EQ(request("POST", "/api/metar", apply, bearer()).status, 200);
  EXPECT_TRUE(stations()[0]["report"].is_object());
  const Answer removed = request("POST", "/api/metar", R"({"apply": true, "remove": ["LIPQ"],
    "stations": [{"icao": "LIPQ", "lat_deg": 45.8, "lon_deg": 13.5, "elevation_m": 12}]})", bearer());
  ASSERT_EQ(removed.status, 200) << removed.body;
  EXPECT_TRUE(stations().empty()) << stations();
  EXPECT_EQ(findRoute("/api/metar/stations")->token, TokenRule::None);
}

// After a restart the reports' texts are gone (kept in memory) but the
// stations' regions are back: a table station's region, found by its centre,
// is listed with its layers and no text; a region elsewhere or outside the
// METAR ids is not taken for it.
TEST(MetarStationBoard, AStationsRegionIsFoundWithoutItsReport) {
  const std::vector<Station> table = {{"LJLJ", 46.2237, 14.4576, 388}, {"LIPQ", 45.8275, 13.4722, 12}};
  WeatherView now;
  weather::Region ljlj;
  ljlj.id = 44773;
  ljlj.centerLat_deg = 46.2237;
  ljlj.centerLon_deg = 14.4576;
  weather::CloudLayer fog;
  fog.id = 40;
  fog.coverage = 1;
  fog.base_m = 388;
  fog.thickness_m = 60;
  ljlj.layers = {fog};
  weather::Region notMetar = ljlj;  // at LIPQ, but an operator's region id
  notMetar.id = 7;
  notMetar.centerLat_deg = 45.8275;
  notMetar.centerLon_deg = 13.4722;
  now.regions = {ljlj, notMetar};
  const auto list = MetarStationBoard().list(table, now)["stations"];
  ASSERT_EQ(list.size(), 2u) << list;
  EXPECT_EQ(list[0]["icao"], "LJLJ");
  ASSERT_TRUE(list[0]["report"].is_object()) << list;
  EXPECT_TRUE(list[0]["report"]["text"].is_null());
  EXPECT_EQ(list[0]["report"]["region_id"], 44773);
  ASSERT_EQ(list[0]["report"]["layers"].size(), 1u);
  EXPECT_EQ(list[0]["report"]["layers"][0]["id"], 40);
  EXPECT_TRUE(list[1]["report"].is_null()) << list;
}

TEST_F(HttpExchangeTest, ForeignHostOrOriginIsForbidden) {
  EXPECT_EQ(send("GET /api/state HTTP/1.1\r\nHost: evil.example:" + std::to_string(api_->port()) + "\r\n\r\n").status,
            403);
  EXPECT_EQ(send("GET /api/state HTTP/1.1\r\n\r\n").status, 403) << "no Host";
  const Answer post = request("POST", "/api/changes", kAddStratus, bearer() + "Origin: http://evil.example\r\n");
  EXPECT_EQ(post.status, 403);
  expectValidJson(post);
  EXPECT_EQ(weather_.accepted(), 0u);
  const std::string upgrade =
      "Upgrade: websocket\r\nConnection: Upgrade\r\nSec-WebSocket-Key: dGhlIHNhbXBsZSBub25jZQ==\r\n"
      "Sec-WebSocket-Version: 13\r\n";
  EXPECT_EQ(request("GET", "/api/ws", "", upgrade + "Origin: http://evil.example\r\n").status, 403);
  EXPECT_EQ(request("GET", "/api/ws", "", upgrade + "Origin: http://" + host_ + "\r\n").next,
            HttpExchange::Next::Upgrade);
  EXPECT_EQ(request("GET", "/api/ws", "", upgrade).next, HttpExchange::Next::Upgrade);
  EXPECT_EQ(request("POST", "/api/changes", kAddStratus, bearer() + "Origin: http://" + host_ + "\r\n").status, 200);
  EXPECT_EQ(rejections_.get(RejectReason::HttpForbidden), 4u);
}

// The console feed's cap refuses an upgrade with a 503 that says why.
TEST_F(HttpExchangeTest, AFullConsoleFeedRefusesTheUpgradeClearly) {
  HttpApiOptions options;
  options.feed.maxClients = 0;
  HttpApiHooks hooks;
  hooks.rejections = &rejections_;
  auto full = HttpApi::create(io_, options, weather_, hooks);
  ASSERT_TRUE(full);
  HttpExchange exchange(**full);
  const auto next = exchange.feed("GET /api/ws HTTP/1.1\r\nHost: localhost\r\nUpgrade: websocket\r\n"
                                  "Connection: Upgrade\r\nSec-WebSocket-Key: dGhlIHNhbXBsZSBub25jZQ==\r\n"
                                  "Sec-WebSocket-Version: 13\r\n\r\n");
  ASSERT_EQ(next, HttpExchange::Next::Answer);
  EXPECT_EQ(exchange.response().result_int(), 503u);
  EXPECT_EQ(nlohmann::json::parse(exchange.response().body())["error"],
            "ws: 0 console clients connected, at most 0");
  EXPECT_EQ(rejections_.get(RejectReason::WsRefused), 1u);
}

TEST_F(HttpExchangeTest, CapsAndMethods) {
  // Header over 8 KiB: 431.
  EXPECT_EQ(request("GET", "/healthz", "", "X-Bloat: " + std::string(9000, 'b') + "\r\n").status, 431);
  // A body over the route's limit: 413 from the declared length.
  const Answer big = send("POST /api/changes HTTP/1.1\r\nHost: " + host_ + "\r\n" + bearer() +
                          "Content-Length: 70000\r\n\r\n{");
  EXPECT_EQ(big.status, 413);
  EXPECT_EQ(big.next, HttpExchange::Next::Answer);
  // Over the largest route's limit: Beast refuses it within the header.
  EXPECT_EQ(send("POST /api/scenario HTTP/1.1\r\nHost: " + host_ + "\r\n" + bearer() +
                 "Content-Length: 2000000\r\n\r\n").status,
            413);
  // A chunked body past the limit is cut off while it is read.
  std::string chunked = "POST /api/changes HTTP/1.1\r\nHost: " + host_ + "\r\n" + bearer() +
                        "Transfer-Encoding: chunked\r\n\r\n";
  for (int i = 0; i < 20; ++i) chunked += "1000\r\n" + std::string(4096, ' ') + "\r\n";
  EXPECT_EQ(send(chunked + "0\r\n\r\n").status, 413);
  const Answer method = request("DELETE", "/api/changes");
  EXPECT_EQ(method.status, 405);
  EXPECT_EQ(method.response["Allow"], "POST");
  EXPECT_EQ(request("GET", "/api/ws").status, 426);
  EXPECT_EQ(send("NOT HTTP\r\n\r\n").status, 400);
  EXPECT_EQ(send("GET /healthz HTTP/1.1\r\nHost: " + host_).next, HttpExchange::Next::Close) << "left mid-header";
  EXPECT_EQ(send("").next, HttpExchange::Next::Close);
  EXPECT_EQ(rejections_.get(RejectReason::HttpHeaderTooLarge), 1u);
  EXPECT_EQ(rejections_.get(RejectReason::HttpTooLarge), 3u);
}

TEST_F(HttpExchangeTest, AnswersCarryTheBrowserSafetyHeaders) {
  for (const std::string target : {"/healthz", "/nowhere"}) {
    const Answer a = request("GET", target);
    EXPECT_EQ(a.response["X-Content-Type-Options"], "nosniff");
    EXPECT_EQ(a.response["X-Frame-Options"], "DENY");
    EXPECT_EQ(a.response["Content-Security-Policy"], "frame-ancestors 'none'");
  }
  const Answer metrics = request("GET", "/metrics");
  EXPECT_NE(metrics.body.find("skyshell_rejected_inputs_total{reason=\"http_forbidden\"} 0"), std::string::npos)
      << metrics.body;
  EXPECT_NE(metrics.body.find("skyshell_http_connections 0"), std::string::npos);
}

}  // namespace
}  // namespace sky::server
