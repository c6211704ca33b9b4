// Reprojection pass: builds this frame's full image from the pixels the
// cloud pass drew (one of each n x n block, packed) and the previous frame's
// full image. A drawn pixel is taken as drawn. Any other pixel is looked up
// in the previous frame where its point was then: the point at the cloud
// depth along its ray (at infinity where there is no cloud), moved back by
// the wind of the layer it lies in, seen from the previous camera. The
// history is taken when its cloud depth there agrees with that point's
// distance from the previous camera; otherwise (disocclusion, a point
// outside the previous view) the pixel is upscaled from this frame's drawn
// pixels. A redraw keeps less of its history the further its point moved
// (TemporalSettings::accumulationMotion_px). With a history clip
// (TemporalSettings::historyClip), in motion the history a pixel takes is
// first clipped to the box the pixels drawn this frame around it span
// (history_clip.glsl). Layout: include/reproject_shared.h; the CPU side decides when the
// history is dropped altogether (temporal_plan.cpp). Where a change of the
// weather's tiles shows (history_drop.hpp), a redrawn pixel replaces its
// history instead of accumulating into it, so what changed is current
// after one cycle of n^2 frames.
#version 450
#extension GL_GOOGLE_include_directive : require

#include "reproject_shared.h"
#include "sky_shared.h"

layout(local_size_x = kReprojectLocalSizeX, local_size_y = kReprojectLocalSizeY) in;

// TemporalSettings::historyClip > 0: the clip's code is compiled in (a
// specialisation constant, as lavapipe runs every branch for every lane).
layout(constant_id = 0) const bool kHistoryClip = false;
// TemporalSettings::sharpHistory: the history resampled with Catmull-Rom
// weights over 4 x 4 pixels instead of bilinearly (compiled in only then).
layout(constant_id = 1) const bool kSharpHistory = false;
// TemporalSettings::freshEdges: the fresh edges' lookup is compiled in only
// then (no preset uses them, and every pixel would pay for it).
layout(constant_id = 2) const bool kFreshEdges = false;

layout(std430, set = 0, binding = kReprojectBindingParams) readonly buffer ParamsBlock { SkyReproject params; };
// What it gathers from is in storage images (renderer/core/src/pixel_mirror.hpp:
// llvmpipe loads a storage buffer at per-lane indices one lane and one
// component at a time, with branches; an image texel whole).
layout(set = 0, binding = kReprojectBindingFresh, rgba32f) uniform readonly image2D freshImage;  // packed: texel (b.x, b.y)
layout(set = 0, binding = kReprojectBindingFreshDepth, r32f) uniform readonly image2D freshDepthImage;
layout(set = 0, binding = kReprojectBindingHistory, rgba32f) uniform readonly image2D historyImage;
layout(set = 0, binding = kReprojectBindingHistoryDepth, r32f) uniform readonly image2D historyDepthImage;
layout(std430, set = 0, binding = kReprojectBindingOut) writeonly buffer OutBlock { vec4 outPixels[]; };
layout(std430, set = 0, binding = kReprojectBindingOutDepth) writeonly buffer OutDepthBlock { float outDepth[]; };
layout(std430, set = 0, binding = kReprojectBindingOutcomes) writeonly buffer OutcomeBlock { uint outcomes[]; };
layout(std430, set = 0, binding = kReprojectBindingDrop) readonly buffer DropBlock { uint dropCells[]; };

#define real float
#define real2 vec2
#define real3 vec3
#define real4 vec4
#define real3x3 mat3
#define SKY_CORE_CONST const
#include "core_common.glsl"
#include "history_clip.glsl"
#include "wind_map.glsl"

layout(set = 0, binding = kReprojectBindingWeather) uniform sampler2DArray weatherTex;
mat3 gCamToAnchor;
vec4 gCamInAnchor;
float gMapScale;
vec4 gRings;
vec4 gLayerWind[kReprojectMaxLayers];
#include "weather_map.glsl"
#include "fresh_edges.glsl"

