// The CPU half of interleaved rendering (TemporalSettings): which pixel of
// each n x n block a frame draws, whether the previous frame's image may be
// reused at all (else the frame is drawn whole), and the reprojection pass's
// parameters: the previous camera and each layer's wind motion in this
// frame's local frame, from the two frames' setups in double precision.
// Pure: no GPU, so the rules are unit-tested (tests/unit/renderer/temporal_plan_test.cpp).
#pragma once

#include <cstdint>
#include <deque>
#include <optional>
#include <string>
#include <vector>

#include <glm/mat3x3.hpp>
#include <glm/vec2.hpp>
#include <glm/vec3.hpp>

#include "frame_setup.hpp"
#include "history_drop.hpp"
#include "reproject_shared.h"
#include "sky/render/cloud_renderer.hpp"

namespace sky::render {

// Absolute slack of TemporalSettings::depthTolerance (m).
inline constexpr double kDepthToleranceSlack_m = 20;
// Height margin around a layer inside which a point moves with its wind (m):
// a cloud depth is a transmittance-weighted mean, which may lie just outside.
inline constexpr double kLayerWindMargin_m = 300;
// A change of tiles by more than this many of the map's 1/255 steps at a
// texel is a step, which redraws the frame whole; up to it, a ramp (a
// server's ramp moves coverage a few steps a frame at 30 frames/s: 0 to 1
// in 10 s is under 1), which keeps the history and is redrawn into it over
// one interleave cycle (docs/motion.md has both measured).
inline constexpr std::uint32_t kMaxRampStep = 16;
// (sqrt(5) - 1) / 2: the step-offset shift per cycle with accumulation.
inline constexpr double kGoldenRatioConjugate = 0.6180339887498949;

// The pixel of its n x n block a frame draws, for the frame's place in the
// cycle (0 .. n^2 - 1): ordered dispersed (Bayer), so consecutive frames
// draw far-apart pixels and any n^2 consecutive frames draw every pixel once.
glm::uvec2 interleavePhase(std::uint32_t n, std::uint32_t cycleIndex);

// The weather map's change since the previous frame, as the renderer knows
// it (WeatherTexture): the texel rectangles rewritten when only tiles
// changed (none when the map did not change), unset when it was rebuilt or
// is not known.
struct WeatherEdit {
  const WeatherField* field = nullptr;
  std::optional<std::vector<TexelRect>> rects;
  std::uint32_t largestStep = 0;  // WeatherMapReport::largestStep
};

struct TemporalPlan {
  bool drawWhole = true;   // no history: the cloud pass draws every pixel
  std::string reason;      // why, when drawWhole
  std::uint32_t interleave = 1;  // of this frame: the settings', 2 in a fast turn, 1 drawn whole
  glm::uvec2 phase{0};
  // Widths in pixels of the bands at the left, right, top and bottom edges
  // the frame draws at every pixel (fresh_edges.glsl): what came into view
  // since the previous frame. 0 without a history or with freshEdges off.
  glm::uvec4 freshEdges{0};
  std::uint32_t freshEdgePixels = 0;  // pixels in those bands
  // Where the changes of the weather's tiles of the last interleave cycle
  // show (history_drop.hpp): there a redraw replaces its history. Empty
  // cells when none.
  HistoryDrop drop;
  double turned_px = 0;  // how far the view turned since the previous frame, in pixels at the image's centre
  double jitterShift = 0;      // FrameSetup::jitterShift: the cycle's step-offset shift with accumulation
  glm::dvec2 pixelShift{0};    // FrameSetup::pixelShift: the cycle's ray-position shift with pixelJitter
  bool pixelJitter = false;
  gpu::SkyReproject params{};  // the reprojection pass's block (image.w = 1 when a history is used)
};

class TemporalPlanner {
 public:
  explicit TemporalPlanner(const TemporalSettings& settings) : settings_(settings) {}

  // Plans the frame with this setup (inputs: its clock and weather; edit:
  // how the weather map changed since the previous call) and remembers it
  // as the previous frame for the next call. Without an edit a change of
  // the weather's tiles redraws the frame whole.
  TemporalPlan plan(const FrameSetup& setup, const FrameInputs& inputs, const WeatherEdit& edit = {});
  // The settings of the frames from the next on (a frame budget's level):
  // the previous frame is kept, as a history of any interleave is a whole image.
  void setSettings(const TemporalSettings& settings) { settings_ = settings; }
  // Forgets the previous frame (after a frame that failed on the GPU, or on
  // a host's reset): the next frame is drawn whole, for `reason`.
  void forget(std::string reason = "first frame") {
    previous_.reset();
    recent_.clear();
    forgottenBecause_ = std::move(reason);
  }

 private:
  struct Remembered {
    glm::dvec3 cameraEcef_m{0};
    glm::dmat3 localToEcef{1};
    glm::dvec3 forward{0}, right{0}, down{0};  // local frame of that frame
    glm::dvec4 frustum{0};                     // FrameSetup::frustum
    glm::dvec3 keyLightEcef{0};
    bool moonLit = false;
    bool flashLit = false;  // a lightning flash lit the frame (its light changes from frame to frame)
    double clock_s = 0;
    std::uint64_t structureKey = 0;  // weatherStructureKey
    std::uint64_t contentKey = 0;    // weatherContentKey
    std::vector<int> layerSide;  // per layer: -1 under its base, 0 inside, 1 over its top
  };
  // The angle the view turned from `prev` to `now` (the rotation between the
  // two cameras' axes in ECEF, roll included), degrees.
  static double turn_deg(const Remembered& prev, const Remembered& now);
  // The fresh edges' widths for a frame with this setup drawing 1 pixel of
  // n x n after `prev`, within what the cloud pass's output can hold.
  static glm::uvec4 freshEdges(const Remembered& prev, const FrameSetup& setup, std::uint32_t n);
  // Why the history cannot be used for a frame after `prev`; empty when it can.
  std::string resetReason(const Remembered& prev, const Remembered& now) const;

  TemporalSettings settings_;
  std::optional<Remembered> previous_;
  // The keys of the last weather version seen (FrameInputs::weatherVersion).
  std::optional<std::uint64_t> keyVersion_;
  std::uint64_t versionStructureKey_ = 0, versionContentKey_ = 0;
  std::string forgottenBecause_ = "first frame";  // the reason of a frame without previous_
  std::uint64_t frames_ = 0;  // frames planned: the place in the interleave cycle (without patternIndex)
  // The changes of tiles of the last interleave cycle (their frame, the
  // map's texels they rewrote) and the map's anchor they refer to.
  struct RecentEdit {
    std::uint64_t frame = 0;
    std::vector<TexelRect> rects;
  };
  std::deque<RecentEdit> recent_;
  geo::Geodetic recentAnchor_;
};

}  // namespace sky::render
