// CIGI weather input: maps the weather packets of one decoded host->IG
// datagram onto the change vocabulary (change.hpp).
//
// Layer ids: CIGI Cloud Layer 1..3 become our layers 1..3; IG-defined ids
// 10..255 are taken as further cloud layers with the same id. Ground Fog (0)
// becomes our layer 0 of type fog, its density the packet's visibility range
// (weather::fogDensityForVisibility; a range <= 0 is refused), its cloud type
// field not used. The precipitation ids 4..7 (rain, snow, sleet, hail)
// become our layers 4..7 of those types (precipitation.hpp): the rate from
// the packet's visibility range when it gives one (> 0: the visibility in
// the precipitation), else from its severity (0-1 light, 2-3 moderate, 4
// heavy, 5 twice heavy); base, thickness, coverage and wind as a cloud
// layer's, the cloud type field not used. Sand and dust (8, 9) have no
// counterpart in our model yet and are ignored (counted).
//
// Weather Control, global scope: enabled -> SetLayer (coverage % / 100, base
// elevation, thickness, transition band, cloud type, horizontal wind speed,
// wind direction (from; -180..0 folded into [0, 360)), vertical wind; density
// 1); disabled -> RemoveLayer of a layer this input enabled before
// (a disabled layer it never enabled is left alone). Regional scope: the layer joins (or, disabled,
// leaves) the layers of the region given by Entity/Region ID, and the region
// is sent whole as SetRegion once an Environmental Region Control has placed
// it. Entity scope is rejected (no entity weather in our model). Ignored
// fields: humidity, air temperature, visibility (but ground fog's and
// precipitation's), scud, random winds and lightning, severity (but
// precipitation's), pressure, aerosol concentration.
//
// Environmental Region Control: Active -> SetRegion (centre, size, corner
// radius, rotation, transition perimeter, with the layers given so far);
// Inactive -> RemoveRegion, its geometry and layers kept so a later Active
// brings it back; Destroyed -> RemoveRegion and forgotten. The four merge
// flags are ignored: our regions always replace the global layer of the same
// id inside them and blend in the perimeter.
//
// Hosts resend Weather Control every frame: the mapper remembers what it last
// produced per layer and per region and leaves out anything identical, so a
// steady host produces no changes at all.
#pragma once

#include <cstddef>
#include <cstdint>
#include <map>
#include <optional>

#include "sky/cigi/codec.hpp"
#include "sky/core/result.hpp"
#include "sky/server/change.hpp"

namespace sky::server {

// Regions one sending host may have this input remember (active, inactive
// or placed by Weather Control before its Environmental Region Control).
// CIGI region ids run to 65535; a host describes the few around its ownship
// (the CIGI 3.3 ICD's examples use a handful), so 64 is generous and bounds
// what one host's datagrams can make the server hold.
inline constexpr std::size_t kMaxCigiRegionsPerSender = 64;

class CigiWeatherMapper {
 public:
  // The changes in `datagram` that differ from what this mapper produced
  // before; an empty vector when nothing changed. A packet out of our ranges
  // rejects the whole datagram (InvalidArgument naming the packet index, the
  // packet and the field) and leaves the remembered state as it was; so does
  // a datagram that would make more than kMaxCigiRegionsPerSender regions.
  Result<std::vector<WeatherChange>> map(const cigi::Datagram& datagram);

  // Forget everything remembered (after a submit failed, so the next
  // resend is mapped again).
  void reset();

  std::size_t ignoredLayers() const { return ignoredLayers_; }

 private:
  struct RegionState {
    std::optional<weather::Region> geometry;  // from the last Active ERC
    std::map<std::uint32_t, weather::CloudLayer> layers;
    bool active = false;
    std::optional<weather::Region> lastSent;  // none: not on the server
  };
  std::map<std::uint32_t, std::optional<weather::CloudLayer>> globalSent_;  // none: removed
  std::map<std::uint32_t, RegionState> regions_;
  std::size_t ignoredLayers_ = 0;
};

// The cloud layer a Weather Control describes, or an error naming the field
// ("Weather Control layer 2: coverage 120 outside [0, 100] %"); none when
// the layer id has no counterpart in our model.
Result<std::optional<weather::CloudLayer>> cloudLayerFrom(const cigi::WeatherControl& packet);

}  // namespace sky::server