// The block's numbers, read once at the start of main: storage loads are
// gathers on lavapipe (clouds.comp says more), and the per-tap tests below
// would otherwise reload them for every tap.
uvec2 gSize;   // image width, height
vec2 gRaster;  // the image's extent for the camera rays (SkyReproject::raster)
uint gN;       // interleave
int gShift;    // log2(gN): n is 1, 2 or 4, and vector integer division is slow on the CPU
uvec2 gPhase;  // this frame's drawn pixel in each block
vec3 gForward, gRight, gDown;              // this camera
vec3 gPrevForward, gPrevRight, gPrevDown;  // the previous camera
vec3 gPrevPosition;
float gRadius;
float gGroundC;      // the ground sphere's constant c (core_common.glsl's rayMeetsSphere)
bool gHorizonSides;  // TemporalSettings::horizonSides: take and blend only pixels on the pixel's side of the horizon
bool gPixelGround;   // whether this invocation's pixel looks at the ground (set in resolvePixel)
vec4 gFrustum, gPrevFrustum;  // this frame's and the previous frame's view frusta
float gRelTolerance, gAbsTolerance, gBandMargin;
float gAccumulation;  // the history's share of a redrawn pixel
float gClipGamma;     // the history clip's gamma (0: off)
bool gClip;           // clip the history this frame: gamma > 0 and the view not still
float gAccumulationMotion;  // pixels of motion at which a redraw keeps half its history's share (0: share constant)
uint gLayers;
vec4 gBand[kReprojectMaxLayers];
vec3 gMotion[kReprojectMaxLayers];
bool gHasHistory;
uint gHistoryTries;  // 2 with a history: from the frame, so the loop over them stays a loop (reuseHistory)
uvec4 gEdges;      // the fresh edges' widths (SkyReproject::freshEdges)
uint gEdgeBase;    // where in the packed image their samples start (after the drawn pixels)
float gPackedW;    // the packed image's width
bool gStill;  // neither the camera nor any layer's air moved since the previous frame
bool gDrop;   // the history-drop mask is set this frame (SkyReproject::drop)
// Its cells across and down, log2 of a cell's edge in pixels.
uvec4 gDropGrid;

// The drawn pixel of block b, when it lies inside the image; texel: where
// the packed image holds it.
bool drawnPixel(ivec2 b, out ivec2 texel) {
  ivec2 px = (b << gShift) + ivec2(gPhase);
  texel = b;
  return b.x >= 0 && b.y >= 0 && px.x < int(gSize.x) && px.y < int(gSize.y);
}

vec4 freshAt(ivec2 texel) { return imageLoad(freshImage, texel); }
float freshDepthAt(ivec2 texel) { return imageLoad(freshDepthImage, texel).x; }
vec4 historyAtPixel(ivec2 c) { return imageLoad(historyImage, c); }
float historyDepthAtPixel(ivec2 c) { return imageLoad(historyDepthImage, c).x; }

// Ground and sky both have no cloud depth (0), so the depth test alone lets
// a pixel take history or blend drawn pixels from across the horizon, and
// each frame's resampling then smears the one into the other along it (the
// band of streaks on a banked horizon, docs/motion.md). With
// gHorizonSides a pixel takes only what lies on its own side: a history
// pixel's side from the previous camera's ray through it, a drawn pixel's
// from this camera's; the upscale pass sorts its taps the same way.
bool historySideAgrees(ivec2 c) {
  if (!gHorizonSides) return true;
  vec2 s = frustumPoint(gPrevFrustum, float(c.x) + 0.5, float(c.y) + 0.5, gRaster.x, gRaster.y);
  return rayFromMeetsSphere(gPrevPosition, gPrevForward + gPrevRight * s.x - gPrevDown * s.y, gRadius, gGroundC) ==
         gPixelGround;
}

bool drawnSideAgrees(ivec2 px) {
  if (!gHorizonSides) return true;
  vec2 s = frustumPoint(gFrustum, float(px.x) + 0.5, float(px.y) + 0.5, gRaster.x, gRaster.y);
  return rayMeetsSphere(gForward + gRight * s.x - gDown * s.y, gRadius, gGroundC) == gPixelGround;
}

