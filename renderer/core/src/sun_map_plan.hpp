// When the sun map (shaders/include/sun_map.glsl) is rebuilt, and where it
// lies in the meantime. The map is Earth-fixed: built around the camera's
// position at the time (its anchor), on axes across the sun fixed in ECEF,
// and read by later frames through the anchor's offset and the axes in
// their own local frame. It is rebuilt when what it holds has moved by
// more than it resolves: the first frame; a new weather map (a new
// snapshot, changed tiles); the key light turned by more than
// kSunMapRebuildTurn_deg; the clouds drifted with the wind by more than half
// a texel of the first cascade since the build; the camera moved more than
// a quarter of the first cascade's half extent from the anchor (the
// cascades stay centred on it); the map's settings changed.
#pragma once

#include <cstdint>
#include <optional>
#include <string>

#include <glm/vec3.hpp>

#include "frame_setup.hpp"

namespace sky::render {

// 0.05 degrees: a shadow cast from 5 km above moves 4 m; the sun turns
// that far in 12 s.
inline constexpr double kSunMapRebuildTurn_deg = 0.05;

struct SunMapPlan {
  bool rebuild = false;
  std::string reason;  // why it is rebuilt ("first frame", "weather changed", ...); empty when reused
  SunMapGeometry geometry;  // the map as this frame reads it (its axes and origin in this frame)
};

class SunMapPlanner {
 public:
  // The plan for frame s at weatherClock_s, whose weather map has had
  // weatherUploads uploads so far (WeatherTexture::uploads).
  SunMapPlan plan(const FrameSetup& s, double weatherClock_s, std::uint64_t weatherUploads);
  // The map was not built after all (the frame failed): rebuild next time.
  void forget() { anchor_.reset(); }

 private:
  struct Anchor {
    glm::dvec3 ecef{0};              // the camera at the build
    glm::dvec3 axisU{0}, axisV{0};   // the map's axes, ECEF
    glm::dvec3 sun{0};               // the key light's direction, ECEF
    double weatherClock_s = 0;
    std::uint64_t weatherUploads = 0;
    SunMapSettings settings;
  };
  std::optional<Anchor> anchor_;
};

}  // namespace sky::render
