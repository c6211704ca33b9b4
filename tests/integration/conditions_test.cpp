// A host asks the renderer, over real CIGI UDP, for the weather at points
// around the ownship (Environmental Conditions Requests) and the renderer
// answers (Weather Conditions Response, Aerosol Concentration Response) from
// the weather it holds; the same points asked of the weather server
// (GET /api/conditions, the same protocol/ function over the same tiles)
// must give the same wind, vertical wind and cloud. A few answers are also
// checked against hand values from the scenario, so both sides cannot agree
// on something wrong.
#include <arpa/inet.h>
#include <netinet/in.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <thread>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "child_process.hpp"
#include "sky/cigi/codec.hpp"
#include "sky/weather/query.hpp"
#include "weatherd_process.hpp"

namespace fs = std::filesystem;
using namespace std::chrono_literals;

namespace sky::test {
namespace {

// The renderer's documented mapping of cloud to the CIGI response
// (docs/integrating.md, "Conditions answers"): humidity 100 % in cloud, 50 % in clear air; visibility
// 3.912 / (0.05 /m x density), at most 50 km; cloud water 0.5 g/m^3 x density.
constexpr double kExtinctionPerDensity = 0.05, kClearVisibility_m = 50000, kLiquidWater_gpm3 = 0.5;

// Two layers with different winds and a gap between them (the wind there is
// interpolated), clock at x1.
constexpr const char* kScenario = R"([clock]
start_s = 0.0
rate = 1.0

[[layer]]
id = 1
type = "cumulus"
base_m = 1500.0
thickness_m = 1500.0
transition_band_m = 200.0
coverage = 0.4
density = 0.8
wind = { speed_mps = 10.0, from_deg = 270.0, vertical_mps = 0.5 }

[[layer]]
id = 2
type = "altostratus"
base_m = 5000.0
thickness_m = 1000.0
transition_band_m = 100.0
coverage = 0.9
density = 0.6
wind = { speed_mps = 25.0, from_deg = 300.0, vertical_mps = -0.2 }
)";

constexpr double kLat = 46.2, kLon = 12.8;

// A CIGI host on one UDP socket: sends a datagram to the renderer and reads
// the IG's answers.
class CigiHost {
 public:
  CigiHost() : fd_(::socket(AF_INET, SOCK_DGRAM, 0)) {}
  double ownshipLat_deg = kLat, ownshipLon_deg = kLon;  // where ownship() flies
  ~CigiHost() { ::close(fd_); }
  void send(unsigned port, const std::vector<cigi::Packet>& packets) {
    cigi::DatagramWriter w(cigi::ByteOrder::Big);
    cigi::IgControl ig;
    ig.hostFrame = frame_++;
    w.add(ig);
    for (const auto& p : packets) w.add(p);
    sockaddr_in to{};
    to.sin_family = AF_INET;
    to.sin_port = htons(static_cast<std::uint16_t>(port));
    to.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    const auto& bytes = w.bytes();
    ASSERT_EQ(::sendto(fd_, bytes.data(), bytes.size(), 0, reinterpret_cast<const sockaddr*>(&to), sizeof to),
              static_cast<ssize_t>(bytes.size()));
  }
  // The next IG datagram within `timeout`, decoded.
  std::optional<cigi::Datagram> receive(std::chrono::milliseconds timeout) {
    pollfd p{fd_, POLLIN, 0};
    if (::poll(&p, 1, static_cast<int>(timeout.count())) <= 0) return std::nullopt;
    std::vector<std::uint8_t> buf(65536);
    const ssize_t n = ::recv(fd_, buf.data(), buf.size(), 0);
    if (n <= 0) return std::nullopt;
    auto d = cigi::decodeDatagram(std::span(buf.data(), std::size_t(n)));
    EXPECT_TRUE(d) << describe(d.error());
    return d ? std::optional(*d) : std::nullopt;
  }

