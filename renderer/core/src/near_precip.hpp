// Precipitation near the camera: the drops or flakes within a few metres,
// each drawn as the streak its motion relative to the camera leaves over
// the frame's exposure (near_precip_pass.hpp draws them). Farther away the
// precipitation is a medium the clouds' march draws (its extinction and
// light); here its drops are counted and sized by published laws, moved by
// their fall speed, the wind and the camera's own motion, and seen through
// the frame's view.
//
// The drops are points of a pattern that repeats every `box` metres along
// the Earth-fixed (ECEF) axes and drifts with the air: drop i sits at
// box x frac(u_i + (v_i t - camera) / box), a cube of side `box` round the
// camera, u_i and its size from a hash of (seed, i). Every channel of a host
// that draws the same clock at the same place draws the same drops; a rate
// that rises adds drops (those numbered past the old count) without moving
// the others.
#pragma once

#include <cstdint>
#include <optional>
#include <vector>

#include <glm/glm.hpp>

#include "frame_setup.hpp"
#include "near_precip_shared.h"
#include "sky/render/cloud_renderer.hpp"
#include "sky/weather/model.hpp"
#include "sky/weather/query.hpp"

namespace sky::render {

// At most this many drops a frame (a heavier rate draws a subset, said in
// DropPopulation::capped), and this many (streak, tile) entries.
inline constexpr std::uint32_t kMaxNearDrops = 16384;
inline constexpr std::uint32_t kMaxNearEntries = 1u << 20;
// The faintest streak drawn: one that covers no pixel for more than this
// share of the exposure changes none by more than 0.1 % of the difference
// between the drop's radiance and what lies behind it (a drop far off and
// small, or one the camera passes fast). Such streaks would be most of the
// work of a fast camera's frame (4426 streaks on a 640x360 image at 70 m/s
// in 8 mm/h rain, in 54011 tile entries), for light the precipitation's
// medium already draws on average.
inline constexpr double kFaintestStreak = 1e-3;
// The nearest a drop is drawn, m: closer ones would be on the canopy or lens
// of whatever carries the camera.
inline constexpr double kNearestDrop_m = 0.3;

// The drops of one precipitation type and rate drawn round the camera.
// Rain, sleet and hail: Marshall and Palmer (1948), N(D) = N0 e^(-Lambda D)
// with N0 = 8000 m^-3 mm^-1 and Lambda = 4.1 R^-0.21 mm^-1. Snow: Gunn and
// Marshall (1958) for the melted diameter, N0 = 3800 R^-0.87 m^-3 mm^-1 and
// Lambda = 2.55 R^-0.48 mm^-1; a flake of snow of density 0.1 g/cm^3 is
// 10^(1/3) = 2.15 times its melted diameter across. Only drops of at least
// minDiameter are drawn (the smaller ones are too faint to see as streaks;
// the medium's extinction has them all).
struct DropPopulation {
  weather::CloudType type = weather::CloudType::None;
  double rate_mmph = 0;
  double box_m = 0;                // the side of the cube round the camera
  double minDiameter_mm = 0;       // the smallest drawn (melted, for snow)
  double maxDiameter_mm = 0;       // the largest (rain drops break up past it)
  double lambda_permm = 0;         // the size distribution's slope
  double numberDensity_perm3 = 0;  // drops of at least minDiameter per m^3
  std::uint32_t count = 0;         // drawn: numberDensity x box^3, at most kMaxNearDrops
  bool capped = false;             // the rate asked for more than kMaxNearDrops
  // A drop's radiance over the mean radiance of the frame's image: a raindrop
  // refracts its surroundings over about 165 degrees into the eye, at 0.94
  // of their mean radiance (Garg and Nayar 2007, "Vision and rain"); a
  // snowflake or hailstone is a white diffuser (albedo 0.9, chosen), whose
  // radiance under surroundings of mean radiance L is 0.9 L; sleet the mean.
  double radianceFactor = 0;
};

// The drops for precipitation of this type and rate; count 0 for no
// precipitation (a type that is not, or a rate <= 0).
DropPopulation dropPopulation(weather::CloudType type, double rate_mmph);

// The terminal fall speed of a raindrop of diameter d (mm) at sea level:
// Atlas, Srivastava and Sekhon (1973), 9.65 - 10.3 e^(-0.6 d) m/s, 0 at
// the smallest sizes. Snow falls at the type's speed (about 1 m/s for
// aggregates, precipitation.hpp), sleet and hail at theirs.
double raindropFallSpeed_mps(double diameter_mm);

// One frame's inputs: the precipitation at the camera, the air's motion,
// the camera's, and the view.
struct NearPrecipInputs {
  weather::CloudType type = weather::CloudType::None;
  double rate_mmph = 0;
  glm::dvec3 airEnu_mps{0};     // the wind at the camera (east, north, up)
  glm::dvec3 cameraEnu_mps{0};  // the camera's velocity (east, north, up)
  double clock_s = 0;           // the weather clock at the end of the exposure
  double exposure_s = 0;
  glm::dvec3 cameraEcef_m{0};
  glm::dmat3 localToEcef{1};    // columns: the camera's east, north, up in ECEF
  glm::dvec3 camForward{0, 1, 0}, camRight{1, 0, 0}, camDown{0, 0, -1};  // local frame
  glm::dvec4 frustum{-1, 1, 1, -1};  // core_common.glsl's frustumPoint
  std::uint32_t width = 0, height = 0;
  std::uint32_t seed = 1;
};

// The streaks of one frame, listed by kNearPrecipTile-pixel tiles.
struct NearPrecipFrame {
  DropPopulation population;
  std::vector<gpu::SkyStreak> streaks;  // those that reach the image
  std::uint32_t tilesX = 0, tilesY = 0;
  std::vector<glm::uvec2> tiles;        // per tile: first entry, entry count
  std::vector<std::uint32_t> entries;   // streak indices, tile by tile
  // The drops' image area, sum of pi r^2 (px^2) over the streaks drawn: the
  // light the pass spreads (precip_streak.glsl) integrates to it.
  double dropArea_px2 = 0;
  bool entriesCapped = false;           // streaks left out past kMaxNearEntries
  std::uint32_t faint = 0;              // streaks left out as fainter than kFaintestStreak
};

NearPrecipFrame buildNearPrecip(const NearPrecipInputs& in);

// A camera's velocity from its positions at two clocks: nullopt (a still
// camera is assumed) when the clock did not move forward, moved more than a
// second, or the speed is past 1000 m/s (a jump, not flight).
std::optional<glm::dvec3> cameraVelocityEcef(const glm::dvec3& fromEcef_m, double from_s, const glm::dvec3& toEcef_m,
                                             double to_s);

// A renderer's source of NearPrecipInputs, frame after frame: the heaviest
// precipitation at the camera and the wind there from the shared point query
// (query.hpp: what the renderer's CIGI answers give its host), and the
// camera's velocity from its last position and clock.
class NearPrecipSource {
 public:
  NearPrecipInputs inputs(const RenderSettings& settings, const FrameInputs& frame, const FrameSetup& setup);

 private:
  // The lookups over the last snapshot's tiles, kept while the caller's
  // weather version (FrameInputs::weatherVersion) and snapshot stay the same.
  const weather::WeatherSnapshot* snapshot_ = nullptr;
  std::optional<std::uint64_t> version_;
  double lookupClock_s_ = 0;  // the clock the lookups were made at
  weather::CoverageLookup coverage_;
  weather::WindLookup wind_;
  std::optional<std::pair<glm::dvec3, double>> last_;  // the last frame's camera (ECEF) and clock
};

}  // namespace sky::render