// This frame's drawn pixels interpolated at pixel px (bilinear over the grid
// of drawn pixels, each block's drawn pixel at b * n + phase); depth from the
// nearest of them.
void upscale(ivec2 px, out vec4 colour, out float depth) {
  vec2 g = (vec2(px) - vec2(gPhase)) / float(gN);
  ivec2 b0 = ivec2(floor(g));
  vec2 f = g - vec2(b0);
  colour = vec4(0.0);
  depth = 0.0;
  float wsum = 0.0, best = -1.0;
  for (int k = 0; k < 4; ++k) {
    ivec2 o = ivec2(k & 1, k >> 1);
    ivec2 i;
    if (!drawnPixel(b0 + o, i)) continue;
    float w = (o.x == 1 ? f.x : 1.0 - f.x) * (o.y == 1 ? f.y : 1.0 - f.y);
    // A drawn pixel across the horizon weighs (almost) nothing: where all
    // four are across it (a sliver of the horizon), they blend as before.
    w *= drawnSideAgrees(((b0 + o) << gShift) + ivec2(gPhase)) ? 1.0 : 1e-6;
    colour += w * freshAt(i);
    wsum += w;
    if (w > best) best = w, depth = freshDepthAt(i);
  }
  if (wsum > 0.0) colour /= wsum;
}

// Cloud depths that agree: both none, or both some and within tolerance.
bool agree(float a, float b) {
  if (a <= 0.0 || b <= 0.0) return a <= 0.0 && b <= 0.0;
  return abs(a - b) <= gRelTolerance * max(a, b) + gAbsTolerance;
}

// Where in the previous image (continuous pixel coordinates, pixel centres
// at +0.5) the point along dir at cloud depth d was, and its distance from
// the previous camera then (0 for no cloud: a direction at infinity, which
// only the rotation moves). False when it was behind the previous camera.
bool previousPixel(vec3 dir, float d, out vec2 p, out float expected) {
  vec3 v = dir;
  expected = 0.0;
  if (d > 0.0) {
    vec3 x = dir * d;
    float h = heightAboveCameraSphere(x, gRadius);
    vec3 motion = vec3(0.0);
    vec4 wind = vec4(0.0);
    // A constant trip count, so the loop unrolls and the arrays stay in
    // registers; the first band that holds the point wins.
    bool found = false;
    for (uint l = 0u; l < kReprojectMaxLayers; ++l) {
      bool inside = l < gLayers && h >= gBand[l].x - gBandMargin && h <= gBand[l].y + gBandMargin;
      motion = (inside && !found) ? gMotion[l] : motion;
      wind = (inside && !found) ? gLayerWind[l] : wind;
      found = found || inside;
    }
    // A layer whose wind varies: the air at x moved with the wind there.
    if (wind.y > 0.5)
      motion = mapWindLocal(wind.x, x, vec3(motion.xy / max(wind.z, 1e-6), 0.0)) * wind.z + vec3(0.0, 0.0, motion.z);
    v = x - motion - gPrevPosition;
    expected = length(v);
  }
  float z = dot(v, gPrevForward);
  if (z <= 0.0) return false;
  vec2 s = vec2(dot(v, gPrevRight), -dot(v, gPrevDown)) / z;
  p = frustumPixel(gPrevFrustum, s, gRaster.x, gRaster.y);
  return true;
}

bool insideImage(ivec2 q) { return q.x >= 0 && q.y >= 0 && q.x < int(gSize.x) && q.y < int(gSize.y); }


// Catmull-Rom weights of the taps at -1, 0, 1 and 2 for a position t in
// [0, 1) past tap 0: they sum to 1 and keep a linear ramp, and resampling
// with them every frame blurs far less than bilinear weights do.
vec4 catmullRom(float t) {
  float t2 = t * t, t3 = t2 * t;
  return vec4(-0.5 * t3 + t2 - 0.5 * t, 1.5 * t3 - 2.5 * t2 + 1.0, -1.5 * t3 + 2.0 * t2 + 0.5 * t, 0.5 * t3 - 0.5 * t2);
}