 private:
  int fd_;
  std::uint32_t frame_ = 0;
};

cigi::EntityControl ownship(const CigiHost& host) {
  cigi::EntityControl e;
  e.lat_deg = host.ownshipLat_deg;
  e.lon_deg = host.ownshipLon_deg;
  e.alt_m = 900;
  e.yaw_deg = 90;
  return e;
}

struct Point {
  const char* what;
  double lat_deg, lon_deg, alt_m;
};

struct IgAnswer {
  std::optional<cigi::WeatherConditionsResponse> weather;
  std::vector<cigi::AerosolConcentrationResponse> aerosols;
};

// Asks until answered (UDP may drop; the renderer answers every datagram).
IgAnswer ask(CigiHost& host, unsigned port, std::uint8_t id, const Point& p) {
  cigi::EnvironmentalConditionsRequest r;
  r.requestType = cigi::kRequestWeather | cigi::kRequestAerosol;
  r.requestId = id;
  r.lat_deg = p.lat_deg;
  r.lon_deg = p.lon_deg;
  r.alt_m = p.alt_m;
  for (int attempt = 0; attempt < 100; ++attempt) {
    host.send(port, {ownship(host), r});
    for (auto until = std::chrono::steady_clock::now() + 2s; std::chrono::steady_clock::now() < until;) {
      auto d = host.receive(500ms);
      if (!d) continue;
      IgAnswer a;
      for (const auto& packet : d->packets) {
        if (const auto* w = std::get_if<cigi::WeatherConditionsResponse>(&packet); w && w->requestId == id)
          a.weather = *w;
        if (const auto* c = std::get_if<cigi::AerosolConcentrationResponse>(&packet); c && c->requestId == id)
          a.aerosols.push_back(*c);
      }
      if (a.weather) return a;
    }
  }
  ADD_FAILURE() << "no Weather Conditions Response to request " << int(id) << " (" << p.what << ")";
  return {};
}

// skyshell-render headless on the weather server, taking CIGI on a port of
// its own (its log in dir/render.log).
ChildProcess startRenderer(const fs::path& dir, unsigned streamPort) {
  return ChildProcess({SKY_RENDER, "--headless", "--server", "127.0.0.1:" + std::to_string(streamPort), "--cigi-port",
                       "0", "--port-file", (dir / "render.port").string(), "--out", (dir / "frames").string(),
                       "--width", "32", "--height", "18", "--no-exr", "--weather-timeout", "120"},
                      (dir / "render.log").string(), {"ASAN_OPTIONS=detect_leaks=0:abort_on_error=1"});
}

// Flies the ownship until the renderer logs a snapshot of its detailed area
// (area 0) that `wanted(layers, tiles)` accepts; false after 180 s.
template <class Wanted>
bool waitForSnapshot(ChildProcess& render, CigiHost& host, unsigned cigiPort, Wanted wanted) {
  const std::string snapshot = "weather snapshot of area 0: ";
  for (auto until = std::chrono::steady_clock::now() + 180s; std::chrono::steady_clock::now() < until;) {
    host.send(cigiPort, {ownship(host)});
    while (host.receive(100ms)) {
    }
    const std::string log = render.log();
    for (std::size_t at = log.find(snapshot); at != std::string::npos; at = log.find(snapshot, at + 1)) {
      int layers = 0, tiles = 0;
      if (std::sscanf(log.c_str() + at + snapshot.size(), "%d layers, %d", &layers, &tiles) == 2 &&
          wanted(layers, tiles))
        return true;
    }
    std::this_thread::sleep_for(200ms);
  }
  return false;
}

double angleBetween_deg(double a, double b) {
  const double d = std::fmod(std::abs(a - b), 360.0);
  return std::min(d, 360.0 - d);
}

TEST(CigiConditions, TheRendererAnswersWhatTheServerSaysAtThePoint) {
  const fs::path dir = fs::path(SKY_TEST_OUTPUT_DIR) / "conditions-vs-server";
  fs::remove_all(dir);  // an old port file would name a port nobody listens on
  fs::create_directories(dir);
  std::ofstream(dir / "two-layers.toml") << kScenario;
  Weatherd w("conditions-vs-server-weatherd", (dir / "two-layers.toml").string());
  ASSERT_GT(w.streamPort, 0u) << w.process->log();
  ASSERT_GT(w.httpPort, 0u) << w.process->log();
  // A 20 km storm region on the ownship, drifting with the wind, with denser
  // cumulus: inside it the renderer's tiles carry coverage 0.95.
  const auto posted = w.request("POST", "/api/changes", R"({"changes": [{"op": "set_region", "region": {
      "id": 3, "center_lat_deg": 46.2, "center_lon_deg": 12.8, "size_x_m": 20000, "size_y_m": 20000,
      "corner_radius_m": 2000, "transition_m": 1000, "drifts_with_wind": true,
      "layers": [{"id": 1, "type": "cumulus", "base_m": 1500, "thickness_m": 1500, "transition_band_m": 200,
                  "coverage": 0.95, "density": 1,
                  "wind": {"speed_mps": 10, "from_deg": 270, "vertical_mps": 0.5}}]}}]})");
  ASSERT_EQ(posted.status, 200) << posted.body;

  ChildProcess render = startRenderer(dir, w.streamPort);
  const unsigned cigiPort = waitForPortFile((dir / "render.port").string(), 120s);
  ASSERT_GT(cigiPort, 0u) << render.log();

  // The ownship's pose makes the renderer subscribe around it: wait for the
  // snapshot with the region's tiles before asking.
  CigiHost host;
  const bool tiles = waitForSnapshot(render, host, cigiPort, [](int, int count) { return count > 0; });
  ASSERT_TRUE(tiles) << "no snapshot with tiles:\n" << render.log();

  const double kmLat = 1.0 / 111.2, kmLon = 1.0 / (111.2 * std::cos(kLat * M_PI / 180));
  const Point points[] = {
      {"in the region, inside layer 1", kLat, kLon, 2200},
      {"outside the region (40 km east), inside layer 1", kLat, kLon + 40 * kmLon, 2200},
      {"below every layer", kLat, kLon, 500},
      {"in layer 1's base transition band", kLat, kLon, 1450},
      {"between the layers", kLat, kLon, 4000},
      {"inside layer 2", kLat + 30 * kmLat, kLon - 20 * kmLon, 5500},
      {"above every layer", kLat, kLon, 9000},
  };
  std::vector<nlohmann::json> server;
  std::vector<IgAnswer> ig;
  for (std::size_t i = 0; i < std::size(points); ++i) {
    const Point& p = points[i];
    ig.push_back(ask(host, cigiPort, static_cast<std::uint8_t>(10 + i), p));
    char target[160];
    std::snprintf(target, sizeof target, "/api/conditions?lat_deg=%.9f&lon_deg=%.9f&alt_m=%.3f", p.lat_deg,
                  p.lon_deg, p.alt_m);
    const auto reply = w.request("GET", target, "", "");
    ASSERT_EQ(reply.status, 200) << reply.body;
    server.push_back(nlohmann::json::parse(reply.body));
    ASSERT_TRUE(ig.back().weather) << p.what;
    const auto& wcr = *ig.back().weather;
    const auto& s = server.back();
    SCOPED_TRACE(std::string(p.what) + ": server " + s.dump());
    EXPECT_EQ(s["tile_level"], 11);
    // Wind: the CIGI fields are floats.
    EXPECT_NEAR(wcr.horizontalWind_mps, s["wind"]["speed_mps"].get<double>(), 1e-4);
    EXPECT_NEAR(wcr.verticalWind_mps, s["wind"]["vertical_mps"].get<double>(), 1e-5);
    if (s["wind"]["speed_mps"].get<double>() > 0.1) {
      EXPECT_LT(angleBetween_deg(wcr.windDirection_deg, s["wind"]["from_deg"].get<double>()), 1e-3);
    }
    // Cloud: present or not, and how dense (from the visibility).
    const double density = s["cloud_density"].get<double>();
    EXPECT_EQ(wcr.humidity_pct, density > 0 ? 100 : 50);
    const double visibility = density > 0 ? std::min(kClearVisibility_m, 3.912 / (kExtinctionPerDensity * density))
                                          : kClearVisibility_m;
    EXPECT_NEAR(wcr.visibility_m, visibility, 1e-4 * visibility);
    if (density > 0) {
      EXPECT_NEAR(s["visibility_m"].get<double>(), 3.912 / (kExtinctionPerDensity * density), 1e-6);
    } else {
      EXPECT_TRUE(s["visibility_m"].is_null());
    }
    // The densest layer's cloud water, in its Aerosol Concentration Response.
    if (!s["layer_id"].is_null()) {
      const auto layer = s["layer_id"].get<std::uint32_t>();
      const auto it = std::find_if(ig.back().aerosols.begin(), ig.back().aerosols.end(),
                                   [&](const auto& a) { return static_cast<std::uint32_t>(a.layerId) == layer; });
      ASSERT_NE(it, ig.back().aerosols.end()) << "no aerosol response for layer " << layer;
      EXPECT_NEAR(it->concentration_gpm3, kLiquidWater_gpm3 * density, 1e-5);
    }
    EXPECT_NEAR(wcr.airTemperature_c, s["air_temperature_c"].get<double>(), 1e-4);
    EXPECT_NEAR(wcr.pressure_hpa, s["pressure_hpa"].get<double>(), 1e-3);
    std::printf("[conditions] %-48s IG wind %6.2f m/s from %6.1f, vertical %5.2f, humidity %3d, visibility %8.1f m"
                " | server density %.4f layer %s\n",
                p.what, wcr.horizontalWind_mps, wcr.windDirection_deg, wcr.verticalWind_mps, wcr.humidity_pct,
                wcr.visibility_m, density, s["layer_id"].dump().c_str());
  }
  // Hand values from the scenario and the region: coverage x density x
  // presence, and each layer's own wind inside it. Tile fractions travel in
  // 8 bits: within half a step of 1/255 where the layer has tiles.
  constexpr double kTileStep = 0.5 / 255;
  EXPECT_NEAR(server[0]["cloud_density"].get<double>(), 0.95 * 1.0, kTileStep);  // the region's cumulus
  EXPECT_NEAR(server[1]["cloud_density"].get<double>(), 0.4 * 0.8, kTileStep);   // the global layer
  EXPECT_EQ(server[2]["cloud_density"].get<double>(), 0.0);
  EXPECT_GT(server[3]["cloud_density"].get<double>(), 0.0);                 // fading in below the base
  EXPECT_LT(server[3]["cloud_density"].get<double>(), 0.95);
  EXPECT_EQ(server[4]["cloud_density"].get<double>(), 0.0);
  EXPECT_NEAR(server[5]["cloud_density"].get<double>(), 0.9 * 0.6, 1e-6);
  EXPECT_EQ(server[6]["cloud_density"].get<double>(), 0.0);
  EXPECT_NEAR(ig[0].weather->horizontalWind_mps, 10, 1e-4);
  EXPECT_NEAR(ig[0].weather->verticalWind_mps, 0.5, 1e-5);
  EXPECT_NEAR(ig[5].weather->horizontalWind_mps, 25, 1e-4);
  EXPECT_NEAR(ig[5].weather->windDirection_deg, 300, 1e-3);
  EXPECT_NEAR(ig[6].weather->horizontalWind_mps, 25, 1e-4);  // above the top: the highest layer's
  // Between the layers (4000 m: 1/2 of the way from layer 1's top at 3000 m
  // to layer 2's base at 5000 m) the wind is neither layer's.
  const double between = ig[4].weather->horizontalWind_mps;
  EXPECT_GT(between, 10.5);
  EXPECT_LT(between, 24.5);
  EXPECT_EQ(w.process->stop(), 0) << w.process->log();
}

