// FlatBuffers encoding of the weather stream messages, with verification and
// range checks on decode.
#include "sky/stream/messages.hpp"

#include <cmath>
#include <string>

#include "weather_stream_generated.h"

namespace sky::stream {

namespace fbs = sky::stream::fb;

namespace {

template <class... Ts>
struct Overloaded : Ts... {
  using Ts::operator()...;
};
template <class... Ts>
Overloaded(Ts...) -> Overloaded<Ts...>;  // clang 14 lacks aggregate CTAD

flatbuffers::Offset<fbs::Layer> encodeLayer(flatbuffers::FlatBufferBuilder& b,
                                            const weather::CloudLayer& l) {
  const fbs::Wind wind(static_cast<float>(l.wind.speed_mps),
                       static_cast<float>(l.wind.fromDirection_deg),
                       static_cast<float>(l.wind.vertical_mps));
  return fbs::CreateLayer(b, l.id, static_cast<std::uint8_t>(l.type),
                          static_cast<float>(l.base_m), static_cast<float>(l.thickness_m),
                          static_cast<float>(l.transitionBand_m), static_cast<float>(l.coverage),
                          static_cast<float>(l.density), &wind);
}

Result<void> checkFinite(const char* message, const char* field, double v) {
  if (std::isfinite(v)) return {};
  return fail(ErrorCode::Malformed, std::string(message) + "." + field + " is not finite");
}

Result<void> checkRange(const char* message, const char* field, double v, double lo, double hi) {
  if (std::isfinite(v) && v >= lo && v <= hi) return {};
  return fail(ErrorCode::InvalidArgument, std::string(message) + "." + field + " = " +
                                              std::to_string(v) + " outside [" +
                                              std::to_string(lo) + ", " + std::to_string(hi) + "]");
}

Result<Message> decodeHello(const fbs::Hello& h) {
  Hello out;
  out.protocolVersion = h.protocol_version();
  if (out.protocolVersion != kProtocolVersion)
    return fail(ErrorCode::Unsupported, "Hello.protocol_version " +
                                            std::to_string(out.protocolVersion) + ", we speak " +
                                            std::to_string(kProtocolVersion));
  out.serverId = h.server_id() ? h.server_id()->str() : std::string();
  out.weatherClock_s = h.weather_clock_s();
  out.clockRate = h.clock_rate();
  if (auto r = checkFinite("Hello", "weather_clock_s", out.weatherClock_s); !r)
    return tl::unexpected(r.error());
  if (auto r = checkRange("Hello", "clock_rate", out.clockRate, 0, 3600); !r)
    return tl::unexpected(r.error());
  return Message(std::move(out));
}

Result<Message> decodeSubscribe(const fbs::Subscribe& s) {
  Subscribe out;
  out.area = {s.center_lat_deg(), s.center_lon_deg(), s.radius_m()};
  out.altMin_m = s.alt_min_m();
  out.altMax_m = s.alt_max_m();
  out.tileLevel = s.tile_level();
  for (auto r : {checkRange("Subscribe", "center_lat_deg", out.area.centerLat_deg, -90, 90),
                 checkRange("Subscribe", "center_lon_deg", out.area.centerLon_deg, -540, 540),
                 checkRange("Subscribe", "radius_m", out.area.radius_m, 1, 2.0e7),
                 checkRange("Subscribe", "alt_min_m", out.altMin_m, -1000, 1.0e6),
                 checkRange("Subscribe", "alt_max_m", out.altMax_m, out.altMin_m, 1.0e6),
                 checkRange("Subscribe", "tile_level", out.tileLevel, 0, 20)})
    if (!r) return tl::unexpected(r.error());
  return Message(out);
}

Result<Message> decodeSnapshot(const fbs::Snapshot& s) {
  weather::WeatherSnapshot out;
  out.weatherClock_s = s.weather_clock_s();
  out.tileLevel = s.tile_level();
  if (auto r = checkFinite("Snapshot", "weather_clock_s", out.weatherClock_s); !r)
    return tl::unexpected(r.error());
  if (auto r = checkRange("Snapshot", "tile_level", out.tileLevel, 0, 30); !r)
    return tl::unexpected(r.error());
  if (s.layers()) {
    for (const fbs::Layer* l : *s.layers()) {
      weather::CloudLayer layer;
      layer.id = l->id();
      if (l->cloud_type() > weather::kMaxCloudType)
        return fail(ErrorCode::InvalidArgument, "Snapshot.layers[" + std::to_string(l->id()) +
                                                    "].cloud_type " +
                                                    std::to_string(l->cloud_type()) +
                                                    " outside [0, 10]");
      layer.type = static_cast<weather::CloudType>(l->cloud_type());
      layer.base_m = l->base_m();
      layer.thickness_m = l->thickness_m();
      layer.transitionBand_m = l->transition_band_m();
      layer.coverage = l->coverage();
      layer.density = l->density();
      if (const fbs::Wind* w = l->wind())
        layer.wind = {w->speed_mps(), w->from_deg(), w->vertical_mps()};
      if (auto r = weather::validate(layer); !r)
        return fail(ErrorCode::InvalidArgument, "Snapshot: " + r.error().detail);
      out.layers.push_back(layer);
    }
  }
  if (s.tiles()) {
    out.tiles.reserve(s.tiles()->size());
    for (const fbs::Tile* t : *s.tiles()) {
      const weather::CoverageTile tile{t->cell_id(), t->layer_id(), t->coverage(), t->density()};
      if (auto r = checkRange("Snapshot.tiles", "coverage", tile.coverage, 0, 1); !r)
        return tl::unexpected(r.error());
      if (auto r = checkRange("Snapshot.tiles", "density", tile.density, 0, 1); !r)
        return tl::unexpected(r.error());
      out.tiles.push_back(tile);
    }
  }
  return Message(std::move(out));
}

}  // namespace

std::vector<std::uint8_t> encodeMessage(const Message& message) {
  flatbuffers::FlatBufferBuilder b(256);
  const auto [type, body] = std::visit(
      Overloaded{
          [&](const Hello& h) {
            return std::pair{fbs::Body::Hello,
                             fbs::CreateHelloDirect(b, h.protocolVersion, h.serverId.c_str(),
                                                    h.weatherClock_s, h.clockRate)
                                 .Union()};
          },
          [&](const Subscribe& s) {
            return std::pair{fbs::Body::Subscribe,
                             fbs::CreateSubscribe(b, s.area.centerLat_deg, s.area.centerLon_deg,
                                                  s.area.radius_m, s.altMin_m, s.altMax_m,
                                                  static_cast<std::uint8_t>(s.tileLevel))
                                 .Union()};
          },
          [&](const weather::WeatherSnapshot& s) {
            std::vector<flatbuffers::Offset<fbs::Layer>> layers;
            for (const auto& l : s.layers) layers.push_back(encodeLayer(b, l));
            std::vector<fbs::Tile> tiles;
            tiles.reserve(s.tiles.size());
            for (const auto& t : s.tiles) tiles.emplace_back(t.cellId, t.layerId, t.coverage, t.density);
            return std::pair{fbs::Body::Snapshot,
                             fbs::CreateSnapshotDirect(b, s.weatherClock_s, &layers,
                                                       static_cast<std::uint8_t>(s.tileLevel), &tiles)
                                 .Union()};
          },
          [&](const Heartbeat& h) {
            return std::pair{fbs::Body::Heartbeat, fbs::CreateHeartbeat(b, h.weatherClock_s).Union()};
          },
          [&](const StreamError& e) {
            return std::pair{fbs::Body::ErrorMessage,
                             fbs::CreateErrorMessageDirect(b, e.code, e.detail.c_str()).Union()};
          }},
      message);
  b.Finish(fbs::CreateMessage(b, type, body));
  return {b.GetBufferPointer(), b.GetBufferPointer() + b.GetSize()};
}

Result<Message> decodeMessage(std::span<const std::uint8_t> payload) {
  flatbuffers::Verifier verifier(payload.data(), payload.size());
  if (!fbs::VerifyMessageBuffer(verifier))
    return fail(ErrorCode::Malformed,
                "frame of " + std::to_string(payload.size()) + " bytes fails FlatBuffers verification");
  const fbs::Message* m = fbs::GetMessage(payload.data());
  // The verifier accepts a union whose type is set but whose table is absent
  // (the field is optional): reject that here, before any body_as_*().
  if (m->body_type() != fbs::Body::NONE && m->body() == nullptr)
    return fail(ErrorCode::Malformed, "message names body type " +
                                          std::to_string(static_cast<int>(m->body_type())) +
                                          " but carries no body");
  switch (m->body_type()) {
    case fbs::Body::Hello: return decodeHello(*m->body_as_Hello());
    case fbs::Body::Subscribe: return decodeSubscribe(*m->body_as_Subscribe());
    case fbs::Body::Snapshot: return decodeSnapshot(*m->body_as_Snapshot());
    case fbs::Body::Heartbeat: {
      const double clock = m->body_as_Heartbeat()->weather_clock_s();
      if (auto r = checkFinite("Heartbeat", "weather_clock_s", clock); !r)
        return tl::unexpected(r.error());
      return Message(Heartbeat{clock});
    }
    case fbs::Body::ErrorMessage: {
      const auto* e = m->body_as_ErrorMessage();
      return Message(StreamError{e->code(), e->detail() ? e->detail()->str() : std::string()});
    }
    case fbs::Body::NONE: break;
  }
  return fail(ErrorCode::Malformed,
              "message body type " + std::to_string(static_cast<int>(m->body_type())) + " unknown");
}

const char* kindName(const Message& message) {
  return std::visit(Overloaded{[](const Hello&) { return "Hello"; },
                               [](const Subscribe&) { return "Subscribe"; },
                               [](const weather::WeatherSnapshot&) { return "Snapshot"; },
                               [](const Heartbeat&) { return "Heartbeat"; },
                               [](const StreamError&) { return "Error"; }},
                    message);
}

}  // namespace sky::stream
