// Weather stream client (see weather_client.hpp).
#include "sky/app/weather_client.hpp"

#include <unistd.h>

#include <algorithm>
#include <cmath>

#include <spdlog/spdlog.h>

#include "sky/core/overloaded.hpp"
#include "sky/flight/utf8_text.hpp"

namespace sky::app {

namespace asio = boost::asio;
using Clock = std::chrono::steady_clock;

namespace {
// Reconnect backoff grows to this cap: short enough that a restarted server
// is picked up within seconds, long enough not to spin on a dead one.
constexpr std::chrono::milliseconds kMaxBackoff{2000};
// A server's id and error text are logged up to this many bytes, ill-formed
// UTF-8 and control characters replaced: the stream does not check them.
constexpr std::size_t kMaxEchoedServerText = 200;

std::string defaultChannel() {
  char name[256] = {};
  if (::gethostname(name, sizeof name - 1) != 0) return "render";
  return std::string("render@") + name;
}

// At most `max` bytes, cut at a UTF-8 character boundary.
std::string cutUtf8(std::string s, std::size_t max) {
  if (s.size() <= max) return s;
  std::size_t n = max;
  while (n > 0 && (static_cast<unsigned char>(s[n]) & 0xc0) == 0x80) --n;
  s.resize(n);
  return s;
}

// A server without kFeatureTileDrift leaves Layer.tiles_drift unset and
// meant every layer's tiles to move with the wind.
void allTilesDrift(std::vector<weather::CloudLayer>& layers) {
  for (weather::CloudLayer& l : layers) l.tilesDrift = true;
}

}  // namespace

WeatherClient::WeatherClient(asio::io_context& io, SharedState& state, std::string host, unsigned short port,
                             std::string channel)
    : io_(io),
      state_(state),
      host_(std::move(host)),
      port_(port),
      socket_(io),
      retryTimer_(io),
      channel_(cutUtf8(channel.empty() ? defaultChannel() : std::move(channel), stream::kMaxChannelBytes)) {}

void WeatherClient::start() {
  asio::post(io_, [this] { connect(); });
}

void WeatherClient::stop() {
  asio::post(io_, [this] {
    stopped_ = true;
    retryTimer_.cancel();
    boost::system::error_code ec;
    socket_.close(ec);
  });
}

void WeatherClient::subscribe(const stream::Subscribe& area) {
  asio::post(io_, [this, area] {
    if (area.areaIndex >= areas_.size()) return;
    areas_[area.areaIndex] = area;
    if (socket_.is_open() && (area.areaIndex == 0 || serverTakesAreas_)) send(area);
  });
}

void WeatherClient::connect() {
  if (stopped_) return;
  boost::system::error_code ec;
  const auto address = asio::ip::make_address(host_, ec);
  if (ec) {
    spdlog::error("weather server address '{}' is not an IP address", host_);
    return;
  }
  socket_ = asio::ip::tcp::socket(io_);
  socket_.async_connect({address, port_}, [this](boost::system::error_code e) {
    if (e) {
      scheduleReconnect();
      return;
    }
    spdlog::info("connected to weather server {}:{}", host_, port_);
    backoff_ = std::chrono::milliseconds(250);
    decoder_ = stream::FrameDecoder();
    inFlight_.clear();
    for (auto& p : pendingSubscribe_) p.reset();
    pendingReport_.reset();
    serverTakesReports_ = false;  // until this server's Hello says so
    serverTakesAreas_ = false;
    state_.setConnected(true);
    // The detailed area at once; the others once the Hello says they are taken.
    if (areas_[0]) send(*areas_[0]);
    read();
  });
}

void WeatherClient::scheduleReconnect() {
  serverTakesReports_ = false;
  serverTakesAreas_ = false;
  serverTakesHostClock_ = false;
  serverTakesLightningRequests_ = false;
  if (stopped_) return;
  state_.setConnected(false);
  boost::system::error_code ec;
  socket_.close(ec);
  retryTimer_.expires_after(backoff_);
  backoff_ = std::min(backoff_ * 2, kMaxBackoff);
  retryTimer_.async_wait([this](boost::system::error_code e) {
    if (!e) connect();
  });
}

void WeatherClient::read() {
  socket_.async_read_some(asio::buffer(rx_), [this](boost::system::error_code ec, std::size_t n) {
    if (ec) {
      if (!stopped_) spdlog::warn("weather server connection lost: {}", ec.message());
      scheduleReconnect();
      return;
    }
    decoder_.append(std::span(rx_.data(), n));
    while (true) {
      auto frame = decoder_.next();
      if (!frame) {
        ++malformed_;
        spdlog::error("weather stream: {}; reconnecting", describe(frame.error()));
        scheduleReconnect();
        return;
      }
      if (!*frame) break;
      onFrame(**frame);
    }
    read();
  });
}

void WeatherClient::onFrame(std::span<const std::uint8_t> payload) {
  auto message = stream::decodeMessage(payload);
  if (!message) {
    ++malformed_;
    spdlog::warn("weather stream: dropped a frame: {}", describe(message.error()));
    return;
  }
  const auto now = Clock::now();
  std::visit(Overloaded{
                 [&](const stream::Hello& h) {
                   clockRate_ = h.clockRate;
                   state_.setClock(h.weatherClock_s, h.clockRate, now);
                   const bool reports = (h.features & stream::kFeatureCameraReports) != 0;
                   serverTakesReports_ = reports;
                   reportNow_ = reports;
                   const bool areas = (h.features & stream::kFeatureAreas) != 0;
                   serverTakesAreas_ = areas;
                   // A server that restarted holds no host's clock: every
                   // channel proposes again, and the first one wins for all.
                   state_.setHostClock(std::nullopt);
                   serverTakesHostClock_ = (h.features & stream::kFeatureHostClock) != 0;
                   serverMarksTileDrift_ = (h.features & stream::kFeatureTileDrift) != 0;
                   serverTakesLightningRequests_ = (h.features & stream::kFeatureLightningRequests) != 0;
                   spdlog::info("weather server '{}' protocol {} clock {:.1f} s x{}{}{}",
                                flight::messageText(h.serverId, kMaxEchoedServerText),
                                h.protocolVersion, h.weatherClock_s, h.clockRate,
                                reports ? "; reporting the camera as '" + channel_ + "'" : "",
                                areas ? "" : "; it takes one area only: the coarse ring holds what the detailed area brings");
                   if (areas) {
                     for (std::size_t i = 1; i < areas_.size(); ++i)
                       if (areas_[i]) send(*areas_[i]);
                   } else {
                     state_.dropCoarse();
                   }
                 },
                 [&](const weather::WeatherSnapshot& s) {
                   spdlog::info("weather snapshot of area {}: {} layers, {} tiles at S2 level {}", s.areaIndex,
                                s.layers.size(), s.tiles.size(), s.tileLevel);
                   if (serverMarksTileDrift_) {
                     state_.setSnapshot(s, now);
                   } else {
                     weather::WeatherSnapshot drifting = s;
                     allTilesDrift(drifting.layers);
                     state_.setSnapshot(drifting, now);
                   }
                 },
                 [&](const weather::WeatherDelta& delta) {
                   weather::WeatherDelta drifting;
                   if (!serverMarksTileDrift_) {
                     drifting = delta;
                     allTilesDrift(drifting.layers);
                   }
                   const weather::WeatherDelta& d = serverMarksTileDrift_ ? delta : drifting;
                   if (auto r = state_.applyDelta(d, now); !r) {
                     ++malformed_;
                     spdlog::warn("weather stream: dropped a Delta: {}; asking for a new Snapshot", r.error().detail);
                     if (d.areaIndex < areas_.size() && areas_[d.areaIndex]) send(*areas_[d.areaIndex]);
                   }
                 },
                 [&](const stream::Heartbeat& h) { state_.setClock(h.weatherClock_s, clockRate_, now); },
                 [&](const stream::StreamError& e) {
                   spdlog::warn("weather server error {}: {}", e.code,
                                flight::messageText(e.detail, kMaxEchoedServerText));
                 },
                 [&](const stream::Subscribe&) {
                   ++malformed_;
                   spdlog::warn("weather stream: a server must not send Subscribe; dropped");
                 },
                 [&](const stream::CameraReport&) {
                   ++malformed_;
                   spdlog::warn("weather stream: a server must not send CameraReport; dropped");
                 },
                 [&](const stream::Lightning& l) {
                   if (onlyAskedFlashes_ && serverTakesLightningRequests_ && !l.answersTo_s) return;
                   // An answer is at the asker's clock, which may be far from
                   // the server's: its flashes are kept by that clock.
                   state_.addFlashes(l.flashes, l.answersTo_s.value_or(l.weatherClock_s));
                   if (l.answersTo_s) state_.setLightningAnsweredTo(*l.answersTo_s);
                 },
                 [&](const stream::LightningRequest&) {
                   ++malformed_;
                   spdlog::warn("weather stream: a server must not send LightningRequest; dropped");
                 },
                 [&](const stream::HostClock& c) { state_.setHostClock(c); },
                 [&](const stream::UnknownKind&) {
                   // A newer server of our major version: ignore what we do not know.
                 }},
             *message);
}

void WeatherClient::reportCamera(const geo::GeodeticPose& pose, std::uint64_t frame, std::uint64_t weatherVersion,
                                 double weatherClock_s) {
  if (!serverTakesReports_) return;
  stream::CameraReport r;
  r.channel = channel_;
  // Into the ranges the stream checks: a pose from a host may carry any
  // longitude or heading, and a report out of range would close the stream.
  r.lat_deg = std::clamp(pose.position.lat_deg, -90.0, 90.0);
  r.lon_deg = geo::normalizeLon_deg(pose.position.lon_deg);
  r.alt_m = std::clamp(pose.position.alt_m, -1000.0, 1.0e6);
  r.heading_deg = std::fmod(geo::normalizeLon_deg(pose.yaw_deg) + 360.0, 360.0);
  r.pitch_deg = std::clamp(pose.pitch_deg, -90.0, 90.0);
  r.roll_deg = geo::normalizeLon_deg(pose.roll_deg);
  r.frame = frame;
  r.weatherVersion = weatherVersion;
  r.weatherClock_s = weatherClock_s;
  for (double v : {r.lat_deg, r.lon_deg, r.alt_m, r.heading_deg, r.pitch_deg, r.roll_deg, r.weatherClock_s})
    if (!std::isfinite(v)) return;
  if (!reportWorthSending(r, Clock::now())) return;
  asio::post(io_, [this, r = std::move(r)] {
    if (!socket_.is_open() || !serverTakesReports_) return;
    send(r);
    ++reportsSent_;
  });
}

void WeatherClient::proposeHostClock(const stream::HostClock& proposal) {
  if (!serverTakesHostClock_) return;
  asio::post(io_, [this, proposal] {
    if (socket_.is_open() && serverTakesHostClock_) send(proposal);
  });
}

void WeatherClient::requestLightning(double from_s, double to_s) {
  if (!serverTakesLightningRequests_) return;
  const stream::LightningRequest request{from_s, to_s};
  asio::post(io_, [this, request] {
    if (socket_.is_open() && serverTakesLightningRequests_) send(request);
  });
}

bool WeatherClient::reportWorthSending(const stream::CameraReport& r, Clock::time_point now) {
  std::lock_guard lock(reportMutex_);
  const bool forced = reportNow_.exchange(false);
  if (lastReport_ && !forced) {
    const auto since = now - lastReportAt_;
    if (since < kMinReportInterval) return false;
    const stream::CameraReport& last = *lastReport_;
    const bool moved =
        geo::geodesicDistance_m(last.lat_deg, last.lon_deg, r.lat_deg, r.lon_deg) > kReportMove_m ||
        std::abs(r.alt_m - last.alt_m) > kReportMove_m ||
        std::abs(geo::angleDiff_deg(last.heading_deg, r.heading_deg)) > kReportTurn_deg ||
        std::abs(r.pitch_deg - last.pitch_deg) > kReportTurn_deg ||
        std::abs(geo::angleDiff_deg(last.roll_deg, r.roll_deg)) > kReportTurn_deg;
    if (!moved && r.weatherVersion == last.weatherVersion && since < kReportKeepAlive) return false;
  }
  lastReport_ = r;
  lastReportAt_ = now;
  return true;
}

void WeatherClient::send(const stream::Message& message) {
  auto bytes = stream::encodeFrame(stream::encodeMessage(message));
  if (!inFlight_.empty()) {
    // Coalesce: only the newest request of each area and the newest report matter.
    if (const auto* sub = std::get_if<stream::Subscribe>(&message))
      pendingSubscribe_[sub->areaIndex] = std::move(bytes);
    else if (std::holds_alternative<stream::HostClock>(message))
      pendingHostClock_ = std::move(bytes);
    else if (std::holds_alternative<stream::LightningRequest>(message))
      pendingLightning_ = std::move(bytes);
    else
      pendingReport_ = std::move(bytes);
    return;
  }
  inFlight_ = std::move(bytes);
  flushWrite();
}

void WeatherClient::flushWrite() {
  asio::async_write(socket_, asio::buffer(inFlight_), [this](boost::system::error_code ec, std::size_t) {
    inFlight_.clear();
    if (ec) return;  // the read side notices and reconnects
    static_assert(stream::kMaxAreas == 2, "one pending Subscribe per area");
    for (auto* pending :
         {&pendingSubscribe_[0], &pendingSubscribe_[1], &pendingHostClock_, &pendingLightning_, &pendingReport_}) {
      if (!*pending) continue;
      inFlight_ = std::move(**pending);
      pending->reset();
      flushWrite();
      return;
    }
  });
}

}  // namespace sky::app