TEST(CigiConditions, TheServerRefusesABadQueryNamingTheField) {
  Weatherd w("conditions-bad-query");
  ASSERT_GT(w.httpPort, 0u) << w.process->log();
  const std::pair<const char*, const char*> cases[] = {
      {"/api/conditions?lat_deg=46&lon_deg=12", "alt_m: missing"},
      {"/api/conditions?lat_deg=91&lon_deg=12&alt_m=0", "lat_deg: 91 is not in"},
      {"/api/conditions?lat_deg=46&lon_deg=abc&alt_m=0", "lon_deg: 'abc' is not a number"},
      {"/api/conditions?lat_deg=46&lon_deg=12&alt_m=0&level=2.5", "level: '2.5' is not an integer"},
      {"/api/conditions?lat_deg=46&lat_deg=47&lon_deg=12&alt_m=0", "lat_deg: given twice"},
      {"/api/conditions?lat=46&lon_deg=12&alt_m=0", "unknown key 'lat'"},
  };
  for (const auto& [target, message] : cases) {
    const auto reply = w.request("GET", target, "", "");
    EXPECT_EQ(reply.status, 400) << target;
    EXPECT_NE(reply.body.find(message), std::string::npos) << target << ": " << reply.body;
  }
  const auto ok = w.request("GET", "/api/conditions?lat_deg=46&lon_deg=12&alt_m=2000&level=13", "", "");
  ASSERT_EQ(ok.status, 200) << ok.body;
  EXPECT_EQ(nlohmann::json::parse(ok.body)["tile_level"], 13);
  EXPECT_EQ(w.process->stop(), 0) << w.process->log();
}

