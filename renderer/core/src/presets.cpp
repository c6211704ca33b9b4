// Quality presets (see presets.hpp).
#include "sky/render/presets.hpp"

namespace sky::render {

namespace {

MarchSettings march(std::uint32_t primarySteps, std::uint32_t lightSteps, double minTransmittance,
                    std::uint32_t emptyStride) {
  MarchSettings m;
  m.primarySteps = primarySteps;
  m.lightSteps = lightSteps;
  m.minTransmittance = minTransmittance;
  m.emptyStride = emptyStride;
  return m;
}

// The march in metres (MarchSettings::cloudStep_m > 0): primarySteps caps a
// span's samples.
MarchSettings metres(std::uint32_t maxSamples, std::uint32_t lightSteps, double minTransmittance, double cloudStep_m,
                     double emptyStep_m, double stepGrowth, std::uint32_t airSteps) {
  MarchSettings m = march(maxSamples, lightSteps, minTransmittance, 1);
  m.cloudStep_m = cloudStep_m;
  m.emptyStep_m = emptyStep_m;
  m.stepGrowth = stepGrowth;
  m.airSteps = airSteps;
  return m;
}

// The clear air marched along every view ray with 64 steps, the most the
// settings take, not read from the air table: against a 64-step march the
// default 16 steps leave 40 dB in the above-atmosphere scene, where the air
// table's 31 leave 52 (docs/light-transport.md).
MarchSettings marched(MarchSettings m) {
  m.airTable.enabled = false;
  m.airSteps = 64;
  return m;
}

// The sun's optical depth over the whole column above each cloud sample,
// marched in 64 steps per layer crossed (and the air's and the ground's in 64
// per layer): the ground truth the sun maps were measured against
// (docs/light-transport.md). The presets' old secondary march stops at half a
// layer's thickness, so it lit the far sides and bases of towering clouds
// as if the sun shone through them: against this column it scores 6.6 dB on
// the cumulonimbus at low sun. 256 primary x 64 column steps stays inside
// lavapipe's loop budget (CloudRenderer refuses more).
MarchSettings columnSun(MarchSettings m) {
  m.sunShadow.method = SunShadow::Column;
  m.lightSteps = 64;
  m.sunShadow.buildSteps = 64;
  return m;
}

// The sun's optical depth from a deep shadow map (the optical depth at 8
// depths along each sun line; size x size texels x 4 cascades from 4 km to
// 256 km either side), reused until what it holds has moved and then rebuilt
// over buildFrames frames (sun_map_plan.hpp). On the bench's eight stills of
// cloud seen from below or level it is 0.9-49 dB closer to the column than
// the secondary march at about the same cost; it loses up to 2.8 dB inside
// a deck, 1.9 above one and 3.8 from 90 km up (docs/light-transport.md,
// "The presets on the sun map"). The light march
// is compiled out, so lightSteps is unused. The cheaper the preset, the
// more frames a rebuild is spread over: a map of three layers at a sun 35
// degrees up takes 115 ms to build whole at 128 texels (the airliner climb).
MarchSettings deepMap(MarchSettings m, std::uint32_t size, std::uint32_t buildFrames) {
  m.sunShadow.method = SunShadow::Deep;
  m.sunShadow.size = size;
  m.sunShadow.buildFrames = buildFrames;
  return m;
}

// A smaller air table: it is built for every frame whatever the share of
// pixels drawn, so at a few milliseconds a frame the cheap presets feel its
// size (skyshell-bench 320x180: realtime 12.6 -> 5.2 ms on cumulus-midday
// with 32 x 32 x 16, PSNR 40.92 -> 40.93 dB; on a clear sunset 50.0 -> 48.0).
MarchSettings withAirTable(MarchSettings m, std::uint32_t azimuths, std::uint32_t zeniths, std::uint32_t slices) {
  m.airTable.azimuths = azimuths;
  m.airTable.zeniths = zeniths;
  m.airTable.slices = slices;
  return m;
}

// Interleaved, n x n, with temporal accumulation (TemporalSettings), the
// history resampled with Catmull-Rom weights: in the bench's turns it costs
// the reprojection about twice its time (a tenth of a `realtime` frame) and
// keeps every path closer to `reference` (docs/motion.md).
TemporalSettings interleaved(std::uint32_t n, double accumulation, double denseTurn_px = 2) {
  TemporalSettings t;
  t.interleave = n;
  t.accumulation = accumulation;
  t.denseTurn_px = denseTurn_px;
  t.sharpHistory = true;
  t.historyClip = 4;
  return t;
}

ResolutionSettings divided(std::uint32_t divisor) {
  ResolutionSettings r;
  r.divisor = divisor;
  return r;
}

}  // namespace

const std::vector<Preset>& presets() {
  static const std::vector<Preset> all = {
      {"reference",
       "ground truth: 256 primary steps, no early exit, every sample, every pixel; the sun marched through the "
       "whole column above each sample in 64 steps per layer; the air marched per pixel in 64 steps",
       columnSun(marched(march(256, 64, 0, 1))), {}},
      {"high",
       "the default: 48 primary steps, exit at 1 %, every sample, every pixel; the sun from a deep shadow map "
       "(128 x 128 x 4 cascades, rebuilt over 4 frames); the air from the per-frame table (as every preset but "
       "reference)",
       deepMap(MarchSettings{}, 128, 4), {}},
      // Growth 0.005 and exit at 0.2 %: what puts medium past both seeds'
      // settings on the scenes where coarser values lose to them
      // (skyshell-bench 320x180: above-deck-10km PSNR 56.3 dB at 13.4 ms
      // against ford-2024's 52.3; overcast-below 65.1 dB at 12.1 ms against
      // haggstrom-2018's 61.4; with growth 0.01 and exit at 2 % medium is
      // below both: CHANGELOG).
      {"medium",
       "steps of 40 m in cloud, 80 m in clear air, +0.5 % of the distance; exit at 0.2 %; the sun from a deep shadow "
       "map (128 x 128 x 4, rebuilt over 8 frames); "
       "1 pixel of 16 per frame (1 of 4 in a turn of over 2 pixels a frame), the rest reprojected, redraws accumulated "
       "(history 0.75 at rest, 0.375 from 1 pixel of motion a frame, resampled Catmull-Rom, clipped in motion where "
       "it shows cloud or sky the drawn pixels round it do not)",
       deepMap(metres(256, 4, 0.002, 40, 80, 0.005, 12), 128, 8), interleaved(4, 0.75)},
      {"low",
       "steps of 40 m in cloud, 80 m in clear air, +1 % of the distance; exit at 3 %; the sun from a deep shadow map "
       "(128 x 128 x 4, rebuilt over 16 frames); "
       "the air from a 48 x 48 x 24 table; 1 pixel of 16 per frame (1 of 4 in a turn of over 2 pixels a frame), the "
       "rest reprojected, redraws accumulated (history 0.75 at rest, 0.375 from 1 pixel of motion a frame, "
       "resampled Catmull-Rom, clipped in motion where it shows cloud or sky the drawn pixels round it do not)",
       deepMap(withAirTable(metres(256, 3, 0.03, 40, 80, 0.01, 8), 48, 48, 24), 128, 16), interleaved(4, 0.75)},
      {"realtime",
       "steps of 40 m in cloud, 80 m in clear air, +2 % of the distance; exit at 5 %; the sun from a deep shadow map "
       "(64 x 64 x 4, rebuilt over 16 frames); "
       "the air from a 32 x 32 x 16 table; the clouds drawn at 1/2 the width and height (depth-aware upscale); 1 "
       "pixel of 16 per frame (1 of 4 in a turn of over 1 pixel of the half size a frame), the rest reprojected, "
       "redraws accumulated (history 0.75 at rest, 0.375 from 1 pixel of motion a frame, resampled Catmull-Rom, "
       "clipped in motion where it shows cloud or sky the drawn pixels round it do not)",
       // The dense turn's threshold is in the cloud pass's pixels: 1 at half
       // the size is the other presets' 2 of the image. The bundled glider's
       // circle turns 1.1-1.7 of these pixels a frame; drawn densely there,
       // realtime reaches SSIM 0.973 on that path (worst frame 0.954) at 7.9
       // ms a frame at 320x180, where a threshold of 2 gives 0.965 (0.931)
       // at 6.7 ms (docs/motion.md).
       deepMap(withAirTable(metres(256, 3, 0.05, 40, 80, 0.02, 8), 32, 32, 16), 64, 16), interleaved(4, 0.75, 1),
       divided(2)},
  };
  return all;
}

Result<Preset> findPreset(const std::string& name) {
  std::string valid;
  for (const Preset& p : presets()) {
    if (p.name == name) return p;
    valid += (valid.empty() ? "" : ", ") + p.name;
  }
  return fail(ErrorCode::InvalidArgument, "unknown preset '" + name + "' (valid: " + valid + ")");
}

}  // namespace sky::render