// historyAt's resampling with kSharpHistory: Catmull-Rom over the 4 x 4
// taps round i0 + f whose depth agrees, renormalised over them, and held
// within the range of the four nearest agreeing taps (the negative lobes
// would otherwise ring at a cloud's edge). Accepted, and the depth blended,
// as the bilinear lookup: over the four nearest taps.
bool sharpHistoryAt(ivec2 i0, vec2 f, float expected, out vec4 colour, out float seenDepth) {
  vec4 wx = catmullRom(f.x), wy = catmullRom(f.y);
  colour = vec4(0.0);
  seenDepth = 0.0;
  vec4 lo = vec4(3.0e38), hi = vec4(-3.0e38);
  float wsum = 0.0, inner = 0.0;
  // The horizon is a gentle curve at the scale of the 4 x 4 taps: when the
  // four corner taps lie on the pixel's side, all sixteen do, and only the
  // taps of a footprint the horizon crosses are tested one by one.
  bool oneSide = historySideAgrees(i0 - 1) && historySideAgrees(i0 + ivec2(2, -1)) &&
                 historySideAgrees(i0 + ivec2(-1, 2)) && historySideAgrees(i0 + 2);
  for (int k = 0; k < 16; ++k) {
    ivec2 o = ivec2(k & 3, k >> 2) - 1;
    ivec2 c = i0 + o;
    if (!insideImage(c)) continue;
    float hd = historyDepthAtPixel(c);
    if (!agree(hd, expected) || !(oneSide || historySideAgrees(c))) continue;
    vec4 v = historyAtPixel(c);
    float w = wx[o.x + 1] * wy[o.y + 1];
    colour += w * v;
    wsum += w;
    if (o.x >= 0 && o.x <= 1 && o.y >= 0 && o.y <= 1) {
      float b = (o.x == 1 ? f.x : 1.0 - f.x) * (o.y == 1 ? f.y : 1.0 - f.y);
      seenDepth += b * hd;
      inner += b;
      lo = min(lo, v);
      hi = max(hi, v);
    }
  }
  if (inner < 0.5 || wsum < 0.25) return false;
  colour = clamp(colour / wsum, lo, hi);
  seenDepth /= inner;
  return true;
}

// The history at continuous position p, bilinear over the taps whose depth
// agrees with `expected`; exactly the nearest pixel when p is (within 1e-3
// px) a pixel centre, so a still view keeps its pixels bit for bit. That
// case returns early: lavapipe then skips the resampling's loads for the
// lanes that took it (snapping the fraction to 0 and resampling instead
// gives the same pixels and cost a still 1280x720 `realtime` frame 7 ms,
// docs/light-transport.md). False unless the agreeing taps hold at least
// half the bilinear weight (else a neighbour with a sliver of weight would
// stand in for a pixel that shows something else).
// seenDepth: the history's cloud depth there, blended as the colour (0
// where no tap that agreed saw cloud).
bool historyAt(vec2 p, float expected, out vec4 colour, out float seenDepth) {
  vec2 q = p - 0.5;
  ivec2 i0 = ivec2(floor(q));
  vec2 f = q - vec2(i0);
  colour = vec4(0.0);
  seenDepth = 0.0;
  if (all(lessThan(abs(f - round(f)), vec2(1e-3)))) {
    ivec2 c = i0 + ivec2(round(f));
    if (!insideImage(c)) return false;
    float hd = historyDepthAtPixel(c);
    if (!agree(hd, expected) || !historySideAgrees(c)) return false;
    colour = historyAtPixel(c);
    seenDepth = hd;
    return true;
  }
  if (kSharpHistory) return sharpHistoryAt(i0, f, expected, colour, seenDepth);
  float wsum = 0.0;
  for (int k = 0; k < 4; ++k) {
    ivec2 o = ivec2(k & 1, k >> 1);
    ivec2 c = i0 + o;
    if (!insideImage(c)) continue;
    float hd = historyDepthAtPixel(c);
    if (!agree(hd, expected) || !historySideAgrees(c)) continue;
    float w = (o.x == 1 ? f.x : 1.0 - f.x) * (o.y == 1 ? f.y : 1.0 - f.y);
    colour += w * historyAtPixel(c);
    seenDepth += w * hd;
    wsum += w;
  }
  if (wsum < 0.5) return false;
  colour /= wsum;
  seenDepth /= wsum;
  return true;
}