// A GRIB2 forecast (GFS over north-east Italy) reaches the renderer through
// the stream: its CIGI answers carry the forecast's layers, as the server's
// point query does, inside each of them and between them.
TEST(CigiConditions, TheRendererAnswersTheForecastsClouds) {
  const fs::path dir = fs::path(SKY_TEST_OUTPUT_DIR) / "conditions-grib";
  fs::remove_all(dir);
  fs::create_directories(dir);
  Weatherd w("conditions-grib-weatherd", SKY_SCENARIO_CLEAR, false,
             {"--grib", std::string(SKY_TEST_DATA_DIR) + "/grib/gfs-2p5deg-2011011012-f120-cloud-layers-10m-wind.grib2"});
  ASSERT_GT(w.httpPort, 0u) << w.process->log();
  ChildProcess render = startRenderer(dir, w.streamPort);
  const unsigned cigiPort = waitForPortFile((dir / "render.port").string(), 120s);
  ASSERT_GT(cigiPort, 0u) << render.log();
  // Wait for the detailed area's snapshot with the forecast's tiles (the
  // scenario's layer and the five forecast layers).
  CigiHost host;
  const bool tiles =
      waitForSnapshot(render, host, cigiPort, [](int layers, int count) { return layers >= 5 && count > 0; });
  ASSERT_TRUE(tiles) << "no snapshot with the forecast's tiles:\n" << render.log();
  const Point points[] = {
      {"in the boundary-layer cloud", kLat, kLon, 800},   {"in the low layer", kLat, kLon, 1700},
      {"between low and middle", kLat, kLon, 3000},       {"in the middle layer", kLat, kLon, 4500},
      {"in the high layer", kLat, kLon, 8500},            {"above every layer", kLat, kLon, 12000},
  };
  int cloudy = 0;
  double boundaryWind = 0;
  for (std::size_t i = 0; i < std::size(points); ++i) {
    const Point& p = points[i];
    const IgAnswer ig = ask(host, cigiPort, static_cast<std::uint8_t>(40 + i), p);
    char target[160];
    std::snprintf(target, sizeof target, "/api/conditions?lat_deg=%.9f&lon_deg=%.9f&alt_m=%.3f", p.lat_deg, p.lon_deg,
                  p.alt_m);
    const auto s = nlohmann::json::parse(w.request("GET", target, "", "").body);
    ASSERT_TRUE(ig.weather) << p.what;
    SCOPED_TRACE(std::string(p.what) + ": server " + s.dump());
    const double density = s["cloud_density"].get<double>();
    cloudy += density > 0;
    EXPECT_EQ(ig.weather->humidity_pct, density > 0 ? 100 : 50);
    const double visibility = density > 0 ? std::min(kClearVisibility_m, 3.912 / (kExtinctionPerDensity * density))
                                          : kClearVisibility_m;
    EXPECT_NEAR(ig.weather->visibility_m, visibility, 1e-4 * visibility);
    if (!s["layer_id"].is_null()) {
      const auto layer = s["layer_id"].get<std::uint32_t>();
      EXPECT_GE(layer, 30u);
      EXPECT_LE(layer, 34u);
      EXPECT_FALSE(s["forecast_sources"][std::to_string(layer)].is_null());
    }
    // The wind: the forecast's 10 m wind moves the boundary-layer cloud
    // (wind tiles); the renderer's area and the server's point query cover
    // the point with wind tiles of different levels, each smoothed by the
    // same kernel, hence the tolerance (GFS's 2.5-degree field is smooth).
    const double speed = s["wind"]["speed_mps"].get<double>();
    EXPECT_NEAR(ig.weather->horizontalWind_mps, speed, 0.3);
    if (speed > 1) {
      EXPECT_LT(angleBetween_deg(ig.weather->windDirection_deg, s["wind"]["from_deg"].get<double>()), 3);
    }
    if (i == 0) boundaryWind = speed;
    std::printf("[conditions] %-28s IG humidity %3d visibility %8.1f m wind %5.2f m/s from %5.1f | server density "
                "%.4f layer %s wind %5.2f from %5.1f\n",
                p.what, ig.weather->humidity_pct, ig.weather->visibility_m, ig.weather->horizontalWind_mps,
                ig.weather->windDirection_deg, density, s["layer_id"].dump().c_str(), speed,
                s["wind"]["from_deg"].get<double>());
  }
  EXPECT_GE(cloudy, 3) << "GFS has boundary-layer, low, middle and high cloud over 46.2 N 12.8 E on 2011-01-15 12Z";
  // The forecast's layers have no wind of their own: the boundary layer's is GFS's 10 m wind.
  EXPECT_GT(boundaryWind, 0.5);
  EXPECT_EQ(render.stop(), 0) << render.log();
  EXPECT_EQ(w.process->stop(), 0) << w.process->log();
}

