// CIGI UDP endpoint of a renderer channel (see cigi_listener.hpp).
#include "sky/app/cigi_listener.hpp"

#include <algorithm>
#include <charconv>
#include <cmath>

#include "sky/cigi/celestial_time.hpp"
#include "sky/cigi/precipitation_layers.hpp"
#include "sky/render/haze.hpp"
#include "sky/weather/air_field.hpp"
#include "sky/weather/precipitation.hpp"
#include "sky/weather/query.hpp"

#include <spdlog/spdlog.h>

namespace sky::app {

namespace asio = boost::asio;

namespace {

// The ownship the areas of interest follow, when a pose has come.
std::optional<geo::Geodetic> ownship(const SharedState& state) {
  const auto pose = state.pose();
  if (!pose) return std::nullopt;
  return pose->pose.position;
}
}  // namespace

Result<CigiHost> parseCigiHost(std::string_view text) {
  std::string_view addressText = text, portText;
  if (!text.empty() && text.front() == '[') {
    const auto close = text.find(']');
    if (close == std::string_view::npos)
      return fail(ErrorCode::InvalidArgument, "--cigi-host: '[' without ']' (IPv6 is written [ADDR]:PORT)");
    addressText = text.substr(1, close - 1);
    const std::string_view rest = text.substr(close + 1);
    if (!rest.empty()) {
      if (rest.front() != ':')
        return fail(ErrorCode::InvalidArgument, "--cigi-host: after ']' only ':PORT' may follow");
      portText = rest.substr(1);
      if (portText.empty()) return fail(ErrorCode::InvalidArgument, "--cigi-host: ':' without a port");
    }
  } else if (const auto colon = text.find(':');
             colon != std::string_view::npos && text.find(':', colon + 1) == std::string_view::npos) {
    // One colon: IPv4 ADDR:PORT. More than one: a bare IPv6 address.
    addressText = text.substr(0, colon);
    portText = text.substr(colon + 1);
    if (portText.empty()) return fail(ErrorCode::InvalidArgument, "--cigi-host: ':' without a port");
  }
  CigiHost host;
  boost::system::error_code ec;
  host.address = asio::ip::make_address(std::string(addressText), ec);
  if (ec) return fail(ErrorCode::InvalidArgument, "--cigi-host: the address is not an IPv4 or IPv6 address");
  if (!portText.empty()) {
    unsigned port = 0;
    const auto [end, pec] = std::from_chars(portText.data(), portText.data() + portText.size(), port);
    if (pec != std::errc() || end != portText.data() + portText.size() || port == 0 || port > 65535)
      return fail(ErrorCode::InvalidArgument, "--cigi-host: the port is not in 1..65535");
    host.port = static_cast<unsigned short>(port);
  }
  return host;
}

CigiListener::CigiListener(asio::io_context& io, SharedState& state, const std::string& address,
                           unsigned short port, std::optional<CigiHost> host)
    : socket_(io), state_(state), host_(std::move(host)) {
  const asio::ip::udp::endpoint ep(asio::ip::make_address(address), port);
  socket_.open(ep.protocol());
  socket_.bind(ep);
  port_ = socket_.local_endpoint().port();
}

void CigiListener::start() { receive(); }

void CigiListener::stop() {
  boost::system::error_code ec;
  socket_.close(ec);
}

std::optional<CigiHost> CigiListener::host() const {
  std::lock_guard lock(hostMutex_);
  return host_;
}

void CigiListener::receive() {
  socket_.async_receive_from(asio::buffer(rx_), from_, [this](boost::system::error_code ec, std::size_t n) {
    if (ec == asio::error::operation_aborted) return;
    if (!ec) {
      const auto reply = handleDatagram(std::span(rx_.data(), n), from_);
      boost::system::error_code sendError;
      if (!reply.empty()) socket_.send_to(asio::buffer(reply), from_, 0, sendError);
    }
    receive();
  });
}

void CigiListener::ignore(std::uint8_t id) {
  ignored_.add(id);
  if (loggedIgnored_.insert(id).second)
    spdlog::info("CIGI: ignoring {} (id {}) packets: accepted, not used, counted", cigi::packetIdName(id), id);
}

std::string CigiListener::ignoredSummary() const {
  std::string out;
  for (unsigned id = 0; id < 256; ++id) {
    const std::uint64_t n = ignored_.of(static_cast<std::uint8_t>(id));
    if (n == 0) continue;
    if (!out.empty()) out += ", ";
    out += std::string(cigi::packetIdName(static_cast<std::uint8_t>(id))) + " (" + std::to_string(id) + ") " +
           std::to_string(n);
  }
  return out.empty() ? "none" : out;
}

void CigiListener::dropped(DropReason reason, const std::string& detail) {
  drops_.add(reason);
  if (loggedReasons_.insert(dropKind(reason, detail)).second)
    spdlog::warn("CIGI: dropped a datagram ({}): {} (further drops of this kind are only counted)",
                 toString(reason), detail);
}

std::vector<std::uint8_t> CigiListener::handleDatagram(std::span<const std::uint8_t> bytes,
                                                       const asio::ip::udp::endpoint& from) {
  // Senders other than the host are dropped before their bytes are looked
  // at, and never answered: the port is no reflector.
  std::optional<CigiHost> host = this->host();
  if (host && !host->matches(from)) {
    dropped(DropReason::ForeignSender, "from " + from.address().to_string() + " (port " +
                                           std::to_string(from.port()) + "), not the host this port answers");
    return {};
  }
  auto datagram = cigi::decodeDatagram(bytes);
  if (!datagram) {
    dropped(dropReasonOf(datagram.error().code), datagram.error().detail);
    return {};
  }
  const auto* ig = std::get_if<cigi::IgControl>(&datagram->packets.front());
  if (!ig) {
    dropped(DropReason::NotFromHost, "datagram starts with Start of Frame: an IG accepts host datagrams only");
    return {};
  }
  if (!host) {
    std::lock_guard lock(hostMutex_);
    // The address only: a host that restarts comes back on a new ephemeral
    // port and must be answered again; --cigi-host ADDR:PORT pins a port.
    host_ = CigiHost{from.address(), std::nullopt};
    spdlog::info("CIGI: answering host {} (the first valid datagram's sender, any port); other senders are dropped",
                 from.address().to_string());
  }
  ++accepted_;
  const auto now = std::chrono::steady_clock::now();
  // The channels one host drives share its clock (host_locked_clock.hpp) by
  // the address they all see it at.
  const std::string hostKey = from.address().to_string();
  clock_.advanceTo(timeline_.advance(ig->timestampValid, ig->timestamp_10us, now));
  // Reset/Standby forgets the pose once, on entry; no pose is taken while in it.
  const bool standby = ig->mode == cigi::IgMode::ResetStandby;
  if (standby && !standby_.load()) {
    state_.resetChannel();
    spdlog::info("CIGI: the host put the IG in Reset/Standby: pose and temporal history forgotten");
  }
  standby_ = standby;
  for (const std::uint8_t id : datagram->skippedIds) ignore(id);
  // Time and atmosphere first: the ownship pose of this datagram carries them.
  for (const auto& packet : datagram->packets) {
    if (const auto* c = std::get_if<cigi::CelestialSphereControl>(&packet)) {
      // The decoder passed only calendar dates; a date the host marks
      // invalid changes nothing.
      if (const auto minute = cigi::celestialUtc(*c); c->dateTimeValid && minute)
        clock_.set(double(*minute), 60.0, TimeSource::Cigi);
    } else if (const auto* a = std::get_if<cigi::AtmosphereControl>(&packet)) {
      state_.setAtmosphere(atmosphereFrom(*a));
    } else if (const auto* definition = std::get_if<cigi::ViewDefinition>(&packet)) {
      takeView(*definition, "View Definition");
    } else if (const auto* control = std::get_if<cigi::ViewControl>(&packet)) {
      takeView(*control, "View Control");
    } else if (const auto* exposure = std::get_if<cigi::CameraExposureControl>(&packet)) {
      takeExposure(*exposure);
    }
  }
  for (std::size_t i = 1; i < datagram->packets.size(); ++i) {
    const auto& packet = datagram->packets[i];
    const auto* entity = std::get_if<cigi::EntityControl>(&packet);
    if (!entity) {
      if (!std::holds_alternative<cigi::CelestialSphereControl>(packet) &&
          !std::holds_alternative<cigi::AtmosphereControl>(packet) &&
          !std::holds_alternative<cigi::ViewDefinition>(packet) && !std::holds_alternative<cigi::ViewControl>(packet) &&
          !std::holds_alternative<cigi::CameraExposureControl>(packet) &&
          !std::holds_alternative<cigi::EnvironmentalConditionsRequest>(packet))
        ignore(cigi::packetId(packet));
      continue;
    }
    if (entity->entityId != 0 || entity->attached || standby) {
      ignore(cigi::EntityControl::kId);
      continue;
    }
    HostPose p;
    p.pose.position = {entity->lat_deg, entity->lon_deg, entity->alt_m};
    p.pose.yaw_deg = entity->yaw_deg;
    p.pose.pitch_deg = entity->pitch_deg;
    p.pose.roll_deg = entity->roll_deg;
    p.hostFrame = ig->hostFrame;
    p.hostTime_s = ig->timestampValid ? ig->timestamp_10us * 1.0e-5 : 0.0;
    p.hostTimeValid = ig->timestampValid;
    p.host = hostKey;
    p.receivedAt = now;
    p.utc_s = clock_.utc_s();
    p.timeSource = clock_.source();
    state_.setPose(p);
  }
  // Environmental Conditions Requests, answered with Start of Frame from the
  // weather this channel holds, by the query every process shares.
  std::vector<cigi::Packet> replies;
  std::optional<ConditionsSource> source;  // once per datagram, when it asks
  for (const auto& packet : datagram->packets)
    if (const auto* request = std::get_if<cigi::EnvironmentalConditionsRequest>(&packet)) {
      if (!source) source.emplace(state_.weather(), now);
      for (auto& reply : answerConditions(*request, *source, ownship(state_), state_.atmosphere()))
        replies.push_back(std::move(reply));
    }
  if (synchronous_ && !standby) {
    pendingReplies_ = std::move(replies);
    syncHost_ = from;
    return {};
  }
  return startOfFrame(ig->hostFrame, standby, replies);
}

std::vector<std::uint8_t> CigiListener::startOfFrame(std::uint32_t lastHostFrame, bool standby,
                                                     const std::vector<cigi::Packet>& replies) {
  cigi::StartOfFrame sof;
  sof.mode = standby ? cigi::IgMode::ResetStandby : cigi::IgMode::Operate;
  sof.igFrame = igFrame_++;
  sof.lastHostFrame = lastHostFrame;
  cigi::DatagramWriter w;
  w.add(sof);
  for (const auto& reply : replies) w.add(reply);
  return w.bytes();
}

void CigiListener::frameDrawn(std::uint32_t hostFrame) {
  asio::post(socket_.get_executor(), [this, hostFrame] {
    if (!syncHost_ || !socket_.is_open()) return;
    const auto bytes = startOfFrame(hostFrame, standby_.load(), pendingReplies_);
    pendingReplies_.clear();
    boost::system::error_code ec;
    socket_.send_to(asio::buffer(bytes), *syncHost_, 0, ec);
  });
}

template <class ViewPacket>
void CigiListener::takeView(const ViewPacket& packet, const char* name) {
  const ViewUpdate u = state_.applyView(packet);
  switch (u.outcome) {
    case ViewPacketOutcome::OtherView: otherViewPackets_.fetch_add(1, std::memory_order_relaxed); return;
    case ViewPacketOutcome::Rejected:
      // The packet only: the rest of its datagram (the pose) still counts.
      drops_.add(DropReason::OutOfRange);
      if (loggedReasons_.insert(dropKind(DropReason::OutOfRange, u.detail)).second)
        spdlog::warn("CIGI: ignored a {} ({}) (further ones of this kind are only counted)", name, u.detail);
      return;
    case ViewPacketOutcome::Applied:
      for (const auto& part : u.unsupported) {
        unsupportedViewParts_.fetch_add(1, std::memory_order_relaxed);
        if (loggedReasons_.insert("view: " + part).second)
          spdlog::warn("CIGI: {} for this channel's view asks for {}: not supported, counted", name, part);
      }
      return;
  }
}

void CigiListener::takeExposure(const cigi::CameraExposureControl& e) {
  // The decoder checked every field; what is left is whose view it is.
  if (e.viewId != cigi::CameraExposureControl::kAllViews && e.viewId != state_.view().viewId) {
    otherViewPackets_.fetch_add(1, std::memory_order_relaxed);
    otherViewExposures_.fetch_add(1, std::memory_order_relaxed);
    return;
  }
  state_.setHostExposure(e);
  hostExposures_.fetch_add(1, std::memory_order_relaxed);
  // A host may send its setting with every frame: said when it changes.
  if (loggedExposure_ != e) {
    loggedExposure_ = e;
    if (e.mode == cigi::ExposureMode::Fixed)
      spdlog::info("CIGI: the host fixed the camera exposure at EV100 {:.2f}, compensation {:+.2f} EV", e.ev100,
                   e.compensation_ev);
    else
      spdlog::info("CIGI: the host gave the camera exposure to the meter, compensation {:+.2f} EV", e.compensation_ev);
  }
}

ConditionsSource::ConditionsSource(WeatherView v, std::chrono::steady_clock::time_point now)
    : view(std::move(v)),
      tiles(weather::snapshotLookup(view.snapshot, view.clockNow(now))),
      coarseTiles(view.coarse ? weather::snapshotLookup(*view.coarse, view.clockNow(now)) : tiles),
      wind(weather::snapshotWindLookup(view.snapshot)),
      coarseWind(view.coarse ? weather::snapshotWindLookup(*view.coarse) : wind),
      air(view.snapshot),
      coarseAir(view.coarse ? weather::AirField(*view.coarse) : air) {}

std::vector<cigi::Packet> answerConditions(const cigi::EnvironmentalConditionsRequest& r, const WeatherView& view,
                                          std::chrono::steady_clock::time_point now,
                                          const std::optional<geo::Geodetic>& camera, const HostAtmosphere& air) {
  return answerConditions(r, ConditionsSource(view, now), camera, air);
}

std::vector<cigi::Packet> answerConditions(const cigi::EnvironmentalConditionsRequest& r,
                                          const ConditionsSource& source, const std::optional<geo::Geodetic>& camera,
                                          const HostAtmosphere& air) {
  const WeatherView& view = source.view;
  std::vector<cigi::Packet> out;
  // The layers are the same in both areas' snapshots; the tiles and the wind
  // tiles come from the area that reaches the point.
  const auto& layers = view.snapshot.layers;
  const bool far = view.coarse && camera &&
                   geo::geodesicDistance_m(camera->lat_deg, camera->lon_deg, r.lat_deg, r.lon_deg) > kDetailedReach_m;
  const weather::CoverageLookup& lookup = far ? source.coarseTiles : source.tiles;
  if (r.requestType & cigi::kRequestWeather) {
    const weather::PointWeather pw =
        weather::weatherAt(layers, lookup, r.lat_deg, r.lon_deg, r.alt_m, far ? source.coarseWind : source.wind);
    cigi::WeatherConditionsResponse wcr;
    wcr.requestId = r.requestId;
    // A forecast's temperature and humidity where the weather has them (air
    // tiles); elsewhere the ISA's lapse from the host's sea-level temperature.
    const std::optional<weather::AirValues> forecast = (far ? source.coarseAir : source.air).at(r.lat_deg, r.lon_deg, r.alt_m);
    const double humidity = forecast && forecast->humidity_pct >= 0 ? forecast->humidity_pct : air.humidity_pct;
    wcr.humidity_pct = static_cast<std::uint8_t>(pw.cloudDensity > 0 ? 100 : std::lround(std::clamp(humidity, 0.0, 100.0)));
    wcr.airTemperature_c = static_cast<float>(
        forecast ? forecast->temperature_c
                 : weather::isaTemperature_c(r.alt_m) + (air.seaLevelTemperature_c - kIsaSeaLevelTemperature_c));
    // In cloud, fog and precipitation the Koschmieder range of their
    // extinction (the fog and precipitation types draw exactly that), never
    // longer than the clear air's.
    wcr.visibility_m = static_cast<float>(std::min(air.visibility_m, weather::visibilityAt_m(pw)));
    // The weather's layer winds where it has layers; with none (clear sky,
    // no server yet), the host's Atmosphere Control wind when it sent one.
    const bool hostWind = layers.empty() && air.source != AtmosphereSource::Default;
    wcr.horizontalWind_mps = static_cast<float>(hostWind ? air.windSpeed_mps : pw.wind.speed_mps);
    wcr.verticalWind_mps = static_cast<float>(hostWind ? air.verticalWind_mps : pw.wind.vertical_mps);
    wcr.windDirection_deg = static_cast<float>(hostWind ? air.windFrom_deg : pw.wind.fromDirection_deg);
    wcr.pressure_hpa =
        static_cast<float>(weather::isaPressure_hpa(r.alt_m) * air.seaLevelPressure_hpa / kIsaSeaLevelPressure_hpa);
    out.push_back(wcr);
  }
  if (r.requestType & cigi::kRequestAerosol) {
    // CIGI cloud layers 1-3 are our layers of those ids; their liquid water
    // at the point, g/m^3.
    for (const auto& l : layers) {
      if (l.id < 1 || l.id > 3 || weather::isPrecipitation(l.type)) continue;
      const weather::PointWeather one = weather::weatherAt(std::span(&l, 1), lookup, r.lat_deg, r.lon_deg, r.alt_m);
      cigi::AerosolConcentrationResponse a;
      a.requestId = r.requestId;
      a.layerId = static_cast<cigi::LayerId>(l.id);
      a.concentration_gpm3 = static_cast<float>(kCloudLiquidWater_gpm3 * one.cloudDensity);
      out.push_back(a);
    }
    // CIGI's precipitation layers (rain, snow, sleet, hail: 4-7) are our
    // layers of those types, whatever their ids: the water they hold at the
    // point (rate over fall speed), where the weather has one.
    for (const cigi::LayerId id : cigi::kPrecipitationLayerIds) {
      const weather::CloudType type = cigi::precipitationTypeOf(id);
      std::vector<weather::CloudLayer> ofType;
      for (const auto& l : layers)
        if (l.type == type) ofType.push_back(l);
      if (ofType.empty()) continue;
      const weather::PointWeather one = weather::weatherAt(ofType, lookup, r.lat_deg, r.lon_deg, r.alt_m);
      cigi::AerosolConcentrationResponse a;
      a.requestId = r.requestId;
      a.layerId = id;
      a.concentration_gpm3 = static_cast<float>(weather::precipitationWater_gpm3(type, one.precipitationRate_mmph));
      out.push_back(a);
    }
  }
  return out;
}

}  // namespace sky::app