// The cloud depth along this frame's ray of a pixel taken from the history:
// the guess it was looked up with, moved by how far the history's surface
// lay from where the guess put it (seen from the previous camera; the two
// rays differ by a small turn, so the difference carries over). The
// history's own depth where the camera has not moved (a still view keeps its
// depths bit for bit); 0 where the history saw no cloud.
float reusedDepth(float guess, float expected, float seen) {
  if (seen <= 0.0) return 0.0;
  return gStill ? seen : max(guess + (seen - expected), 0.0);
}

// Depth of the history pixel nearest p (p inside the image).
float historyDepthNear(vec2 p) {
  ivec2 c = clamp(ivec2(floor(p)), ivec2(0), ivec2(gSize) - 1);
  return historyDepthAtPixel(c);
}

// The depth of the drawn pixel nearest px (its own block's, or, at the
// image's right and bottom edges where that one falls outside, the block
// before), 0 when there is none.
float nearestDrawnDepth(ivec2 px) {
  ivec2 b = ivec2(floor((vec2(px) - vec2(gPhase)) / float(gN) + 0.5));
  ivec2 i;
  for (int k = 0; k < 2; ++k, b -= 1)
    if (drawnPixel(max(b, ivec2(0)), i)) return freshDepthAt(i);
  return 0.0;
}

// The pixel from the history: the point at `depth` (the nearest drawn
// pixel's) seen from the previous camera; failing that, the point at the
// depth the history holds there. `depth` becomes the reused pixel's depth
// (reusedDepth). from: where in the previous image it was taken (pixels).
// colour is meaningful only when it returns kStatReused.
uint reuseHistory(ivec2 px, out vec4 colour, inout float depth, out vec2 from) {
  vec3 dir = cameraRay(gForward, gRight, gDown, gFrustum, float(px.x), float(px.y), gRaster.x, gRaster.y);
  colour = vec4(0.0);
  from = vec2(px) + 0.5;
  // Two tries: the first guess of the pixel's cloud depth (its own block's
  // drawn pixel's, upscale's nearest), then what the history holds where
  // that led. A loop, not two copies, and its count not a constant the
  // compiler could unroll: lavapipe leaves a loop when no lane of the 8 is
  // still in it, so the second try costs only the vectors where a lane needs it.
  float guess = depth;
  for (uint attempt = 0u; attempt < gHistoryTries; ++attempt) {
    vec2 p;
    float expected, seen;
    if (!previousPixel(dir, guess, p, expected) || !insideImage(ivec2(floor(p)))) return kStatOffscreen;
    if (historyAt(p, expected, colour, seen)) {
      depth = reusedDepth(guess, expected, seen);
      from = p;
      return kStatReused;
    }
    guess = historyDepthNear(p);
  }
  return kStatDisoccluded;
}

// The box of the pixels drawn this frame around px (history_clip.glsl): the
// four drawn pixels whose grid cell holds px (the upscale's). The 3 x 3
// blocks round it spanned 6 to 12 pixels, wide enough to hold sky and
// cloud at every edge, so nothing at an edge was ever outside the box.
HistoryBox drawnBox(ivec2 px) {
  ivec2 c = ivec2(floor((vec2(px) - vec2(gPhase)) / float(gN)));
  HistoryBox box = historyBoxEmpty();
  for (int k = 0; k < 4; ++k) {
    ivec2 t;
    if (drawnPixel(c + ivec2(k & 1, k >> 1), t)) box = historyBoxAdd(box, historyClipSpace(freshAt(t)));
  }
  return box;
}