// A METAR's fog reaches the renderer through the stream (a station region's
// fog layer, its density in the tiles' 8 bits): the CIGI answer at a pilot's
// eye over the station gives the reported visibility, as the server's point
// query does (within WMO-No. 8's uncertainty, 20 % above 1500 m, which
// covers the 8 bits), and 20 m above the mist's top the clear air's.
TEST(CigiConditions, TheRendererAnswersAMetarsVisibility) {
  const fs::path dir = fs::path(SKY_TEST_OUTPUT_DIR) / "conditions-fog";
  fs::remove_all(dir);
  fs::create_directories(dir);
  Weatherd w("conditions-fog-weatherd", SKY_SCENARIO_CLEAR);
  ASSERT_GT(w.httpPort, 0u) << w.process->log();
  const auto applied = w.request("POST", "/api/metar", R"({"apply": true, "reports": [
      "METAR LIPA 221150Z 00000KT 0400 FG VV002 05/05 Q1025", "METAR LIPH 221150Z 24004KT 2500 BR SCT015 08/07 Q1021",
      "METAR LIPQ 221150Z 20008KT 3000 +RA BKN010 OVC030 10/09 Q1005"],
    "stations": [{"icao": "LIPA", "lat_deg": 46.0319, "lon_deg": 12.5965, "elevation_m": 125},
                 {"icao": "LIPH", "lat_deg": 45.6484, "lon_deg": 12.1944, "elevation_m": 18},
                 {"icao": "LIPQ", "lat_deg": 45.8275, "lon_deg": 13.4722, "elevation_m": 12}]})");
  ASSERT_EQ(applied.status, 200) << applied.body;
  ChildProcess render = startRenderer(dir, w.streamPort);
  const unsigned cigiPort = waitForPortFile((dir / "render.port").string(), 120s);
  ASSERT_GT(cigiPort, 0u) << render.log();
  CigiHost host;
  host.ownshipLat_deg = 45.85;
  host.ownshipLon_deg = 12.4;
  ASSERT_TRUE(waitForSnapshot(render, host, cigiPort, [](int layers, int count) { return layers >= 2 && count > 0; }))
      << "no snapshot with the stations' tiles:\n" << render.log();
  struct Case {
    Point p;
    double visibility_m;  // 0: clear air (the renderer's, kClearVisibility_m)
  };
  const Case cases[] = {
      {{"LIPA, fog", 46.0319, 12.5965, 125 + 2}, 400},
      {{"LIPH, mist", 45.6484, 12.1944, 18 + 2}, 2500},
      // Heavy rain under a broken deck and the mist the rain leaves of 3 km.
      {{"LIPQ, rain", 45.8275, 13.4722, 12 + 2}, 3000},
      {{"above LIPH's mist", 45.6484, 12.1944, 18 + 300 + 300 * 0.1 + 20}, 0},
  };
  for (std::size_t i = 0; i < std::size(cases); ++i) {
    const Case& c = cases[i];
    const IgAnswer ig = ask(host, cigiPort, static_cast<std::uint8_t>(60 + i), c.p);
    ASSERT_TRUE(ig.weather) << c.p.what;
    char target[160];
    std::snprintf(target, sizeof target, "/api/conditions?lat_deg=%.6f&lon_deg=%.6f&alt_m=%.3f", c.p.lat_deg,
                  c.p.lon_deg, c.p.alt_m);
    const auto s = nlohmann::json::parse(w.request("GET", target, "", "").body);
    SCOPED_TRACE(std::string(c.p.what) + ": server " + s.dump());
    if (c.visibility_m == 0) {
      EXPECT_EQ(ig.weather->visibility_m, kClearVisibility_m);
      EXPECT_TRUE(s["visibility_m"].is_null());
    } else {
      const double tolerance = c.visibility_m <= 600 ? 50 : 0.2 * c.visibility_m;
      EXPECT_NEAR(ig.weather->visibility_m, c.visibility_m, tolerance);
      EXPECT_NEAR(s["visibility_m"].get<double>(), ig.weather->visibility_m, 1e-3 * c.visibility_m);
      EXPECT_EQ(ig.weather->humidity_pct, 100);
    }
    if (std::string_view(c.p.what).starts_with("LIPQ")) {
      // The rain itself: heavy (15 mm/h) over the deck's 6/8, so its mean
      // over the tile is 0.75^(1/0.63) of it (the extinction is averaged),
      // within the 8 bits' 12 %.
      ASSERT_FALSE(s["precipitation"].is_null());
      EXPECT_EQ(s["precipitation"]["type"], "rain");
      EXPECT_NEAR(s["precipitation"]["rate_mmph"].get<double>(), 15 * std::pow(0.75, 1 / 0.63), 0.12 * 9.5);
    } else {
      EXPECT_TRUE(s["precipitation"].is_null());
    }
    std::printf("[conditions] %-20s reported %6.0f m, CIGI answer %8.1f m, server %s\n", c.p.what, c.visibility_m,
                ig.weather->visibility_m, s["visibility_m"].dump().c_str());
  }
  EXPECT_EQ(render.stop(), 0) << render.log();
  EXPECT_EQ(w.process->stop(), 0) << w.process->log();
}

