// CIGI UDP endpoint of a renderer channel (see cigi_listener.hpp).
#include "sky/app/cigi_listener.hpp"

#include <algorithm>

#include "sky/weather/query.hpp"

#include <spdlog/spdlog.h>

namespace sky::app {

namespace asio = boost::asio;

namespace {
// The part of an error detail before the first digit-bearing position
// ("packet 1 (Entity Control) at byte 24: latitude 95 outside ...") becomes
// the kind we log once: the packet name and field, not the values.
std::string reasonKind(const std::string& detail) {
  std::string kind;
  for (char c : detail) {
    if (c >= '0' && c <= '9') continue;
    kind += c;
  }
  return kind.substr(0, 80);
}

// The ownship the areas of interest follow, when a pose has come.
std::optional<geo::Geodetic> ownship(const SharedState& state) {
  const auto pose = state.pose();
  if (!pose) return std::nullopt;
  return pose->pose.position;
}
}  // namespace

CigiListener::CigiListener(asio::io_context& io, SharedState& state, const std::string& address,
                           unsigned short port)
    : socket_(io), state_(state) {
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

void CigiListener::receive() {
  socket_.async_receive_from(asio::buffer(rx_), from_, [this](boost::system::error_code ec, std::size_t n) {
    if (ec == asio::error::operation_aborted) return;
    if (!ec) onDatagram(std::span(rx_.data(), n));
    receive();
  });
}

void CigiListener::dropped(const std::string& reason) {
  ++dropped_;
  if (loggedReasons_.insert(reasonKind(reason)).second)
    spdlog::warn("CIGI: dropped a datagram: {} (further drops of this kind are only counted)", reason);
}

void CigiListener::onDatagram(std::span<const std::uint8_t> bytes) {
  auto datagram = cigi::decodeDatagram(bytes);
  if (!datagram) {
    dropped(datagram.error().detail);
    return;
  }
  const auto* ig = std::get_if<cigi::IgControl>(&datagram->packets.front());
  if (!ig) {
    dropped("datagram starts with Start of Frame: an IG accepts host datagrams only");
    return;
  }
  ++accepted_;
  for (const auto& packet : datagram->packets) {
    const auto* entity = std::get_if<cigi::EntityControl>(&packet);
    if (!entity || entity->entityId != 0 || entity->attached) continue;
    HostPose p;
    p.pose.position = {entity->lat_deg, entity->lon_deg, entity->alt_m};
    p.pose.yaw_deg = entity->yaw_deg;
    p.pose.pitch_deg = entity->pitch_deg;
    p.pose.roll_deg = entity->roll_deg;
    p.hostFrame = ig->hostFrame;
    p.hostTime_s = ig->timestampValid ? ig->timestamp_10us * 1.0e-5 : 0.0;
    p.receivedAt = std::chrono::steady_clock::now();
    state_.setPose(p);
  }
  cigi::StartOfFrame sof;
  sof.mode = cigi::IgMode::Operate;
  sof.igFrame = igFrame_++;
  sof.lastHostFrame = ig->hostFrame;
  cigi::DatagramWriter w;
  w.add(sof);
  // Environmental Conditions Requests, answered in the same datagram from the
  // weather this channel holds, by the query every process shares.
  for (const auto& packet : datagram->packets)
    if (const auto* request = std::get_if<cigi::EnvironmentalConditionsRequest>(&packet))
      for (const auto& reply :
           answerConditions(*request, state_.weather(), std::chrono::steady_clock::now(), ownship(state_)))
        w.add(reply);
  boost::system::error_code ec;
  socket_.send_to(asio::buffer(w.bytes()), from_, 0, ec);
}

std::vector<cigi::Packet> answerConditions(const cigi::EnvironmentalConditionsRequest& r, const WeatherView& view,
                                          std::chrono::steady_clock::time_point now,
                                          const std::optional<geo::Geodetic>& camera) {
  std::vector<cigi::Packet> out;
  // The layers (and their winds) are the same in both areas' snapshots; the
  // tiles come from the area that reaches the point.
  const auto& layers = view.snapshot.layers;
  const bool far = view.coarse && camera &&
                   geo::geodesicDistance_m(camera->lat_deg, camera->lon_deg, r.lat_deg, r.lon_deg) > kDetailedReach_m;
  const auto lookup = weather::snapshotLookup(far ? *view.coarse : view.snapshot, view.clockNow(now));
  if (r.requestType & cigi::kRequestWeather) {
    const weather::PointWeather pw = weather::weatherAt(layers, lookup, r.lat_deg, r.lon_deg, r.alt_m);
    cigi::WeatherConditionsResponse wcr;
    wcr.requestId = r.requestId;
    wcr.humidity_pct = static_cast<std::uint8_t>(pw.cloudDensity > 0 ? 100 : kClearAirHumidity_pct);
    wcr.airTemperature_c = static_cast<float>(weather::isaTemperature_c(r.alt_m));
    // Koschmieder: visual range 3.912 / extinction.
    const double sigma = kExtinctionPerDensity_perm * pw.cloudDensity;
    wcr.visibility_m = static_cast<float>(sigma > 0 ? std::min(kClearVisibility_m, 3.912 / sigma) : kClearVisibility_m);
    wcr.horizontalWind_mps = static_cast<float>(pw.wind.speed_mps);
    wcr.verticalWind_mps = static_cast<float>(pw.wind.vertical_mps);
    wcr.windDirection_deg = static_cast<float>(pw.wind.fromDirection_deg);
    wcr.pressure_hpa = static_cast<float>(weather::isaPressure_hpa(r.alt_m));
    out.push_back(wcr);
  }
  if (r.requestType & cigi::kRequestAerosol) {
    // CIGI cloud layers 1-3 are our layers of those ids; their liquid water
    // at the point, g/m^3.
    for (const auto& l : layers) {
      if (l.id < 1 || l.id > 3) continue;
      const weather::PointWeather one = weather::weatherAt(std::span(&l, 1), lookup, r.lat_deg, r.lon_deg, r.alt_m);
      cigi::AerosolConcentrationResponse a;
      a.requestId = r.requestId;
      a.layerId = static_cast<cigi::LayerId>(l.id);
      a.concentration_gpm3 = static_cast<float>(kCloudLiquidWater_gpm3 * one.cloudDensity);
      out.push_back(a);
    }
  }
  return out;
}

}  // namespace sky::app
