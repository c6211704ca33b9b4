// Interleaved rendering with reprojection (TemporalSettings) on the GPU,
// against the same renderer drawing every pixel (interleave 1):
//  * a still view converges in n^2 frames to exactly the image drawn whole;
//  * under a turn, and under clouds moving with a 40 m/s wind, the
//    reprojected image is much closer to the whole image of the same frame
//    than the first frame is (what a history held still, without motion
//    vectors, would show);
//  * flying through a cumulus layer at 150 m/s, the error stays bounded;
//  * the history is dropped, and the frame drawn whole (bit-identical to the
//    whole image), on a teleport, a large turn, a clock jump, entering or
//    leaving a layer and a weather change (of the fine or the coarse snapshot);
//  * a ramp of tiles in part of the view keeps the history and is redrawn
//    into it within one cycle, where accumulation alone would lag.
#include <cmath>
#include <cstdio>
#include <cstring>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "scenes.hpp"
#include "sky/render/cloud_renderer.hpp"
#include "sky/render/presets.hpp"
#include "sky/weather/tiling.hpp"

namespace sky::test {
namespace {

constexpr std::uint32_t kW = 160, kH = 90;
// The motion tests use `high`: its per-pixel noise is small next to the
// errors measured (realtime's alone is ~4 % of a frame under motion).
constexpr const char* kMotionPreset = "high";

// Bounds on the displayed RMSE (scenes.hpp, Diff) of 4x4 block means of a
// reprojected frame against the whole frame, as a fraction of the whole
// frame's mean displayed value. Measured (lavapipe, this machine, `high`):
// turn 1.4 % after one frame, 4.5 % after 16 (the bilinear history blurs a
// little with every resampling); wind 1.1 % to 5.2 %; fly-through mean 1.0 %,
// worst 1.4 %.
constexpr double kTurnBound = 0.07;
constexpr double kWindBound = 0.08;
// The shear (AWindShearMovesEachPixelsHistoryByItsOwnWind): measured with
// each pixel's wind 0.49-0.51 of the error without motion from frame 4 on,
// worst 0.083; with the camera's wind for the whole view (nothing, over the
// line) 0.62-0.85, worst 0.118. The rest is the shear band, where the flow
// stretches the noise within a frame's step.
constexpr double kShearBetterThanStale = 0.6;
constexpr double kShearBound = 0.1;
constexpr double kFlyMeanBound = 0.02, kFlyWorstBound = 0.03;
// How much closer to the whole frame the reprojected one must be than the
// first frame (drawn whole) is: what interleaving without motion vectors,
// the history held still, would show.
constexpr double kBetterThanStale = 0.5;
// How much closer to the pixel-area average pixel jitter must bring a still
// view than centre samples (PixelJitterAveragesOverThePixel).
constexpr double kJitterGain = 0.8;

std::unique_ptr<render::CloudRenderer> makeRenderer(std::uint32_t interleave, const char* preset, std::string* skip) {
  render::RenderSettings s;
  s.width = kW;
  s.height = kH;
  s.march = render::findPreset(preset)->march;
  s.temporal.interleave = interleave;
  auto r = render::CloudRenderer::create(s);
  if (!r) {
    if (r.error().code == ErrorCode::NoDevice) *skip = describe(r.error());
    else ADD_FAILURE() << describe(r.error());
    return nullptr;
  }
  return std::move(*r);
}

#define SKY_TEMPORAL_RENDERERS(preset, n)                                          \
  std::string skip;                                                                \
  auto whole = makeRenderer(1, preset, &skip);                                     \
  auto interleaved = whole ? makeRenderer(n, preset, &skip) : nullptr;             \
  if (!whole || !interleaved) {                                                    \
    if (!skip.empty()) GTEST_SKIP() << skip;                                       \
    return;                                                                        \
  }

render::Image renderOk(render::CloudRenderer& r, const render::FrameInputs& in) {
  auto image = r.render(in);
  EXPECT_TRUE(image) << (image ? "" : describe(image.error()));
  return image ? std::move(*image) : render::Image{};
}

bool identical(const render::Image& a, const render::Image& b) {
  return a.rgba.size() == b.rgba.size() && !a.rgba.empty() &&
         std::memcmp(a.rgba.data(), b.rgba.data(), a.rgba.size() * sizeof(float)) == 0;
}

// The image averaged over 4x4 blocks: a march's per-pixel noise (its sample
// offsets belong to the pixel, not to the scene, so they do not move with a
// reprojected image) averages out; a misplaced image does not.
render::Image blockMean(const render::Image& a) {
  render::Image out;
  out.width = a.width / 4;
  out.height = a.height / 4;
  out.rgba.assign(std::size_t(out.width) * out.height * 4, 0.0f);
  for (std::uint32_t y = 0; y < out.height * 4; ++y)
    for (std::uint32_t x = 0; x < out.width * 4; ++x)
      for (int c = 0; c < 4; ++c)
        out.rgba[((y / 4) * out.width + x / 4) * 4 + c] += a.rgba[(std::size_t(y) * a.width + x) * 4 + c] / 16.0f;
  return out;
}

// Displayed RMSE over the mean displayed value, of the 4x4 block means.
double relativeError(const render::Image& test, const render::Image& truth) {
  const Diff d = diff(blockMean(test), blockMean(truth));
  return d.displayedRmse / std::max(d.displayedMean, 1e-9);
}

render::FrameInputs cumulusInputs(const weather::WeatherSnapshot& snap) {
  render::FrameInputs in;
  in.camera = pose(47.0, 8.0, 500.0, 0.0, 25.0);
  in.weather = &snap;
  in.sunAzimuth_deg = 135.0;
  in.sunElevation_deg = 60.0;
  return in;
}

weather::WeatherSnapshot cumulus(double windSpeed_mps = 0) {
  weather::WeatherSnapshot s;
  s.layers.push_back(layer(1, 1200.0, 1500.0, 0.45, 1.0));
  s.layers[0].wind.speed_mps = windSpeed_mps;
  s.layers[0].wind.fromDirection_deg = 270.0;
  return s;
}

// Renders the still view n^2 + 1 times: the history is full afterwards.
void converge(render::CloudRenderer& r, const render::FrameInputs& in, std::uint32_t n) {
  for (std::uint32_t i = 0; i <= n * n; ++i) renderOk(r, in);
}

// Two renderers of `s`: as it is, and with `change` made to its temporal
// settings (the tests that weigh one setting against its absence).
struct Variants {
  Result<std::unique_ptr<render::CloudRenderer>> as, changed;
};
Variants variants(render::RenderSettings s, const std::function<void(render::TemporalSettings&)>& change) {
  auto as = render::CloudRenderer::create(s);
  change(s.temporal);
  return {std::move(as), render::CloudRenderer::create(s)};
}

TEST(Temporal, StillViewConvergesToTheWholeImage) {
  for (std::uint32_t n : {2u, 4u}) {
    SCOPED_TRACE("interleave " + std::to_string(n));
    SKY_TEMPORAL_RENDERERS("high", n);
    const weather::WeatherSnapshot snap = cumulus();
    const render::FrameInputs in = cumulusInputs(snap);
    const render::Image truth = renderOk(*whole, in);
    const render::Image first = renderOk(*interleaved, in);
    EXPECT_TRUE(interleaved->lastTemporal().drawnWhole);
    EXPECT_EQ(interleaved->lastTemporal().reason, "first frame");
    EXPECT_TRUE(identical(first, truth));
    std::uint64_t drawn = 0;
    for (std::uint32_t f = 0; f < n * n; ++f) {
      const render::Image image = renderOk(*interleaved, in);
      const render::TemporalReport& t = interleaved->lastTemporal();
      EXPECT_FALSE(t.drawnWhole) << t.reason;
      // A still view: every pixel not drawn is reused, none upscaled.
      EXPECT_EQ(t.drawn + t.reused, std::uint64_t(kW) * kH);
      EXPECT_EQ(t.offscreen + t.disoccluded, 0u);
      drawn += t.drawn;
      // The history holds the whole image; each frame redraws part of it.
      EXPECT_TRUE(identical(image, truth)) << "frame " << f;
      EXPECT_EQ(image.cloudDepth_m, truth.cloudDepth_m) << "frame " << f;
    }
    EXPECT_EQ(drawn, std::uint64_t(kW) * kH);  // n^2 frames draw every pixel once
  }
}

// The image averaged over each pixel's area: drawn whole at kSuper times the
// size and box-filtered down.
constexpr std::uint32_t kSuper = 3;
render::Image boxDown(const render::Image& big, std::uint32_t k) {
  render::Image out;
  out.width = big.width / k;
  out.height = big.height / k;
  out.rgba.assign(std::size_t(out.width) * out.height * 4, 0.0f);
  const float w = 1.0f / float(k * k);
  for (std::uint32_t y = 0; y < out.height * k; ++y)
    for (std::uint32_t x = 0; x < out.width * k; ++x)
      for (int c = 0; c < 4; ++c)
        out.rgba[((y / k) * out.width + x / k) * 4 + c] += w * big.rgba[(std::size_t(y) * big.width + x) * 4 + c];
  return out;
}

// Pixel jitter with accumulation: the redraws of a still view go to other
// places in their pixels, so the accumulated image tends to the pixel-area
// average (anti-aliased cloud edges) instead of the centre sample. Against
// the image drawn at 3x3 the size and box-filtered down, the jittered one
// must be clearly closer than the same accumulation without jitter.
TEST(Temporal, PixelJitterAveragesOverThePixel) {
  std::string skip;
  render::RenderSettings big;
  big.width = kW * kSuper;
  big.height = kH * kSuper;
  big.march = render::findPreset("high")->march;
  auto super = render::CloudRenderer::create(big);
  if (!super) {
    if (super.error().code == ErrorCode::NoDevice) GTEST_SKIP() << describe(super.error());
    FAIL() << describe(super.error());
  }
  const weather::WeatherSnapshot snap = cumulus();
  const render::FrameInputs in = cumulusInputs(snap);
  const render::Image area = boxDown(renderOk(**super, in), kSuper);
  double err[2] = {0, 0};
  for (int jitter = 0; jitter <= 1; ++jitter) {
    render::RenderSettings s;
    s.width = kW;
    s.height = kH;
    s.march = big.march;
    s.temporal.interleave = 2;
    s.temporal.accumulation = 0.75;
    s.temporal.pixelJitter = jitter == 1;
    auto r = render::CloudRenderer::create(s);
    ASSERT_TRUE(r) << describe(r.error());
    render::Image image;
    for (std::uint32_t f = 0; f < render::historyWarmupFrames(s.temporal); ++f) image = renderOk(**r, in);
    err[jitter] = diff(image, area).displayedRmse;
    savePng(image, jitter ? "temporal_pixel_jitter.png" : "temporal_no_jitter.png");
  }
  std::printf("[ measured ] displayed RMSE against the 3x3 box-filtered image: centre %.5f, jittered %.5f\n", err[0],
              err[1]);
  EXPECT_LT(err[1], kJitterGain * err[0]);
}

// A turn at 45 deg/s for 16 frames seen through `frustum`: the reprojected
// frames against the whole ones (worst relative error, kTurnBound), each much
// better than the still history.
void checkTurn(std::optional<render::ViewFrustum> frustum, const char* name) {
  SKY_TEMPORAL_RENDERERS(kMotionPreset, 4);
  const weather::WeatherSnapshot snap = cumulus();
  render::FrameInputs in = cumulusInputs(snap);
  in.frustum = frustum;
  converge(*interleaved, in, 4);
  const render::Image still = renderOk(*whole, in);
  double worst = 0;
  std::uint64_t offscreen = 0;
  for (int f = 1; f <= 16; ++f) {
    in.camera.yaw_deg = 1.5 * f;  // 45 deg/s at 30 frames/s
    const render::Image truth = renderOk(*whole, in);
    const render::Image image = renderOk(*interleaved, in);
    EXPECT_FALSE(interleaved->lastTemporal().drawnWhole) << interleaved->lastTemporal().reason;
    offscreen += interleaved->lastTemporal().offscreen;
    const double e = relativeError(image, truth), stale = relativeError(still, truth);
    worst = std::max(worst, e);
    EXPECT_LT(e, kBetterThanStale * stale) << "frame " << f;
    std::printf("%s frame %d: reprojected %.4f, without motion %.4f\n", name, f, e, stale);
    if (f == 16) savePng(image, std::string("temporal_") + name + "_interleave4");
  }
  EXPECT_LT(worst, kTurnBound);
  EXPECT_GT(offscreen, 0u);  // the view's leading edge comes in from outside the history
  std::printf("%s: worst reprojected error %.4f\n", name, worst);
}

TEST(Temporal, TurnIsReprojected) { checkTurn(std::nullopt, "turn"); }

// A roll at 45 deg/s looking at the horizon, the rotation a glider's
// camera makes rolling into a thermal turn: 1.5 deg a frame is 2.25 pixels
// of this image, past the dense-turn threshold (TemporalSettings::denseTurn_px,
// 2), so the interleave-4 renderer draws 1 pixel of 4 on those frames. Its
// mean error against the frames drawn whole is lower than the same
// renderer's with the dense turn off (which upscales what comes into view
// from 1 pixel of 16), by at least a quarter, and within the turn's bound.
TEST(Temporal, FastRollDrawsDenser) {
  SKY_TEMPORAL_RENDERERS(kMotionPreset, 4);
  render::RenderSettings sparseSettings = interleaved->settings();
  sparseSettings.temporal.denseTurn_px = 0;
  auto sparse = render::CloudRenderer::create(sparseSettings);
  ASSERT_TRUE(sparse) << describe(sparse.error());
  const weather::WeatherSnapshot snap = cumulus();
  render::FrameInputs in = cumulusInputs(snap);
  in.camera = pose(47.0, 8.0, 500.0, 0.0, 5.0);
  converge(*interleaved, in, 4);
  converge(**sparse, in, 4);
  double dense = 0, coarse = 0;
  for (int f = 1; f <= 16; ++f) {
    in.camera.roll_deg = 1.5 * f;
    const render::Image truth = renderOk(*whole, in);
    dense += relativeError(renderOk(*interleaved, in), truth) / 16;
    EXPECT_EQ(interleaved->lastTemporal().interleave, 2u) << "frame " << f;
    EXPECT_FALSE(interleaved->lastTemporal().drawnWhole);
    coarse += relativeError(renderOk(**sparse, in), truth) / 16;
    EXPECT_EQ((*sparse)->lastTemporal().interleave, 4u) << "frame " << f;
  }
  std::printf("[ measured ] roll 45 deg/s: mean relative error %.4f dense, %.4f with 1 of 16\n", dense, coarse);
  EXPECT_LT(dense, 0.75 * coarse);
  EXPECT_LT(dense, kTurnBound);
  // Still again: back to 1 pixel of 16.
  renderOk(*interleaved, in);
  EXPECT_EQ(interleaved->lastTemporal().interleave, 4u);
}

// Fresh edges in a turn (yaw 3 pixels a frame at 1 pixel of 16, the dense
// turn off so the bands stand apart from the drawn pixels): every pixel of
// the reported bands is bit for bit the frame drawn whole (the same ray,
// the same step offsets), no pixel is upscaled for coming into view, the
// bands lie at the side the view turns towards,
// and the frames' mean error against the frames drawn whole is below the
// same renderer's without them, which upscales that side from 1 pixel of 16
// (by little: the bands are ~4 % of the image; measured 0.031 against 0.034).
TEST(Temporal, FreshEdgesAreDrawnAtEveryPixel) {
  SKY_TEMPORAL_RENDERERS(kMotionPreset, 4);
  render::RenderSettings s = interleaved->settings();
  s.temporal.denseTurn_px = 0;
  s.temporal.freshEdges = true;
  auto edged = render::CloudRenderer::create(s);
  s.temporal.freshEdges = false;
  auto upscaled = render::CloudRenderer::create(s);
  ASSERT_TRUE(edged && upscaled);
  const weather::WeatherSnapshot snap = cumulus();
  render::FrameInputs in = cumulusInputs(snap);
  converge(**edged, in, 4);
  converge(**upscaled, in, 4);
  const double pixel_deg = 60.0 / kH;
  double withEdges = 0, without = 0;
  for (int f = 1; f <= 8; ++f) {
    in.camera.yaw_deg = 3 * pixel_deg * f;
    const render::Image truth = renderOk(*whole, in);
    const render::Image image = renderOk(**edged, in);
    const render::TemporalReport& t = (*edged)->lastTemporal();
    ASSERT_FALSE(t.drawnWhole) << t.reason;
    EXPECT_EQ(t.freshEdges[0], 0u) << "frame " << f;  // turning right: nothing new on the left
    EXPECT_GE(t.freshEdges[1], 3u) << "frame " << f;
    EXPECT_EQ(t.offscreen, 0u) << "frame " << f << ": every pixel that came into view was drawn";
    std::uint64_t inBands = 0, equal = 0;
    for (std::uint32_t y = 0; y < kH; ++y)
      for (std::uint32_t x = 0; x < kW; ++x) {
        if (!(x < t.freshEdges[0] || x >= kW - t.freshEdges[1] || y < t.freshEdges[2] || y >= kH - t.freshEdges[3]))
          continue;
        ++inBands;
        const std::size_t i = std::size_t(y) * kW + x;
        bool same = image.cloudDepth_m[i] == truth.cloudDepth_m[i];
        for (int c = 0; c < 4; ++c) same = same && image.rgba[4 * i + c] == truth.rgba[4 * i + c];
        equal += same ? 1 : 0;
      }
    EXPECT_EQ(inBands, t.freshEdgePixels) << "frame " << f;
    EXPECT_EQ(equal, inBands) << "frame " << f << ": band pixels differing from the frame drawn whole";
    withEdges += relativeError(image, truth) / 8;
    without += relativeError(renderOk(**upscaled, in), truth) / 8;
    EXPECT_EQ((*upscaled)->lastTemporal().freshEdgePixels, 0u);
  }
  std::printf("[ measured ] yaw 3 px a frame: mean relative error %.4f with fresh edges, %.4f without\n", withEdges,
              without);
  EXPECT_LT(withEdges, without);
}

// The history resampled with Catmull-Rom weights (TemporalSettings::sharpHistory)
// in a slow yaw (1.2 pixels a frame, so 1 pixel of 16 is drawn and every
// other pixel is resampled from the last frame, for 16 frames): the frames'
// mean error against the frames drawn whole is below the bilinear
// history's, which blurs a little more each frame. A still view takes its
// pixels bit for bit either way (the exact-centre path).
TEST(Temporal, SharpHistoryBlursLessInATurn) {
  SKY_TEMPORAL_RENDERERS(kMotionPreset, 4);
  render::RenderSettings s = interleaved->settings();
  s.temporal.sharpHistory = true;
  auto sharp = render::CloudRenderer::create(s);
  ASSERT_TRUE(sharp) << describe(sharp.error());
  const weather::WeatherSnapshot snap = cumulus();
  render::FrameInputs in = cumulusInputs(snap);
  converge(*interleaved, in, 4);
  converge(**sharp, in, 4);
  EXPECT_TRUE(identical(renderOk(*interleaved, in), renderOk(**sharp, in))) << "a still view";
  const double pixel_deg = 60.0 / kH;
  double bilinear = 0, catmullRom = 0;
  for (int f = 1; f <= 16; ++f) {
    in.camera.yaw_deg = 1.2 * pixel_deg * f;
    const render::Image truth = renderOk(*whole, in);
    bilinear += relativeError(renderOk(*interleaved, in), truth) / 16;
    catmullRom += relativeError(renderOk(**sharp, in), truth) / 16;
    EXPECT_EQ((*sharp)->lastTemporal().interleave, 4u) << "frame " << f;
  }
  std::printf("[ measured ] yaw 1.2 px a frame: mean relative error %.4f bilinear, %.4f Catmull-Rom\n", bilinear,
              catmullRom);
  EXPECT_LT(catmullRom, bilinear);
}

// A banked turn across the horizon (roll 0.75 degrees a frame, the horizon
// at the image's middle, under scattered cumulus): ground and sky both have
// no cloud depth, so without horizonSides a pixel by the horizon takes
// history and drawn pixels from across it, and each frame's resampling
// smears the ground into the sky along it. With it the frames are closer to
// the frames drawn whole; a still view is bit for bit the same either way.
// Measured (lavapipe, `high`, sharp history): 0.0369 against 0.0466 (0.79x)
// over the whole image, whose cloud edges err the same either way; the
// rendering is deterministic, so the bound of 0.85x has room only for a
// change of the scene.
TEST(Temporal, HorizonSidesKeepGroundAndSkyApartInARoll) {
  SKY_TEMPORAL_RENDERERS(kMotionPreset, 4);
  render::RenderSettings s = interleaved->settings();
  s.temporal.sharpHistory = true;
  s.temporal.horizonSides = true;
  auto [sides, across] = variants(s, [](render::TemporalSettings& t) { t.horizonSides = false; });
  ASSERT_TRUE(sides && across);
  const weather::WeatherSnapshot snap = cumulus();
  render::FrameInputs in = cumulusInputs(snap);
  in.camera = pose(47.0, 8.0, 900.0, 0.0, 0.0);
  converge(**sides, in, 4);
  converge(**across, in, 4);
  EXPECT_TRUE(identical(renderOk(**sides, in), renderOk(**across, in))) << "a still view";
  double withSides = 0, without = 0;
  for (int f = 1; f <= 16; ++f) {
    in.camera.roll_deg = 0.75 * f;
    const render::Image truth = renderOk(*whole, in);
    withSides += relativeError(renderOk(**sides, in), truth) / 16;
    without += relativeError(renderOk(**across, in), truth) / 16;
    EXPECT_FALSE((*sides)->lastTemporal().drawnWhole) << "frame " << f;
  }
  std::printf("[ measured ] roll 0.75 deg a frame across the horizon: mean relative error %.4f on its side, "
              "%.4f across it\n",
              withSides, without);
  EXPECT_LT(withSides, 0.85 * without);
}

// How much the rows of an image differ from the mean of the rows above and
// below (the mean over pixels of |a(x, y) - (a(x, y - 1) + a(x, y + 1)) / 2|
// of the view-ray transmittance a): a comb of rows, as the streaks along
// the rows not drawn in a frame make, raises it; an edge across the rows
// does too, once, in the truth as well.
double rowComb(const render::Image& image) {
  double sum = 0;
  std::size_t n = 0;
  auto a = [&](std::uint32_t x, std::uint32_t y) { return double(image.rgba[(std::size_t(y) * image.width + x) * 4 + 3]); };
  for (std::uint32_t y = 1; y + 1 < image.height; ++y)
    for (std::uint32_t x = 0; x < image.width; ++x, ++n) sum += std::abs(a(x, y) - 0.5 * (a(x, y - 1) + a(x, y + 1)));
  return sum / double(std::max<std::size_t>(n, 1));
}

// A banked turn under cumulus (roll 30 degrees, yawing 1.5 degrees a frame,
// past the dense turn's 2 pixels: 1 pixel of 4 drawn), `medium`'s temporal
// settings. Each frame's resampling of the history blends the rows it falls
// between, so at a cloud's edge a pixel left to the history took a blend of
// cloud and sky and the next frames carried it on: streaks of cloud into
// the sky along the rows not drawn that frame, a comb of rows the truth
// does not have. The history clip (historyClip 4) puts a history whose
// transmittance none of the four drawn pixels round it has back into their
// box. Measured (lavapipe, `high`'s march, 24 frames): the comb over the
// truth's 0.0030 without the clip, -0.0012 with it (the truth's own march
// noise is the rest); a still view is bit for bit the same either way (the
// clip applies only in motion). The last frames are in the test output
// (temporal_clip_on/off/truth.png).
TEST(Temporal, HistoryClipKeepsTheSkyClearAtCloudEdgesInABankedTurn) {
  SKY_TEMPORAL_RENDERERS(kMotionPreset, 4);
  render::RenderSettings s = interleaved->settings();
  s.temporal = render::findPreset("medium")->temporal;
  s.temporal.historyClip = 4;
  auto [clipped, unclipped] = variants(s, [](render::TemporalSettings& t) { t.historyClip = 0; });
  ASSERT_TRUE(clipped && unclipped);
  const weather::WeatherSnapshot snap = cumulus();
  render::FrameInputs in = cumulusInputs(snap);
  in.camera.roll_deg = 30.0;
  converge(**clipped, in, 4);
  converge(**unclipped, in, 4);
  EXPECT_TRUE(identical(renderOk(**clipped, in), renderOk(**unclipped, in))) << "a still view";
  double withClip = 0, without = 0;
  const int frames = 24;
  for (int f = 1; f <= frames; ++f) {
    in.camera.yaw_deg = 1.5 * f;
    const render::Image truth = renderOk(*whole, in);
    const render::Image a = renderOk(**clipped, in), b = renderOk(**unclipped, in);
    withClip += (rowComb(a) - rowComb(truth)) / frames;
    without += (rowComb(b) - rowComb(truth)) / frames;
    if (f == frames) savePng(a, "temporal_clip_on"), savePng(b, "temporal_clip_off"), savePng(truth, "temporal_clip_truth");
    EXPECT_FALSE((*clipped)->lastTemporal().drawnWhole) << "frame " << f;
  }
  std::printf("[ measured ] banked turn: the rows' comb over the truth's %.5f with the clip, %.5f without\n",
              withClip, without);
  EXPECT_GT(without, 0.0015) << "the scene no longer shows the streaks the test is about";
  EXPECT_LT(withClip, 0.3 * without);
}

// Accumulation in a slow turn (yaw at 1.2 pixels a frame, under the dense
// turn's 2, so 1 pixel of 16 is drawn): with the history's share falling to
// half at 1 pixel of motion (TemporalSettings::accumulationMotion_px), a
// redraw keeps 0.375 of its history and the mean error against the frames
// drawn whole is lower than with the share held at 0.75, where a fresh
// sample is held back by the resampled history for more frames.
// A still view accumulates as before (share 0.75, moved 0 pixels): its
// redraws converge on the image drawn whole.
TEST(Temporal, AccumulationYieldsToMotion) {
  std::string skip;
  auto whole = makeRenderer(1, kMotionPreset, &skip);
  if (!whole) {
    if (!skip.empty()) GTEST_SKIP() << skip;
    return;
  }
  render::RenderSettings s = whole->settings();
  s.temporal.interleave = 4;
  s.temporal.accumulation = 0.75;
  auto [yielding, holding] = variants(s, [](render::TemporalSettings& t) { t.accumulationMotion_px = 0; });
  ASSERT_TRUE(yielding && holding);
  const weather::WeatherSnapshot snap = cumulus();
  render::FrameInputs in = cumulusInputs(snap);
  for (int i = 0; i < 40; ++i) renderOk(**yielding, in), renderOk(**holding, in);
  const double stillYield = relativeError(renderOk(**yielding, in), renderOk(*whole, in));
  const double stillHold = relativeError(renderOk(**holding, in), renderOk(*whole, in));
  EXPECT_NEAR(stillYield, stillHold, 1e-6) << "a still view accumulates the same either way";
  double yield = 0, hold = 0;
  const double pixel_deg = 60.0 / kH;
  for (int f = 1; f <= 24; ++f) {
    in.camera.yaw_deg = 1.2 * pixel_deg * f;
    const render::Image truth = renderOk(*whole, in);
    yield += relativeError(renderOk(**yielding, in), truth) / 24;
    EXPECT_EQ((*yielding)->lastTemporal().interleave, 4u);
    hold += relativeError(renderOk(**holding, in), truth) / 24;
  }
  std::printf("[ measured ] slow turn: mean relative error %.4f yielding, %.4f holding 0.75\n", yield, hold);
  EXPECT_LT(yield, 0.95 * hold);
}

// The same turn seen by a right-hand side channel (View Definition -5..55
// deg horizontally, 25 up, -10 down): the reprojection projects into the
// previous frame through the same off-axis frustum (core_common.glsl,
// frustumPixel), so its error stays within the symmetric view's bound. A
// still off-axis view converges to its whole image bit for bit.
TEST(Temporal, OffAxisTurnIsReprojected) {
  const render::ViewFrustum side{-5, 55, 25, -10};
  checkTurn(side, "offaxis_turn");
  SKY_TEMPORAL_RENDERERS("high", 2);
  const weather::WeatherSnapshot snap = cumulus();
  render::FrameInputs in = cumulusInputs(snap);
  in.frustum = side;
  const render::Image truth = renderOk(*whole, in);
  converge(*interleaved, in, 2);
  const render::Image image = renderOk(*interleaved, in);
  EXPECT_EQ(interleaved->lastTemporal().drawn + interleaved->lastTemporal().reused, std::uint64_t(kW) * kH);
  EXPECT_TRUE(identical(image, truth));
}

TEST(Temporal, WindMovesTheHistoryWithTheClouds) {
  SKY_TEMPORAL_RENDERERS(kMotionPreset, 4);
  const weather::WeatherSnapshot snap = cumulus(40.0);
  render::FrameInputs in = cumulusInputs(snap);
  // Looking north; the wind from the west moves the clouds to the right.
  converge(*interleaved, in, 4);
  const render::Image still = renderOk(*whole, in);
  double worst = 0;
  for (int f = 1; f <= 16; ++f) {
    in.weatherClock_s = 1.0 * f;  // 40 m per frame
    const render::Image truth = renderOk(*whole, in);
    const render::Image image = renderOk(*interleaved, in);
    EXPECT_FALSE(interleaved->lastTemporal().drawnWhole) << interleaved->lastTemporal().reason;
    const double e = relativeError(image, truth), stale = relativeError(still, truth);
    worst = std::max(worst, e);
    EXPECT_LT(e, kBetterThanStale * stale) << "frame " << f;
    std::printf("wind frame %d: reprojected %.4f, without motion %.4f\n", f, e, stale);
  }
  EXPECT_LT(worst, kWindBound);
  std::printf("wind: worst reprojected error %.4f\n", worst);
}

// A wind that varies across the view: looking straight down from 12 km on a
// deck 10 km below (~12 km of it across the image), the clouds west of the
// camera's meridian move north at 40 m/s, those east of it south, and the
// camera is over the line, where the wind is nothing. Each pixel's history
// moves by the wind at its own point (the wind map, as the cloud pass reads
// it); one wind for the whole view (the camera's) would leave it in place.
TEST(Temporal, AWindShearMovesEachPixelsHistoryByItsOwnWind) {
  SKY_TEMPORAL_RENDERERS(kMotionPreset, 4);
  weather::WeatherSnapshot snap;
  snap.layers.push_back(layer(1, 1500.0, 1000.0, 0.5, 1.0));
  snap.windTileLevel = 12;
  for (std::uint64_t cell : weather::coverCap({47.0, 8.0, 60000}, 12, 100000)) {
    const weather::CellCentre c = weather::cellCentre(cell);
    snap.windTiles.push_back({cell, 1, 0.0f, c.lon_deg < 8.0 ? 40.0f : -40.0f, 0.0f});
  }
  render::FrameInputs in;
  in.camera = pose(47.0, 8.0, 12000.0, 0.0, -90.0);
  in.weather = &snap;
  in.sunAzimuth_deg = 135.0;
  in.sunElevation_deg = 60.0;
  in.weatherClock_s = 200;  // in a plateau of the noise's flow
  converge(*interleaved, in, 4);
  const render::Image still = renderOk(*whole, in);
  double worst = 0;
  for (int f = 1; f <= 12; ++f) {
    in.weatherClock_s = 200 + 1.0 * f;
    const render::Image truth = renderOk(*whole, in);
    const render::Image image = renderOk(*interleaved, in);
    EXPECT_FALSE(interleaved->lastTemporal().drawnWhole) << interleaved->lastTemporal().reason;
    const double e = relativeError(image, truth), stale = relativeError(still, truth);
    worst = std::max(worst, e);
    if (f >= 4) {
      EXPECT_LT(e, kShearBetterThanStale * stale) << "frame " << f;
    }
    std::printf("shear frame %d: reprojected %.4f, without motion %.4f\n", f, e, stale);
  }
  EXPECT_LT(worst, kShearBound);
}

TEST(Temporal, FlyingThroughCloudStaysBounded) {
  SKY_TEMPORAL_RENDERERS(kMotionPreset, 4);
  const weather::WeatherSnapshot snap = cumulus();
  render::FrameInputs in = cumulusInputs(snap);
  in.camera = pose(47.0, 8.0, 2000.0, 90.0, 2.0);  // inside the layer (1.2-2.7 km), flying east
  converge(*interleaved, in, 4);
  const double lon0 = in.camera.position.lon_deg;
  const double metresPerDegree = 111195.0 * std::cos(47.0 * std::acos(-1.0) / 180.0);
  double sum = 0, worst = 0;
  const int frames = 30;
  for (int f = 1; f <= frames; ++f) {
    in.camera.position.lon_deg = lon0 + 5.0 * f / metresPerDegree;  // 150 m/s at 30 frames/s
    const render::Image truth = renderOk(*whole, in);
    const render::Image image = renderOk(*interleaved, in);
    EXPECT_FALSE(interleaved->lastTemporal().drawnWhole) << interleaved->lastTemporal().reason;
    const double e = relativeError(image, truth);
    sum += e;
    worst = std::max(worst, e);
    if (f == frames) savePng(image, "temporal_fly_through_interleave4"), savePng(truth, "temporal_fly_through_whole");
  }
  std::printf("fly-through: mean reprojected error %.4f, worst %.4f\n", sum / frames, worst);
  EXPECT_LT(sum / frames, kFlyMeanBound);
  EXPECT_LT(worst, kFlyWorstBound);
}

TEST(Temporal, HistoryIsDroppedWhenItCannotHold) {
  SKY_TEMPORAL_RENDERERS(kMotionPreset, 4);
  const weather::WeatherSnapshot snap = cumulus(10.0);
  weather::WeatherSnapshot thicker = snap;
  thicker.layers[0].coverage = 0.6;
  // A coarse snapshot for the far ring (FrameInputs::coarseWeather) is
  // weather too: one tile of the layer 300 km north.
  weather::WeatherSnapshot coarse;
  coarse.tileLevel = 9;
  coarse.layers = snap.layers;
  coarse.tiles.push_back({weather::cellAt(47.0 + 300000.0 / 111195.0, 8.0, 9), 1, 0.9f, 1.0f});
  struct Case {
    const char* expect;  // the start of the reason
    std::function<void(render::FrameInputs&)> change;
  };
  const Case cases[] = {
      {"camera moved", [](render::FrameInputs& in) { in.camera.position.lat_deg += 0.05; }},
      {"view turned", [](render::FrameInputs& in) { in.camera.yaw_deg += 45.0; }},
      {"weather clock stepped", [](render::FrameInputs& in) { in.weatherClock_s += 60.0; }},
      {"camera entered cloud layer 0", [](render::FrameInputs& in) { in.camera.position.alt_m = 1300.0; }},
      {"key light moved", [](render::FrameInputs& in) { in.sunElevation_deg -= 5.0; }},
      {"weather changed", [&](render::FrameInputs& in) { in.weather = &thicker; }},
      {"weather changed", [&](render::FrameInputs& in) { in.coarseWeather = &coarse; }},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(c.expect);
    render::FrameInputs in = cumulusInputs(snap);
    converge(*interleaved, in, 1);
    EXPECT_FALSE(interleaved->lastTemporal().drawnWhole);
    c.change(in);
    const render::Image image = renderOk(*interleaved, in);
    const render::TemporalReport& t = interleaved->lastTemporal();
    EXPECT_TRUE(t.drawnWhole);
    EXPECT_EQ(t.reason.rfind(c.expect, 0), 0u) << t.reason;
    EXPECT_TRUE(identical(image, renderOk(*whole, in)));
  }
  // Leaving the layer again.
  render::FrameInputs in = cumulusInputs(snap);
  in.camera.position.alt_m = 1300.0;
  converge(*interleaved, in, 1);
  in.camera.position.alt_m = 1150.0;
  renderOk(*interleaved, in);
  EXPECT_EQ(interleaved->lastTemporal().reason, "camera left cloud layer 0");
}

// A storm cell of 6 km, 25 km ahead on the left, ramps from coverage 0.5 to
// 0.95 in 9 frames (13 of the map's 1/255 steps a frame; the layer tiled at
// level 12 round the camera). The interleaved renderer (1 pixel of 16,
// accumulation 0.5) keeps its history through the ramp, marking part of
// the view until a cycle of 16 frames after its last change. After that
// cycle the error against the whole image of the new weather, above the
// renderer's own once converged, is under kTileChangeGain of what it was at
// the ramp's end: a redraw there replaces its history. Accumulating into it
// instead leaves about a third (measured 0.35 of it; replacing, 0.10).
constexpr double kTileChangeGain = 0.3;

TEST(Temporal, ARampOfTilesIsRedrawnWithinACycle) {
  std::string skip;
  auto whole = makeRenderer(1, kMotionPreset, &skip);
  if (!whole) {
    if (!skip.empty()) GTEST_SKIP() << skip;
    return;
  }
  render::RenderSettings s;
  s.width = kW;
  s.height = kH;
  s.march = render::findPreset(kMotionPreset)->march;
  s.temporal.interleave = 4;
  s.temporal.accumulation = 0.5;
  auto created = render::CloudRenderer::create(s);
  ASSERT_TRUE(created) << describe(created.error());
  render::CloudRenderer& interleaved = **created;
  auto cell = [](float inside) {
    return discSnapshot(layer(1, 1200.0, 1800.0, 0.5, 1.0), {46.0, 13.0, 0.0}, 60000.0, 46.2, 12.85, 6000.0, inside,
                        0.5f);
  };
  std::vector<weather::WeatherSnapshot> ramp;
  for (int k = 0; k <= 9; ++k) ramp.push_back(cell(0.5f + 0.05f * float(k)));
  render::FrameInputs in;
  in.camera = pose(46.0, 13.0, 800.0, 0.0, 8.0);
  in.sunAzimuth_deg = 150.0;
  in.sunElevation_deg = 45.0;
  in.weather = &ramp[0];
  const std::uint32_t warmup = render::historyWarmupFrames(s.temporal);
  for (std::uint32_t i = 0; i < warmup; ++i) renderOk(interleaved, in);
  render::Image atEnd;
  double fraction = 0;
  for (int k = 1; k <= 9; ++k) {
    in.weather = &ramp[std::size_t(k)];
    atEnd = renderOk(interleaved, in);
    const render::TemporalReport& t = interleaved.lastTemporal();
    EXPECT_FALSE(t.drawnWhole) << "ramp frame " << k << ": " << t.reason;
    EXPECT_GT(t.weatherChangedFraction, 0.0) << k;
    EXPECT_LT(t.weatherChangedFraction, 0.5) << k;
    fraction = t.weatherChangedFraction;
  }
  const render::Image truth = renderOk(*whole, in);
  render::Image last;
  for (int f = 1; f <= 16; ++f) {
    last = renderOk(interleaved, in);
    EXPECT_EQ(interleaved.lastTemporal().weatherChangedFraction > 0.0, f < 16) << "frame " << f << " after the ramp";
  }
  EXPECT_FALSE(interleaved.lastTemporal().drawnWhole);
  // The renderer's own error on the still view of the new weather once its
  // accumulation has converged: what the change's error falls back to.
  render::Image converged;
  for (std::uint32_t i = 0; i < warmup; ++i) converged = renderOk(interleaved, in);
  const double e0 = relativeError(converged, truth);
  const double e1 = relativeError(atEnd, truth), e16 = relativeError(last, truth);
  std::printf("[ tiles    ] a cell ramping 0.5 -> 0.95 on %.1f %% of the view: error %.2f %% at the ramp's end, "
              "%.2f %% a cycle later, %.2f %% converged\n",
              100 * fraction, 100 * e1, 100 * e16, 100 * e0);
  EXPECT_GT(e1, 1.5 * e0) << "the change shows";
  EXPECT_LT(e16 - e0, kTileChangeGain * (e1 - e0));
}

TEST(Temporal, SettingsOutOfRangeAreRefused) {
  render::RenderSettings s;
  s.width = kW;
  s.height = kH;
  s.temporal.interleave = 3;
  auto r = render::CloudRenderer::create(s);
  ASSERT_FALSE(r);
  EXPECT_NE(r.error().detail.find("temporal.interleave 3"), std::string::npos) << r.error().detail;
  s.temporal.interleave = 4;
  s.temporal.depthTolerance = 0;
  r = render::CloudRenderer::create(s);
  ASSERT_FALSE(r);
  EXPECT_NE(r.error().detail.find("temporal.depthTolerance"), std::string::npos) << r.error().detail;
}

}  // namespace
}  // namespace sky::test