// NAM's temperature and humidity (air tiles) reach the renderer through the
// stream: its CIGI answers over Kansas carry the forecast's air at the
// point, as the server's point query does, from the ground to the jet
// stream, where without a forecast both answer the standard atmosphere.
TEST(CigiConditions, TheRendererAnswersTheForecastsTemperatureAndHumidity) {
  const fs::path dir = fs::path(SKY_TEST_OUTPUT_DIR) / "conditions-air";
  fs::remove_all(dir);
  fs::create_directories(dir);
  Weatherd w("conditions-air-weatherd", SKY_SCENARIO_CLEAR, false,
             {"--grib", std::string(SKY_TEST_DATA_DIR) + "/grib/nam212-lambert-2004120812-f24.grib2"});
  ASSERT_GT(w.httpPort, 0u) << w.process->log();
  ChildProcess render = startRenderer(dir, w.streamPort);
  const unsigned cigiPort = waitForPortFile((dir / "render.port").string(), 120s);
  ASSERT_GT(cigiPort, 0u) << render.log();
  CigiHost host;
  host.ownshipLat_deg = 38.0;
  host.ownshipLon_deg = -97.0;
  // The scenario's layer and NAM's three (no cover tiles: NAM has no cloud
  // over Kansas at this hour, so its layers are uniform there).
  const bool layers = waitForSnapshot(render, host, cigiPort, [](int n, int) { return n >= 4; });
  ASSERT_TRUE(layers) << "no snapshot with the forecast's layers:\n" << render.log();
  const Point points[] = {
      {"near the ground", 38.0, -97.0, 400},      {"at 850 hPa", 38.05, -97.1, 1457},
      {"between 700 and 500 hPa", 37.9, -96.9, 4300}, {"in the jet stream's level", 38.0, -97.0, 10400},
  };
  double lowest = 1e9, highest = -1e9;
  for (std::size_t i = 0; i < std::size(points); ++i) {
    const Point& p = points[i];
    const IgAnswer ig = ask(host, cigiPort, static_cast<std::uint8_t>(60 + i), p);
    char target[160];
    std::snprintf(target, sizeof target, "/api/conditions?lat_deg=%.9f&lon_deg=%.9f&alt_m=%.3f", p.lat_deg, p.lon_deg,
                  p.alt_m);
    const auto s = nlohmann::json::parse(w.request("GET", target, "", "").body);
    ASSERT_TRUE(ig.weather) << p.what;
    SCOPED_TRACE(std::string(p.what) + ": server " + s.dump());
    EXPECT_EQ(s["air_from"], "forecast");
    const double t = s["air_temperature_c"].get<double>();
    // The renderer's area and the server's point query hold air tiles of
    // different S2 levels, each smoothed by the same kernel, hence the
    // tolerance; the standard atmosphere differs by several kelvin here.
    EXPECT_NEAR(ig.weather->airTemperature_c, t, 0.6);
    if (s["cloud_density"].get<double>() == 0 && !s["humidity_pct"].is_null()) {
      EXPECT_NEAR(ig.weather->humidity_pct, s["humidity_pct"].get<double>(), 3.0);
    }
    lowest = std::min(lowest, t);
    highest = std::max(highest, t);
    std::printf("[conditions] %-26s IG %6.2f C humidity %3d %% | server %6.2f C humidity %s | ISA %6.2f C\n", p.what,
                ig.weather->airTemperature_c, ig.weather->humidity_pct, t, s["humidity_pct"].dump().c_str(),
                weather::isaTemperature_c(p.alt_m));
  }
  EXPECT_GT(highest - lowest, 40.0) << "from the ground to 10 km the air cools by tens of kelvin";
  EXPECT_EQ(render.stop(), 0) << render.log();
  EXPECT_EQ(w.process->stop(), 0) << w.process->log();
}

}  // namespace
}  // namespace sky::test