vec4 clippedHistory(ivec2 px, vec4 history) {
  if (!kHistoryClip || !gClip) return history;
  // Only a history whose transmittance none of the four drawn pixels has
  // is clipped: cloud (or a blend of cloud and sky) where all of them show
  // sky, or the reverse. Each frame's resampling blends the rows it falls
  // between, so at a cloud's edge a pixel left to the history took a
  // blend of sky and cloud, and the next frames carried it on: streaks
  // along the rows not drawn that frame, into the sky of a banked turn
  // (docs/motion.md). Within the cloud the history's finer detail stays.
  HistoryBox box = drawnBox(px);
  bool outside = box.count > 0.5 && (history.w < box.lo.w - 1e-3 || history.w > box.hi.w + 1e-3);
  return outside ? clipHistory(box, history, gClipGamma) : history;
}

// Whether pixel px was drawn this frame, and where its sample is: its
// block's drawn pixel, or a fresh edge's, after the packed pixels (the
// packed image's row found in float: exact for the sizes there are, and
// lavapipe's vector integer division is a loop over the lanes).
bool drawnHere(ivec2 px, out ivec2 texel) {
  ivec2 b = px >> gShift;
  if (px == (b << gShift) + ivec2(gPhase) && drawnPixel(b, texel)) return true;
  if (!kFreshEdges) return false;
  int k = freshEdgeIndex(px, gEdges, gSize);
  uint slot = gEdgeBase + uint(max(k, 0));
  uint row = uint((float(slot) + 0.5) / gPackedW);
  texel = ivec2(int(slot - row * uint(gPackedW)), int(row));
  return k >= 0;
}

// Whether the weather's tiles changed where pixel px looks (the history-drop
// mask's cell): its accumulated history shows the old weather.
bool droppedHere(ivec2 px) {
  if (!gDrop) return false;
  uvec2 c = min(uvec2(px) >> gDropGrid.z, gDropGrid.xy - 1u);
  return dropCells[c.y * gDropGrid.x + c.x] != 0u;
}

// lavapipe runs both sides of a branch for all 8 lanes of a vector when any
// lane takes each, and one block in 16 (4 x 4 interleave) has its drawn pixel
// among the lanes of nearly every vector: so the drawn and the reprojected
// pixels share one history lookup, one clip and one upscale, each taken
// once for the lanes that need it, where a branch per case ran each twice.
uint resolvePixel(ivec2 px, out vec4 colour, out float depth) {
  if (gHorizonSides) {
    vec2 s = frustumPoint(gFrustum, float(px.x) + 0.5, float(px.y) + 0.5, gRaster.x, gRaster.y);
    gPixelGround = rayMeetsSphere(gForward + gRight * s.x - gDown * s.y, gRadius, gGroundC);
  }
  ivec2 drawnTexel;
  bool drawn = drawnHere(px, drawnTexel);
  vec4 fresh = freshAt(drawnTexel);
  float freshDepth = freshDepthAt(drawnTexel);
  // A drawn pixel looks its history up at the depth it was drawn at, blends
  // it in and keeps that depth; any other pixel starts from the nearest
  // drawn pixel's depth, and takes the history's (reusedDepth).
  bool wantHistory = gHasHistory && (!drawn || (gAccumulation > 0.0 && !droppedHere(px)));
  float guess = drawn ? freshDepth : nearestDrawnDepth(px);
  uint outcome = gHasHistory ? kStatDisoccluded : kStatNoHistory;
  vec4 history = vec4(0.0);
  vec2 from = vec2(px) + 0.5;
  if (wantHistory) outcome = reuseHistory(px, history, guess, from);
  bool reused = wantHistory && outcome == kStatReused;
  if (reused) history = clippedHistory(px, history);
  if (drawn) {
    colour = fresh;
    depth = freshDepth;
    if (reused) {
      // In motion the history is resampled (blurred) and partly upscaled:
      // its share falls with how far the pixel moved since the previous
      // frame, to half at gAccumulationMotion pixels. Not to none: inside
      // a cloud the single march's noise, which the mean averages away,
      // costs more than the lag (docs/motion.md).
      float moved = length(from - (vec2(px) + 0.5));
      float share = gAccumulationMotion > 0.0 ? gAccumulation * clamp(1.0 - moved / gAccumulationMotion, 0.5, 1.0)
                                              : gAccumulation;
      colour = mix(colour, history, share);
    }
    return kStatFresh;
  }
  colour = history;
  depth = guess;
  if (!reused) upscale(px, colour, depth);
  return outcome;
}

