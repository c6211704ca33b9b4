// FlatBuffers encoding of the weather stream messages, with verification and
// range checks on decode.
#include "sky/stream/messages.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <string>
#include <tuple>

#include "sky/core/overloaded.hpp"
#include "sky/stream/framing.hpp"
#include "weather_stream_generated.h"

namespace sky::stream {

namespace fbs = sky::stream::fb;

namespace {


flatbuffers::Offset<fbs::Layer> encodeLayer(flatbuffers::FlatBufferBuilder& b,
                                            const weather::CloudLayer& l) {
  const fbs::Wind wind(static_cast<float>(l.wind.speed_mps),
                       static_cast<float>(l.wind.fromDirection_deg),
                       static_cast<float>(l.wind.vertical_mps));
  return fbs::CreateLayer(b, l.id, static_cast<std::uint8_t>(l.type),
                          static_cast<float>(l.base_m), static_cast<float>(l.thickness_m),
                          static_cast<float>(l.transitionBand_m), static_cast<float>(l.coverage),
                          static_cast<float>(l.density), &wind, l.tilesDrift);
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
  out.features = h.features();
  if (auto r = checkFinite("Hello", "weather_clock_s", out.weatherClock_s); !r)
    return tl::unexpected(r.error());
  if (auto r = checkRange("Hello", "clock_rate", out.clockRate, 0, 3600); !r)
    return tl::unexpected(r.error());
  return Message(std::move(out));
}

Result<Message> decodeSubscribe(const fbs::Subscribe& s) {
  Subscribe out;
  out.protocolVersion = s.protocol_version();
  if (out.protocolVersion != kProtocolVersion)
    return fail(ErrorCode::Unsupported, "Subscribe.protocol_version " + std::to_string(out.protocolVersion) +
                                            ", this server speaks " + std::to_string(kProtocolVersion));
  out.area = {s.center_lat_deg(), s.center_lon_deg(), s.radius_m()};
  out.altMin_m = s.alt_min_m();
  out.altMax_m = s.alt_max_m();
  out.tileLevel = s.tile_level();
  out.areaIndex = s.area_index();
  for (auto r : {checkRange("Subscribe", "area_index", out.areaIndex, 0, kMaxAreas - 1),
                 checkRange("Subscribe", "center_lat_deg", out.area.centerLat_deg, -90, 90),
                 checkRange("Subscribe", "center_lon_deg", out.area.centerLon_deg, -540, 540),
                 checkRange("Subscribe", "radius_m", out.area.radius_m, 1, 2.0e7),
                 checkRange("Subscribe", "alt_min_m", out.altMin_m, -1000, 1.0e6),
                 checkRange("Subscribe", "alt_max_m", out.altMax_m, out.altMin_m, 1.0e6),
                 checkRange("Subscribe", "tile_level", out.tileLevel, 0, 20)})
    if (!r) return tl::unexpected(r.error());
  return Message(out);
}

Result<weather::CloudLayer> decodeLayer(const char* message, const fbs::Layer& l) {
  weather::CloudLayer layer;
  layer.id = l.id();
  if (l.cloud_type() > weather::kMaxCloudType)
    return fail(ErrorCode::InvalidArgument, std::string(message) + ".layers[id " + std::to_string(l.id()) +
                                                "].cloud_type " + std::to_string(l.cloud_type()) + " outside [0, " + std::to_string(weather::kMaxCloudType) + "]");
  layer.type = static_cast<weather::CloudType>(l.cloud_type());
  layer.base_m = l.base_m();
  layer.thickness_m = l.thickness_m();
  layer.transitionBand_m = l.transition_band_m();
  layer.coverage = l.coverage();
  layer.density = l.density();
  if (const fbs::Wind* w = l.wind()) layer.wind = {w->speed_mps(), w->from_deg(), w->vertical_mps()};
  layer.tilesDrift = l.tiles_drift();
  if (auto r = weather::validate(layer); !r)
    return fail(ErrorCode::InvalidArgument, std::string(message) + ": " + r.error().detail);
  return layer;
}

Result<void> checkCount(const char* message, const char* field, std::size_t n, std::size_t cap) {
  if (n <= cap) return {};
  return fail(ErrorCode::TooLarge, std::string(message) + "." + field + ": " + std::to_string(n) + ", at most " +
                                       std::to_string(cap));
}

// The layer ids of `layers`, sorted; an error when one appears twice. Sorting
// keeps this O(n log n) (a pairwise check was quadratic in a crafted frame).
Result<std::vector<std::uint32_t>> sortedUniqueIds(const char* message,
                                                   const std::vector<weather::CloudLayer>& layers) {
  std::vector<std::uint32_t> ids;
  ids.reserve(layers.size());
  for (const auto& l : layers) ids.push_back(l.id);
  std::sort(ids.begin(), ids.end());
  if (const auto twice = std::adjacent_find(ids.begin(), ids.end()); twice != ids.end())
    return fail(ErrorCode::InvalidArgument,
                std::string(message) + ".layers: id " + std::to_string(*twice) + " appears twice");
  return ids;
}

Result<std::vector<weather::CloudLayer>> decodeLayers(
    const char* message, const flatbuffers::Vector<flatbuffers::Offset<fbs::Layer>>* layers) {
  std::vector<weather::CloudLayer> out;
  if (!layers) return out;
  if (auto r = checkCount(message, "layers", layers->size(), kMaxMessageLayers); !r) return tl::unexpected(r.error());
  out.reserve(layers->size());
  for (const fbs::Layer* l : *layers) {
    auto layer = decodeLayer(message, *l);
    if (!layer) return tl::unexpected(layer.error());
    out.push_back(*layer);
  }
  if (auto ids = sortedUniqueIds(message, out); !ids) return tl::unexpected(ids.error());
  return out;
}

Result<std::vector<weather::CoverageTile>> decodeTiles(const char* message, int level,
                                                       const flatbuffers::Vector<const fbs::Tile*>* tiles) {
  std::vector<weather::CoverageTile> out;
  if (!tiles) return out;
  if (auto r = checkCount(message, "tiles", tiles->size(), kMaxMessageTiles); !r) return tl::unexpected(r.error());
  out.reserve(tiles->size());
  // The FlatBuffers verifier checks a vector's length prefix (4-byte aligned)
  // but not the alignment of 8-byte-aligned struct elements; a crafted buffer
  // can place them at 4 mod 8 (found by fuzz_stream_frame). Our builder never
  // does, so such a buffer is malformed.
  // (An empty vector has no elements to misread, and FlatBuffers may leave it unpadded.)
  if (tiles->size() > 0 && reinterpret_cast<std::uintptr_t>(tiles->Data()) % alignof(fbs::Tile) != 0)
    return fail(ErrorCode::Malformed, std::string(message) + ".tiles: vector of structs is misaligned");
  for (flatbuffers::uoffset_t i = 0; i < tiles->size(); ++i) {
    const fbs::Tile* t = tiles->Get(i);
    if (!weather::isCellAtLevel(t->cell_id(), level))
      return fail(ErrorCode::InvalidArgument, std::string(message) + ".tiles[" + std::to_string(i) + "].cell_id " +
                                                  std::to_string(t->cell_id()) + " is not an S2 cell of level " +
                                                  std::to_string(level));
    if (t->blend_type() > weather::kMaxCloudType)
      return fail(ErrorCode::InvalidArgument, std::string(message) + ".tiles[" + std::to_string(i) +
                                                  "].blend_type " + std::to_string(t->blend_type()) +
                                                  " outside [0, " + std::to_string(weather::kMaxCloudType) + "]");
    out.push_back({t->cell_id(), t->layer_id(), weather::dequantizeUnit(t->coverage()),
                   weather::dequantizeUnit(t->density()), static_cast<weather::CloudType>(t->blend_type()),
                   weather::dequantizeUnit(t->blend())});
  }
  return out;
}

Result<std::vector<weather::WindTile>> decodeWindTiles(const char* message, int level,
                                                       const flatbuffers::Vector<const fbs::WindTile*>* tiles) {
  std::vector<weather::WindTile> out;
  if (!tiles) return out;
  if (auto r = checkCount(message, "wind_tiles", tiles->size(), kMaxMessageTiles); !r) return tl::unexpected(r.error());
  // As for coverage tiles: the verifier does not check the 8-byte alignment.
  if (tiles->size() > 0 && reinterpret_cast<std::uintptr_t>(tiles->Data()) % alignof(fbs::WindTile) != 0)
    return fail(ErrorCode::Malformed, std::string(message) + ".wind_tiles: vector of structs is misaligned");
  out.reserve(tiles->size());
  for (flatbuffers::uoffset_t i = 0; i < tiles->size(); ++i) {
    const fbs::WindTile* t = tiles->Get(i);
    const std::string at = std::string(message) + ".wind_tiles[" + std::to_string(i) + "]";
    if (!weather::isCellAtLevel(t->cell_id(), level))
      return fail(ErrorCode::InvalidArgument, at + ".cell_id " + std::to_string(t->cell_id()) +
                                                  " is not an S2 cell of level " + std::to_string(level));
    for (auto [name, v, limit] : {std::tuple{"east_cmps", t->east_cmps(), 15000}, {"north_cmps", t->north_cmps(), 15000},
                                  {"up_cmps", t->up_cmps(), 5000}})
      if (v < -limit || v > limit)
        return fail(ErrorCode::InvalidArgument, at + "." + name + " " + std::to_string(v) + " outside [-" +
                                                    std::to_string(limit) + ", " + std::to_string(limit) + "]");
    out.push_back({t->cell_id(), t->layer_id(), weather::dequantizeWind(t->east_cmps()),
                   weather::dequantizeWind(t->north_cmps()), weather::dequantizeWind(t->up_cmps())});
  }
  return out;
}

constexpr std::uint8_t kAirNoHumidity = 255;  // AirTile.humidity_half_pct: the source gives none

// Air tiles of a message whose air levels number levelCount (a Delta's are
// checked against its snapshot's when applied: kMaxAirLevels here).
Result<std::vector<weather::AirTile>> decodeAirTiles(const char* message, int level, std::size_t levelCount,
                                                     const flatbuffers::Vector<const fbs::AirTile*>* tiles) {
  std::vector<weather::AirTile> out;
  if (!tiles) return out;
  if (auto r = checkCount(message, "air_tiles", tiles->size(), kMaxMessageTiles); !r) return tl::unexpected(r.error());
  if (tiles->size() > 0 && reinterpret_cast<std::uintptr_t>(tiles->Data()) % alignof(fbs::AirTile) != 0)
    return fail(ErrorCode::Malformed, std::string(message) + ".air_tiles: vector of structs is misaligned");
  out.reserve(tiles->size());
  for (flatbuffers::uoffset_t i = 0; i < tiles->size(); ++i) {
    const fbs::AirTile* t = tiles->Get(i);
    const std::string at = std::string(message) + ".air_tiles[" + std::to_string(i) + "]";
    if (!weather::isCellAtLevel(t->cell_id(), level))
      return fail(ErrorCode::InvalidArgument, at + ".cell_id " + std::to_string(t->cell_id()) +
                                                  " is not an S2 cell of level " + std::to_string(level));
    if (t->level() >= levelCount)
      return fail(ErrorCode::InvalidArgument, at + ".level " + std::to_string(t->level()) + " past the " +
                                                  std::to_string(levelCount) + " air levels");
    if (t->temperature_dc() < -1000 || t->temperature_dc() > 600)
      return fail(ErrorCode::InvalidArgument,
                  at + ".temperature_dc " + std::to_string(t->temperature_dc()) + " outside [-1000, 600]");
    if (t->humidity_half_pct() > 200 && t->humidity_half_pct() != kAirNoHumidity)
      return fail(ErrorCode::InvalidArgument, at + ".humidity_half_pct " + std::to_string(t->humidity_half_pct()) +
                                                  " outside [0, 200] and not 255 (none)");
    out.push_back({t->cell_id(), t->level(), static_cast<float>(t->temperature_dc()) / 10.0f,
                   t->humidity_half_pct() == kAirNoHumidity ? weather::kNoHumidity
                                                           : static_cast<float>(t->humidity_half_pct()) / 2.0f});
  }
  return out;
}

// A Snapshot's air levels: at most kMaxAirLevels heights, finite, within
// [-1000, 100000] m, strictly ascending.
Result<std::vector<float>> decodeAirLevels(const flatbuffers::Vector<float>* levels) {
  std::vector<float> out;
  if (!levels) return out;
  if (auto r = checkCount("Snapshot", "air_levels_m", levels->size(), weather::kMaxAirLevels); !r)
    return tl::unexpected(r.error());
  for (flatbuffers::uoffset_t i = 0; i < levels->size(); ++i) {
    const float h = levels->Get(i);
    const std::string field = "air_levels_m[" + std::to_string(i) + "]";
    if (auto r = checkRange("Snapshot", field.c_str(), h, -1000, 100000); !r) return tl::unexpected(r.error());
    if (!out.empty() && !(h > out.back()))
      return fail(ErrorCode::InvalidArgument, "Snapshot." + field + " = " + std::to_string(h) +
                                                  " is not above the level before it");
    out.push_back(h);
  }
  return out;
}

Result<Message> decodeSnapshot(const fbs::Snapshot& s) {
  weather::WeatherSnapshot out;
  out.weatherClock_s = s.weather_clock_s();
  out.tileLevel = s.tile_level();
  out.areaIndex = s.area_index();
  if (auto r = checkFinite("Snapshot", "weather_clock_s", out.weatherClock_s); !r)
    return tl::unexpected(r.error());
  if (auto r = checkRange("Snapshot", "area_index", out.areaIndex, 0, kMaxAreas - 1); !r)
    return tl::unexpected(r.error());
  if (auto r = checkRange("Snapshot", "tile_level", out.tileLevel, 0, 30); !r)
    return tl::unexpected(r.error());
  auto layers = decodeLayers("Snapshot", s.layers());
  if (!layers) return tl::unexpected(layers.error());
  out.layers = std::move(*layers);
  auto tiles = decodeTiles("Snapshot", out.tileLevel, s.tiles());
  if (!tiles) return tl::unexpected(tiles.error());
  out.tiles = std::move(*tiles);
  out.windTileLevel = s.wind_tile_level();
  if (auto r = checkRange("Snapshot", "wind_tile_level", out.windTileLevel, 0, 30); !r)
    return tl::unexpected(r.error());
  auto windTiles = decodeWindTiles("Snapshot", out.windTileLevel, s.wind_tiles());
  if (!windTiles) return tl::unexpected(windTiles.error());
  out.windTiles = std::move(*windTiles);
  auto airLevels = decodeAirLevels(s.air_levels_m());
  if (!airLevels) return tl::unexpected(airLevels.error());
  out.airLevels_m = std::move(*airLevels);
  out.airTileLevel = s.air_tile_level();
  if (auto r = checkRange("Snapshot", "air_tile_level", out.airTileLevel, 0, 30); !r) return tl::unexpected(r.error());
  auto airTiles = decodeAirTiles("Snapshot", out.airTileLevel, out.airLevels_m.size(), s.air_tiles());
  if (!airTiles) return tl::unexpected(airTiles.error());
  out.airTiles = std::move(*airTiles);
  // Every tile's layer by binary search in the sorted ids: O(tiles log layers).
  const auto ids = sortedUniqueIds("Snapshot", out.layers);
  if (!ids) return tl::unexpected(ids.error());
  for (const auto& t : out.tiles)
    if (!std::binary_search(ids->begin(), ids->end(), t.layerId))
      return fail(ErrorCode::InvalidArgument,
                  "Snapshot.tiles: a tile of layer " + std::to_string(t.layerId) + ", which the Snapshot does not have");
  for (const auto& t : out.windTiles)
    if (!std::binary_search(ids->begin(), ids->end(), t.layerId))
      return fail(ErrorCode::InvalidArgument, "Snapshot.wind_tiles: a tile of layer " + std::to_string(t.layerId) +
                                                  ", which the Snapshot does not have");
  return Message(std::move(out));
}

Result<Message> decodeDelta(const fbs::Delta& d) {
  weather::WeatherDelta out;
  out.weatherClock_s = d.weather_clock_s();
  out.tileLevel = d.tile_level();
  out.areaIndex = d.area_index();
  if (auto r = checkFinite("Delta", "weather_clock_s", out.weatherClock_s); !r) return tl::unexpected(r.error());
  if (auto r = checkRange("Delta", "area_index", out.areaIndex, 0, kMaxAreas - 1); !r)
    return tl::unexpected(r.error());
  if (auto r = checkRange("Delta", "tile_level", out.tileLevel, 0, 30); !r) return tl::unexpected(r.error());
  auto layers = decodeLayers("Delta", d.layers());
  if (!layers) return tl::unexpected(layers.error());
  out.layers = std::move(*layers);
  if (d.removed_layer_ids()) {
    if (auto r = checkCount("Delta", "removed_layer_ids", d.removed_layer_ids()->size(), kMaxMessageLayers); !r)
      return tl::unexpected(r.error());
    out.removedLayerIds.assign(d.removed_layer_ids()->begin(), d.removed_layer_ids()->end());
  }
  auto tiles = decodeTiles("Delta", out.tileLevel, d.tiles());
  if (!tiles) return tl::unexpected(tiles.error());
  out.tiles = std::move(*tiles);
  out.windTileLevel = d.wind_tile_level();
  if (auto r = checkRange("Delta", "wind_tile_level", out.windTileLevel, 0, 30); !r) return tl::unexpected(r.error());
  auto windTiles = decodeWindTiles("Delta", out.windTileLevel, d.wind_tiles());
  if (!windTiles) return tl::unexpected(windTiles.error());
  out.windTiles = std::move(*windTiles);
  out.airTileLevel = d.air_tile_level();
  if (auto r = checkRange("Delta", "air_tile_level", out.airTileLevel, 0, 30); !r) return tl::unexpected(r.error());
  auto airTiles = decodeAirTiles("Delta", out.airTileLevel, weather::kMaxAirLevels, d.air_tiles());
  if (!airTiles) return tl::unexpected(airTiles.error());
  out.airTiles = std::move(*airTiles);
  return Message(std::move(out));
}

// Well-formed UTF-8 (no overlong forms, surrogates or code points past
// U+10FFFF) without ASCII control characters: a channel name is shown in logs
// and JSON as it is.
bool printableUtf8(std::string_view s) {
  std::size_t i = 0;
  while (i < s.size()) {
    const auto c = static_cast<unsigned char>(s[i]);
    if (c < 0x80) {
      if (c < 0x20 || c == 0x7f) return false;
      ++i;
      continue;
    }
    std::size_t n = 0;
    std::uint32_t cp = 0, min = 0;
    if ((c & 0xe0) == 0xc0) n = 1, cp = c & 0x1f, min = 0x80;
    else if ((c & 0xf0) == 0xe0) n = 2, cp = c & 0x0f, min = 0x800;
    else if ((c & 0xf8) == 0xf0) n = 3, cp = c & 0x07, min = 0x10000;
    else return false;
    if (n >= s.size() - i) return false;  // the sequence runs past the end
    for (std::size_t k = 1; k <= n; ++k) {
      const auto cc = static_cast<unsigned char>(s[i + k]);
      if ((cc & 0xc0) != 0x80) return false;
      cp = (cp << 6) | (cc & 0x3f);
    }
    if (cp < min || cp > 0x10ffff || (cp >= 0xd800 && cp <= 0xdfff)) return false;
    i += n + 1;
  }
  return true;
}

Result<Message> decodeCameraReport(const fbs::CameraReport& r) {
  CameraReport out;
  if (r.channel()) {
    if (r.channel()->size() > kMaxChannelBytes)
      return fail(ErrorCode::InvalidArgument, "CameraReport.channel: " + std::to_string(r.channel()->size()) +
                                                  " bytes, at most " + std::to_string(kMaxChannelBytes));
    out.channel = r.channel()->str();
    if (!printableUtf8(out.channel))
      return fail(ErrorCode::InvalidArgument, "CameraReport.channel: not UTF-8 text without control characters");
  }
  out.lat_deg = r.lat_deg();
  out.lon_deg = r.lon_deg();
  out.alt_m = r.alt_m();
  out.heading_deg = r.heading_deg();
  out.pitch_deg = r.pitch_deg();
  out.roll_deg = r.roll_deg();
  out.frame = r.frame();
  out.weatherVersion = r.weather_version();
  out.weatherClock_s = r.weather_clock_s();
  for (auto c : {checkRange("CameraReport", "lat_deg", out.lat_deg, -90, 90),
                 checkRange("CameraReport", "lon_deg", out.lon_deg, -180, 180),
                 checkRange("CameraReport", "alt_m", out.alt_m, -1000, 1.0e6),
                 checkRange("CameraReport", "heading_deg", out.heading_deg, 0, 360),
                 checkRange("CameraReport", "pitch_deg", out.pitch_deg, -90, 90),
                 checkRange("CameraReport", "roll_deg", out.roll_deg, -180, 180),
                 checkFinite("CameraReport", "weather_clock_s", out.weatherClock_s)})
    if (!c) return tl::unexpected(c.error());
  return Message(std::move(out));
}

Result<Message> decodeHostClock(const fbs::HostClock& h) {
  HostClock out;
  const std::size_t bytes = h.host() ? h.host()->size() : 0;
  if (bytes == 0 || bytes > kMaxChannelBytes)
    return fail(ErrorCode::InvalidArgument, "HostClock.host: " + std::to_string(bytes) + " bytes, 1 to " +
                                                std::to_string(kMaxChannelBytes));
  out.host = h.host()->str();
  if (!printableUtf8(out.host))
    return fail(ErrorCode::InvalidArgument, "HostClock.host: not UTF-8 text without control characters");
  out.offset_s = h.offset_s();
  out.rate = h.rate();
  for (auto c : {checkRange("HostClock", "offset_s", out.offset_s, -1.0e12, 1.0e12),
                 checkRange("HostClock", "rate", out.rate, 0, 3600)})
    if (!c) return tl::unexpected(c.error());
  if (!(out.rate > 0)) return fail(ErrorCode::InvalidArgument, "HostClock.rate: 0, must be above 0");
  return Message(std::move(out));
}

Result<Message> decodeLightning(const fbs::Lightning& l) {
  Lightning out;
  out.weatherClock_s = l.weather_clock_s();
  if (auto r = checkFinite("Lightning", "weather_clock_s", out.weatherClock_s); !r) return tl::unexpected(r.error());
  if (const auto* fs = l.flashes()) {
    if (fs->size() > kMaxMessageFlashes)
      return fail(ErrorCode::TooLarge, "Lightning: " + std::to_string(fs->size()) + " flashes, at most " +
                                           std::to_string(kMaxMessageFlashes));
    out.flashes.reserve(fs->size());
    for (flatbuffers::uoffset_t i = 0; i < fs->size(); ++i) {
      const fbs::Flash* f = fs->Get(i);
      weather::LightningFlash flash;
      flash.seed = f->seed();
      flash.time_s = f->time_s();
      flash.lat_deg = f->lat_deg();
      flash.lon_deg = f->lon_deg();
      flash.energy_j = f->energy_j();
      flash.bottom_m = f->bottom_m();
      flash.top_m = f->top_m();
      flash.kind = static_cast<weather::FlashKind>(f->kind());
      if (auto r = weather::validate(flash); !r)
        return fail(ErrorCode::InvalidArgument, "Lightning.flashes[" + std::to_string(i) + "]: " + r.error().detail);
      out.flashes.push_back(flash);
    }
  }
  if (l.answers_to_s() != -1) {
    if (auto r = checkRange("Lightning", "answers_to_s", l.answers_to_s(), -1.0e12, 1.0e12); !r)
      return tl::unexpected(r.error());
    out.answersTo_s = l.answers_to_s();
  }
  return Message(std::move(out));
}

Result<Message> decodeLightningRequest(const fbs::LightningRequest& r) {
  LightningRequest out{r.from_s(), r.to_s()};
  for (auto c : {checkRange("LightningRequest", "from_s", out.from_s, -1.0e12, 1.0e12),
                 checkRange("LightningRequest", "to_s", out.to_s, -1.0e12, 1.0e12)})
    if (!c) return tl::unexpected(c.error());
  if (!(out.to_s > out.from_s) || out.to_s - out.from_s > kMaxLightningRequestSpan_s)
    return fail(ErrorCode::InvalidArgument, "LightningRequest.to_s: " + std::to_string(out.to_s) +
                                                ", must be after from_s (" + std::to_string(out.from_s) +
                                                ") by at most " + std::to_string(kMaxLightningRequestSpan_s) + " s");
  return Message(out);
}

std::vector<fbs::Tile> encodeTiles(const std::vector<weather::CoverageTile>& tiles) {
  std::vector<fbs::Tile> out;
  out.reserve(tiles.size());
  for (const auto& t : tiles)
    out.emplace_back(t.cellId, static_cast<std::uint16_t>(t.layerId), weather::quantizeUnit(t.coverage),
                     weather::quantizeUnit(t.density), static_cast<std::uint8_t>(t.blendType),
                     weather::quantizeUnit(t.blend));
  return out;
}

std::vector<fbs::WindTile> encodeWindTiles(const std::vector<weather::WindTile>& tiles) {
  std::vector<fbs::WindTile> out;
  out.reserve(tiles.size());
  for (const auto& t : tiles)
    out.emplace_back(t.cellId, static_cast<std::uint16_t>(t.layerId), weather::quantizeWind(t.east_mps, 150),
                     weather::quantizeWind(t.north_mps, 150), weather::quantizeWind(t.up_mps, 50));
  return out;
}

std::vector<fbs::AirTile> encodeAirTiles(const std::vector<weather::AirTile>& tiles) {
  std::vector<fbs::AirTile> out;
  out.reserve(tiles.size());
  for (const auto& t : tiles) {
    const weather::AirTile q = weather::quantizedAir(t);
    out.emplace_back(t.cellId, static_cast<std::uint8_t>(t.level),
                     q.humidity_pct < 0 ? kAirNoHumidity : static_cast<std::uint8_t>(std::lround(q.humidity_pct * 2.0f)),
                     static_cast<std::int16_t>(std::lround(q.temperature_c * 10.0f)), 0u);
  }
  return out;
}

static_assert(sizeof(fbs::WindTile) == kWindTileWireBytes, "kWindTileWireBytes must match the schema's WindTile");
static_assert(sizeof(fbs::AirTile) == kAirTileWireBytes, "kAirTileWireBytes must match the schema's AirTile");
static_assert(sizeof(fbs::Tile) == kTileWireBytes, "kTileWireBytes must match the schema's Tile");
static_assert(kMaxMessageTiles * kTileWireBytes == kMaxFrameBytes, "kMaxMessageTiles: the tiles of one full frame");

}  // namespace

std::vector<std::uint8_t> encodeMessage(const Message& message) {
  flatbuffers::FlatBufferBuilder b(256);
  const auto [type, body] = std::visit(
      Overloaded{
          [&](const Hello& h) {
            return std::pair{fbs::Body::Hello,
                             fbs::CreateHelloDirect(b, h.protocolVersion, h.serverId.c_str(),
                                                    h.weatherClock_s, h.clockRate, h.features)
                                 .Union()};
          },
          [&](const Subscribe& s) {
            return std::pair{fbs::Body::Subscribe,
                             fbs::CreateSubscribe(b, s.protocolVersion, s.area.centerLat_deg,
                                                  s.area.centerLon_deg, s.area.radius_m, s.altMin_m,
                                                  s.altMax_m, static_cast<std::uint8_t>(s.tileLevel), s.areaIndex)
                                 .Union()};
          },
          [&](const weather::WeatherSnapshot& s) {
            std::vector<flatbuffers::Offset<fbs::Layer>> layers;
            for (const auto& l : s.layers) layers.push_back(encodeLayer(b, l));
            const std::vector<fbs::Tile> tiles = encodeTiles(s.tiles);
            const std::vector<fbs::WindTile> windTiles = encodeWindTiles(s.windTiles);
            const std::vector<fbs::AirTile> airTiles = encodeAirTiles(s.airTiles);
            return std::pair{fbs::Body::Snapshot,
                             fbs::CreateSnapshotDirect(b, s.weatherClock_s, &layers,
                                                       static_cast<std::uint8_t>(s.tileLevel), &tiles,
                                                       s.areaIndex, static_cast<std::uint8_t>(s.windTileLevel),
                                                       s.windTiles.empty() ? nullptr : &windTiles,
                                                       s.airLevels_m.empty() ? nullptr : &s.airLevels_m,
                                                       static_cast<std::uint8_t>(s.airTileLevel),
                                                       s.airTiles.empty() ? nullptr : &airTiles)
                                 .Union()};
          },
          [&](const Heartbeat& h) {
            return std::pair{fbs::Body::Heartbeat, fbs::CreateHeartbeat(b, h.weatherClock_s).Union()};
          },
          [&](const StreamError& e) {
            return std::pair{fbs::Body::ErrorMessage,
                             fbs::CreateErrorMessageDirect(b, e.code, e.detail.c_str()).Union()};
          },
          [&](const weather::WeatherDelta& d) {
            std::vector<flatbuffers::Offset<fbs::Layer>> layers;
            for (const auto& l : d.layers) layers.push_back(encodeLayer(b, l));
            const std::vector<fbs::Tile> tiles = encodeTiles(d.tiles);
            const std::vector<fbs::WindTile> windTiles = encodeWindTiles(d.windTiles);
            const std::vector<fbs::AirTile> airTiles = encodeAirTiles(d.airTiles);
            return std::pair{fbs::Body::Delta,
                             fbs::CreateDeltaDirect(b, d.weatherClock_s, &layers, &d.removedLayerIds,
                                                    static_cast<std::uint8_t>(d.tileLevel), &tiles, d.areaIndex,
                                                    static_cast<std::uint8_t>(d.windTileLevel),
                                                    d.windTiles.empty() ? nullptr : &windTiles,
                                                    static_cast<std::uint8_t>(d.airTileLevel),
                                                    d.airTiles.empty() ? nullptr : &airTiles)
                                 .Union()};
          },
          [&](const CameraReport& r) {
            // CreateString takes the length: the channel goes out as it is
            // (an embedded NUL too, which the decoder then refuses).
            const auto channel = b.CreateString(r.channel);
            return std::pair{fbs::Body::CameraReport,
                             fbs::CreateCameraReport(
                                 b, channel, r.lat_deg, r.lon_deg, r.alt_m, static_cast<float>(r.heading_deg),
                                 static_cast<float>(r.pitch_deg), static_cast<float>(r.roll_deg), r.frame,
                                 r.weatherVersion, r.weatherClock_s)
                                 .Union()};
          },
          [&](const Lightning& l) {
            std::vector<fbs::Flash> flashes;
            flashes.reserve(l.flashes.size());
            for (const auto& f : l.flashes)
              flashes.emplace_back(f.seed, f.time_s, f.lat_deg, f.lon_deg, f.energy_j, static_cast<float>(f.bottom_m),
                                   static_cast<float>(f.top_m), static_cast<std::uint8_t>(f.kind), 0, 0, 0u);
            return std::pair{fbs::Body::Lightning,
                             fbs::CreateLightningDirect(b, l.weatherClock_s, &flashes, l.answersTo_s.value_or(-1.0))
                                 .Union()};
          },
          [&](const HostClock& h) {
            return std::pair{fbs::Body::HostClock,
                             fbs::CreateHostClockDirect(b, h.host.c_str(), h.offset_s, h.rate).Union()};
          },
          [&](const LightningRequest& r) {
            return std::pair{fbs::Body::LightningRequest, fbs::CreateLightningRequest(b, r.from_s, r.to_s).Union()};
          },
          [&](const UnknownKind& u) {
            // An empty table under a type byte we do not define: what a newer
            // peer's message looks like to this build.
            const auto start = b.StartTable();
            return std::pair{static_cast<fbs::Body>(u.bodyType), flatbuffers::Offset<void>(b.EndTable(start))};
          }},
      message);
  b.Finish(fbs::CreateMessage(b, type, body));
  return {b.GetBufferPointer(), b.GetBufferPointer() + b.GetSize()};
}

Result<Message> decodeMessage(std::span<const std::uint8_t> payload) {
  // Alignment inside a FlatBuffer is relative to its start: give it a start
  // aligned for the widest scalar when the caller's bytes are not.
  std::vector<std::uint64_t> aligned;
  if (reinterpret_cast<std::uintptr_t>(payload.data()) % alignof(std::uint64_t) != 0) {
    aligned.resize((payload.size() + 7) / 8);
    std::memcpy(aligned.data(), payload.data(), payload.size());
    payload = std::span(reinterpret_cast<const std::uint8_t*>(aligned.data()), payload.size());
  }
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
    case fbs::Body::Delta: return decodeDelta(*m->body_as_Delta());
    case fbs::Body::CameraReport: return decodeCameraReport(*m->body_as_CameraReport());
    case fbs::Body::Lightning: return decodeLightning(*m->body_as_Lightning());
    case fbs::Body::HostClock: return decodeHostClock(*m->body_as_HostClock());
    case fbs::Body::LightningRequest: return decodeLightningRequest(*m->body_as_LightningRequest());
    case fbs::Body::NONE: return fail(ErrorCode::Malformed, "message has no body");
  }
  // A kind appended to the schema after this build: the verifier could not
  // look inside it, and nothing here reads it.
  return Message(UnknownKind{static_cast<std::uint8_t>(m->body_type())});
}

const char* kindName(const Message& message) {
  return std::visit(Overloaded{[](const Hello&) { return "Hello"; },
                               [](const Subscribe&) { return "Subscribe"; },
                               [](const weather::WeatherSnapshot&) { return "Snapshot"; },
                               [](const Heartbeat&) { return "Heartbeat"; },
                               [](const StreamError&) { return "Error"; },
                               [](const weather::WeatherDelta&) { return "Delta"; },
                               [](const CameraReport&) { return "CameraReport"; },
                               [](const Lightning&) { return "Lightning"; },
                               [](const HostClock&) { return "HostClock"; },
                               [](const LightningRequest&) { return "LightningRequest"; },
                               [](const UnknownKind&) { return "an unknown kind"; }},
                    message);
}

}  // namespace sky::stream
