// When the sun map (shaders/include/sun_map.glsl) is rebuilt, and where it
// lies in the meantime. The map is Earth-fixed: each cascade is built around
// the camera's position at the time (its anchor), on axes across the sun
// fixed in ECEF, and read by later frames through the anchor's offset and the
// axes in their own local frame. Every cascade is rebuilt when tiles of the
// weather map change, when the key light turned by more than
// kSunMapRebuildTurn_deg (they share the axes), and when the clouds drifted
// with the wind by more than half a texel of the first cascade (a coarse
// cascade kept until they drifted half of its own texel jumped visibly when
// rebuilt). A cascade alone is rebuilt when the camera moved more than a
// quarter of its half extent from its anchor: cascade c's extent is 4^c
// times cascade 0's, so a flight through calm air rebuilds the fine cascade
// most often and the 256 km one 64 times less often.
//
// A rebuild is built over SunMapSettings::buildFrames frames, a band of rows
// of each cascade it rebuilds per frame, into the other of the image's two
// maps for those cascades, while the frames read the first; the frame that
// builds the last band reads the new cascades, and their slots swap. So a
// rebuild costs a frame 1/buildFrames of its build instead of all of it at
// once (a climbing airliner's map at low sun takes 115 ms to build whole on
// this machine, against a 6 ms `realtime` frame), and the map read lags what
// it should hold by at most buildFrames frames. A build under way is not
// restarted by what moves on (the weather changing every frame would never
// let it finish); when it completes the planner looks again, from the new
// cascades. The first frame and a change of the map's settings build the
// whole map at once: there is nothing to read. So do a weather map rebuilt
// whole (a new snapshot, a new anchor), tiles that stepped (by more than
// kMaxRampStep at a texel) and a jump of the sun, the clouds or the camera
// (kSunMapJumpTurn_deg and below): the old shadows may belong to other
// clouds altogether, where what ramps or moves on changes them a little.
#pragma once

#include <array>
#include <cstdint>
#include <optional>
#include <string>

#include <glm/vec3.hpp>

#include "frame_setup.hpp"

namespace sky::render {

// 0.05 degrees: a shadow cast from 5 km above moves 4 m; the sun turns
// that far in 12 s.
inline constexpr double kSunMapRebuildTurn_deg = 0.05;
// Past these the map has jumped rather than moved on (a host setting the
// time of day or the weather clock, a teleport), and the new one is built
// at once: the sun turned by over 1 degree (a shadow from 5 km up 87 m
// away), the clouds drifted over 8 half texels of the first cascade, the
// camera moved out of the first cascade's half extent.
inline constexpr double kSunMapJumpTurn_deg = 1.0;
inline constexpr double kSunMapJumpTexels = 8.0;

struct SunMapPlan {
  // The map the frame reads and the rows of the cascades it builds, each in
  // this frame's local frame, and their slots (FrameSetup::SunMapFrame).
  FrameSetup::SunMapFrame frame;
  bool completes = false;  // this frame builds the rebuild's last rows (and reads them)
  std::string reason;      // why cascades are being rebuilt ("first frame", ...); empty when none are
  bool builds() const { return frame.rowEnd > frame.rowBegin && frame.endCascade > frame.firstCascade; }
};

class SunMapPlanner {
 public:
  // The plan for frame s at weatherClock_s, whose weather map has had
  // weatherUploads uploads so far (WeatherTexture::uploads); weatherJumped:
  // the last of them was a whole new map or a step (else a ramp). A frame that
  // draws no layer builds nothing and moves nothing on (nothing reads the
  // map, and the map pass does not run).
  SunMapPlan plan(const FrameSetup& s, double weatherClock_s, std::uint64_t weatherUploads, bool weatherJumped);
  // The frame planned last was not drawn (it failed): the maps' contents are
  // unknown, so the next frame builds a whole map.
  void forget() {
    front_.reset();
    pending_.reset();
  }

  static constexpr std::uint32_t kMaxCascades = 4;

 private:
  // What every cascade of a map shares: its axes across the sun, its
  // shells, the sun it was built for, its settings.
  struct Frame {
    glm::dvec3 axisU{0}, axisV{0};  // ECEF
    double top_m = 0, base_m = 0;
    glm::dvec3 sun{0};  // the key light's direction, ECEF
    SunMapSettings settings;
  };
  // Where and when one cascade was built.
  struct Anchor {
    glm::dvec3 ecef{0};  // the camera at the build
    double weatherClock_s = 0;
    std::uint64_t weatherUploads = 0;
  };
  struct Front {
    Frame frame;
    std::array<Anchor, kMaxCascades> anchors{};  // [0, settings.cascades) used
    std::uint32_t slots = 0;                      // bit c: the image's map cascade c is read from
  };
  struct Pending {
    Frame frame;
    Anchor anchor;
    std::uint32_t first = 0, end = 0;  // the cascades being rebuilt
    std::uint32_t rowsDone = 0;
    std::string reason;
  };
  // Why cascades of the map `f` no longer hold frame s (reason empty: none
  // is), whether by a jump (the whole map is of no use), and which
  // cascades: [first, end), every one between the finest and the coarsest
  // that moved on.
  struct Staleness {
    std::string reason;
    bool jumped = false;
    std::uint32_t first = 0, end = 0;
  };
  static Staleness staleness(const Front& f, const FrameSetup& s, double weatherClock_s, std::uint64_t weatherUploads);
  static SunMapGeometry inFrame(const Frame& f, const Anchor& a, const FrameSetup& s);

  std::optional<Front> front_;  // the cascades frames read
  std::optional<Pending> pending_;  // cascades being rebuilt, in their other slots
};

}  // namespace sky::render