void main() {
  gSize = params.image.xy;
  gRaster = params.raster.xy;
  gN = params.image.z;
  gShift = gN == 4u ? 2 : gN == 2u ? 1 : 0;
  gHasHistory = params.image.w != 0u;
  gHistoryTries = gHasHistory ? 2u : 0u;
  gEdges = params.freshEdges;
  uint packedW = params.phase.z;
  gPackedW = float(packedW);
  gEdgeBase = packedW * ((gSize.y + gN - 1u) >> uint(gShift));
  gPhase = params.phase.xy;
  gLayers = params.phase.w;
  gForward = params.camForward.xyz;
  gRight = params.camRight.xyz;
  gDown = params.camDown.xyz;
  gFrustum = params.frustum;
  gPrevFrustum = params.prevFrustum;
  gPrevForward = params.prevForward.xyz;
  gPrevRight = params.prevRight.xyz;
  gPrevDown = params.prevDown.xyz;
  gPrevPosition = params.prevPosition.xyz;
  gRadius = params.prevPosition.w;
  gGroundC = params.camForward.w;
  gHorizonSides = params.camRight.w != 0.0;
  gPixelGround = false;
  gRelTolerance = params.tolerance.x;
  gAbsTolerance = params.tolerance.y;
  gBandMargin = params.tolerance.z;
  gAccumulation = params.tolerance.w;
  gClipGamma = params.raster.z;
  gAccumulationMotion = params.raster.w;
  for (uint l = 0u; l < kReprojectMaxLayers; ++l) {
    gBand[l] = params.layerBand[l];
    gMotion[l] = params.layerMotion[l].xyz;
    gLayerWind[l] = params.layerWind[l];
  }
  gCamToAnchor = transpose(mat3(params.camToAnchor[0].xyz, params.camToAnchor[1].xyz, params.camToAnchor[2].xyz));
  gCamInAnchor = params.camInAnchor;
  gMapScale = params.weatherMap.x;
  gRings = vec4(params.weatherMap.w, params.weatherMap.y, params.weatherMap.z, 0.0);
  gStill = gPrevPosition == vec3(0.0) && gPrevFrustum == gFrustum && gPrevForward == gForward && gPrevRight == gRight && gPrevDown == gDown;
  for (uint l = 0u; l < kReprojectMaxLayers; ++l) gStill = gStill && (l >= gLayers || gMotion[l] == vec3(0.0));
  gClip = gClipGamma > 0.0 && !gStill;
  gDropGrid = params.drop;
  gDrop = gDropGrid.w != 0u && gDropGrid.x > 0u && gDropGrid.y > 0u;
  ivec2 px = ivec2(gl_GlobalInvocationID.xy);
  if (px.x < int(gSize.x) && px.y < int(gSize.y)) {
    vec4 colour;
    float depth;
    uint outcome = resolvePixel(px, colour, depth);
    uint i = uint(px.y) * gSize.x + uint(px.x);
    outPixels[i] = colour;
    outDepth[i] = depth;
    // What became of the pixel, counted on the host (ReprojectPass::counts):
    // a plain store, where counters shared by the workgroup need atomics
    // and barriers, which cost more on lavapipe.
    outcomes[i] = outcome;
  }
}
