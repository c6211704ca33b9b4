// The cloud and sky model, written once in the subset GLSL and C++ share:
// per-layer ray-shell spans, the light (Beer-Lambert, Jendersie-d'Eon phase,
// Wrenninge octaves, a secondary march towards the sun, sky ambient,
// Hillaire's energy-conserving steps), the clear-sky atmosphere behind and
// between the layers (aerial perspective) and the ground. Included by
// shaders/clouds.comp (real = float) and, inside a class body, by
// renderer/core/src/cpu_reference.cpp (real = double).
// The includer defines real, real2, real3, real4, uint, SKY_CORE_CONST,
// kMaxLayers and sampleTransmittanceLut (atmosphere_core.glsl) before
// including this file, and defines the hooks declared below after it:
//   CoreLayer layerAt(int li)                            // layer li of the frame
//   real3 sampleWeather(LayerSampling s, real3 pLocal)   // (coverage, density, blend), 0 outside the map
//   real2 sampleCloudMap(LayerSampling s, real3 pLocal)  // (coverage modulation, peak height) in [0, 1]
//   real2 sampleShape(LayerSampling s, real3 pLocal)     // (billowy, fibrous) shape noise in [0, 1]
//   real  sampleDetail(LayerSampling s, real3 pLocal)    // Worley detail noise in [0, 1]
//   real  sampleMaxCoverage(LayerSampling s, real3 pLocal) // the weather map's max-coverage mip cell:
//                                                          // >= any coverage sampleWeather gives in it
//   real3 sampleWindLocal(LayerSampling s, real3 pLocal) // the layer's wind at p, camera-local (m/s,
//                                                          // horizontal), for a layer whose wind varies
// The three noise hooks read their noise at pLocal - s.flowShift, the
// weather hooks their tiles where the air at pLocal was at the snapshot's
// clock (for a layer whose wind varies: its wind at pLocal times the age).
//   real2 airCloudShadow(AirFrame a, real3 p, real h, real muSun) // airSunShadow(a, p, h, muSun)
//   real4 sampleAirTable(int part, real3 uvw)           // the frame's air table (air_table.glsl)
//   real4 sampleSunMap(int layer, real2 uv)             // the frame's sun map (sun_map.glsl)
//   flashAt, boltStartAt, boltEndAt                      // the frame's lightning (lightning.glsl)
// and the frame's sun map in gSunMap (a global; a data member in C++), and
// kWindField: false where no layer's wind varies over the map and none is
// in a crossfade of its flow's phases (the wind map's reads and the second
// phase are then left out; on the GPU a pipeline constant, true in C++),
// kLightning: false where the frame lights no flash (the same), and
// kShowers: false where no precipitation layer falls under a carrier's
// cells (the same).
// pLocal is camera-relative, local frame: x east, y north, z up (m).

#include "core_common.glsl"
// The air march sees the clouds' shadow (atmosphere_core.glsl's
// airCloudShadow hook; the includer defines it as cloudShadow below).
#define SKY_CLOUD_SHADOWED_AIR
#include "atmosphere_core.glsl"
#include "air_table.glsl"
#include "cloud_density.glsl"
#include "sky/weather/layer_presence.glsl"
#include "wind_map.glsl"
#include "lightning.glsl"

// Single-scattering albedo of cloud droplets and ice in the visible
// (formulas.md: 0.999+).
SKY_CORE_CONST real kAlbedo = 0.999;
// Asymmetry of the Henyey-Greenstein phase function for ice crystals (the
// Mie fit holds for droplets only): g ~ 0.75-0.8 for cirrus in the visible
// (Baum et al. 2005, "Bulk scattering properties for the remote sensing of
// ice clouds"); halos are not modelled.
SKY_CORE_CONST real kIceAsymmetry = 0.75;
// Wrenninge 2015 multiple-scattering octaves: octave i scales the extinction
// towards the sun by a^i, its contribution by b^i and the phase eccentricity
// by c^i; a <= b keeps the sum energy-conserving. a = b = 0.5 as in
// formulas.md. c is the droplets' asymmetry g (kDiffuseAsymmetry), not
// formulas.md's example 0.5: light scattered n times has the asymmetry g^n
// (the phase functions' Legendre moments multiply under convolution), so
// octave i, standing for order i + 1, has eccentricity g c^i = g^(i+1).
// Against the path-traced truth (docs/bench/truth-160x90.md) c = g moves
// every still towards it: front-lit 1.12-1.20x the truth's mean to
// 1.04-1.10x, looking into a low sun 0.45x to 0.58x. 4 octaves, one per lane of a real4 (Ford uses 8; the 5th adds
// under 3 %; arrays of per-octave values cost lavapipe a memory round trip
// per sample, a real4 does not).
SKY_CORE_CONST int kScatterOctaves = 4;
// The parts of the light model a measurement may switch off, one at a
// time, to see what each brings against the path-traced truth
// (skyshell-bench --truth path): constants everywhere but in the CPU
// core, which defines SKY_MODEL_CONST as a data member's type
// (cpu_core.hpp, CpuReference::setModel). kOctaveContribution 0 leaves
// single scattering of the sun; kAmbientGain 0 drops the sky's and the
// scattered sun's diffuse light, kSunDiffuseGain 0 only the scattered
// sun's; kMiePhase false takes one HG lobe of kDiffuseAsymmetry for the
// droplets' Mie fit.
#ifndef SKY_MODEL_CONST
#define SKY_MODEL_CONST SKY_CORE_CONST
#endif
SKY_MODEL_CONST real kOctaveContribution = 0.5;
SKY_MODEL_CONST real kOctaveExtinction = 0.5;
SKY_MODEL_CONST real kAmbientGain = 1.0;
SKY_MODEL_CONST real kSunDiffuseGain = 1.0;
SKY_MODEL_CONST bool kMiePhase = true;
SKY_MODEL_CONST real kOctaveEccentricity = 0.85;
// The march's cost knobs are run-time numbers of the frame (CoreFrame.march,
// RenderSettings::march, the presets); these are their defaults, the
// `high` preset. Primary samples per layer span, spread evenly over it, so
// cost is predictable (lavapipe.md: ~9.5 ns per primary step, 60-130 lookups
// per pixel fit a 33 ms frame).
SKY_CORE_CONST int kPrimarySteps = 48;
// Light samples towards the sun (Haggstrom 2018: 4 was the best trade); the
// distance they cover is per layer (LayerSetup::lightDistance_m).
SKY_CORE_CONST int kLightSteps = 4;
// Longest span marched through one layer, m: beyond this a grazing ray's
// samples would be more than ~1.2 km apart and only add noise.
SKY_CORE_CONST real kMaxSpan_m = 60000.0;
// Spans starting farther than this are not marched, m: the weather map's
// coarse ring reaches 600 km (gnomonic half extent), past the horizon of a
// layer at 2 km seen from 12 km (~550 km); in the low air aerial
// perspective has faded clouds to a few percent of their contrast by
// ~150 km, but seen from cruise altitude through thin air they stay visible.
SKY_CORE_CONST real kMaxViewDistance_m = 600000.0;
// Early exit once the view ray keeps less than 1 % of the background.
SKY_CORE_CONST real kMinTransmittance = 0.01;
// Samples skipped per empty primary sample: 1 marches every sample.
SKY_CORE_CONST real kEmptyStride = 1.0;
// Step lengths of the march in metres (MarchParams): 0, the default, places
// the samples evenly instead.
SKY_CORE_CONST real kCloudStep_m = 0.0;
SKY_CORE_CONST real kEmptyStep_m = 0.0;
SKY_CORE_CONST real kStepGrowth = 0.0;
// Diffuse light inside a layer: the sky's light and the sunlight scattered
// out of the direct beam above a point reach it as diffuse light, transmitted
// through the optical depth tau above as by a conservatively scattering slab
// in the Eddington two-stream approximation, t = 1 / (1 + 3/4 (1 - g) tau)
// (e.g. Bohren & Clothiaux 2006, "Fundamentals of Atmospheric Radiation",
// ch. 6). g = 0.85 is the asymmetry of cloud droplets in the visible (the Mie
// fit's mean cosine at 10-20 um). Wrenninge's octaves carry sunlight a few
// optical depths in; this carries it through an overcast deck.
SKY_CORE_CONST real kDiffuseAsymmetry = 0.85;
// Smallest sun cosine for the direct beam's slant depth (sun at the horizon).
SKY_CORE_CONST real kMinSunCosine = 0.02;
// Lambertian ground albedo (no terrain yet): 0.1, a mix of vegetation and
// soil, as Bruneton 2017's reference ground.
SKY_CORE_CONST real kGroundAlbedo = 0.1;
// Where a layer's textures are read (the hooks' per-layer inputs, carried
// in the layer so a sample reads no frame data).
struct LayerSampling {
  real4 shapeOrigin;     // xyz: (camera ECEF - wind drift) mod period, in periods; w: 1 / period (1/m)
  real4 detailOrigin;    // the same for the detail noise
  real4 cloudMapOrigin;  // the same for the cloud map
  real3 coverageShift;   // xy: coverage drift east/north (m); z: weather-map slice
  real shapeStretchZ;    // the shape noise's ECEF z scale: < 1 draws streaks along the Earth's axis
  real4 flow;            // x, y: the two flow phases' ages (s); z: phase A's weight; w: 1 when the wind varies
  real4 windRef;         // xyz: the layer's own wind (camera-local, m/s); w: the map tiles' age (s)
  real3 flowShift;       // where this sample's noise is read from: pLocal - flowShift (m; flow phase A's)
  real3 flowShiftB;      // the same for flow phase B (the core reads it through the hooks as flowShift)
};

struct CoreLayer {
  real hBase;      // camera height above the layer base, m (negative below)
  real hTop;       // camera height above the layer top, m
  real cBase;      // hBase (2r - hBase), m^2
  real cTop;       // hTop (2r - hTop), m^2
  real thickness;  // m, > 0
  real lightDistance;  // m the secondary march covers towards the sun, > 0
  bool blends;     // tiles blend towards `secondary` by the weather map's blend
  CloudType primary;
  CloudType secondary;
  real3 skyTop;        // mean sky radiance at the layer top, linear units
  real3 sunDiffuseTop; // sunlight at the layer top as a diffuse radiance, E T mu / pi
  real sunCosine;      // mu of the sun at the layer top (>= 0)
  LayerSampling sampling;
  bool absent;         // no coverage anywhere on the weather map: not marched, casts no shadow
  real stepFactor;     // the march in metres' steps (cloud and empty) times this, > 0 (Haggstrom 2018
                       // eq. 34 and 36 from the layer's mean coverage and density; 1: off)
  real band;           // the transition band's fraction of the shell at each end, [0, 0.5): the heights
                       // above (hBase, hTop, thickness) are the shell's, base - band to top + band, and
                       // the cloud fades across the band (layerPresence)
  int carrier;         // a precipitation layer: the layer whose cells drop it (its shafts fall under
                       // them, carrierFootprint), or -1
};

// The layers are read through this hook, not carried in CoreFrame: a frame
// holding every layer's numbers, passed by value into per-sample functions
// and indexed by a run-time layer number, is copied per sample by lavapipe
// (measured: 3x the frame time of reading the one layer a span needs).
CoreLayer layerAt(int li);
real3 sampleWeather(LayerSampling s, real3 pLocal);
real2 sampleCloudMap(LayerSampling s, real3 pLocal);
real2 sampleShape(LayerSampling s, real3 pLocal);
real sampleDetail(LayerSampling s, real3 pLocal);
real sampleMaxCoverage(LayerSampling s, real3 pLocal);
real3 sampleWindLocal(LayerSampling s, real3 pLocal);


// The noise of a layer whose wind varies, carried by the local wind in two
// phases of the flow (the flow-map scheme of texture advection): each phase
// reads the noise where the air was when the phase began, up to a period
// ago (frame_setup.cpp, kWindFlowPeriod_s); as one grows old the other takes
// over across a short crossfade (flow.z: phase A's weight). During it both
// are read and mixed so that the mix keeps the noise's contrast (the
// variance-preserving blend of Heitz and Neyret 2018, about the noise's mid
// value): a plain mix of two unrelated patterns is flatter, and the clouds
// would pulse in brightness at every crossfade. A shear thus stretches the
// shapes by at most its rate times the period and never tears them.
LayerSampling flowPhaseB(LayerSampling s) {
  s.flowShift = s.flowShiftB;
  return s;
}

real flowMix(real a, real b, real wA) {
  real wB = 1.0 - wA;
  return clamp(0.5 + (wA * (a - 0.5) + wB * (b - 0.5)) / sqrt(wA * wA + wB * wB), 0.0, 1.0);
}

// A flowing layer's phases crossfade: the noise is read in both and mixed.
// Outside a crossfade flowShift holds the one phase that shows
// (cloudSample), and the noise is read once. Branches, not loops of zero or
// one trip: llvmpipe gives an invocation 65535 loop iterations over all its
// loops (docs/light-transport.md), and a loop per noise read in the light
// march spent reference's budget. kWindField (the includer's; on the GPU a
// pipeline constant) is false for frames without a wind field or a
// crossfade, so their pipeline holds none of this.
bool flowCrossfades(LayerSampling s) {
  return kWindField && s.flow.z > 0.0 && s.flow.z < 1.0;
}

real2 flowShape(LayerSampling s, real3 p) {
  real2 v = sampleShape(s, p);
  if (flowCrossfades(s)) {
    real2 b = sampleShape(flowPhaseB(s), p);
    v = real2(flowMix(v.x, b.x, s.flow.z), flowMix(v.y, b.y, s.flow.z));
  }
  return v;
}

real2 flowCloudMap(LayerSampling s, real3 p) {
  real2 v = sampleCloudMap(s, p);
  if (flowCrossfades(s)) {
    real2 b = sampleCloudMap(flowPhaseB(s), p);
    v = real2(flowMix(v.x, b.x, s.flow.z), flowMix(v.y, b.y, s.flow.z));
  }
  return v;
}

real flowDetail(LayerSampling s, real3 p) {
  real v = sampleDetail(s, p);
  if (flowCrossfades(s)) v = flowMix(v, sampleDetail(flowPhaseB(s), p), s.flow.z);
  return v;
}

// The march's cost knobs (defaults above; RenderSettings::march). Two ways
// to place the samples of a layer span: evenly (cloudStep 0: primarySteps
// samples over the span, the empty stride skipping through clear air), or
// in metres (cloudStep > 0): long steps of emptyStep through clear air
// judged by the cheap density (no detail noise, no light march), short
// steps of cloudStep inside cloud, both growing by stepGrowth metres per
// metre of distance from the camera and times the layer's stepFactor, at
// most primarySteps samples a span.
struct MarchParams {
  int primarySteps;      // even: samples per layer span; metres: most samples a span; >= 1
  int lightSteps;        // samples of the secondary march towards the sun, >= 1
  real minTransmittance; // stop once the view ray keeps less; 0: never
  real emptyStride;      // even: samples advanced after one that met no cloud, >= 1
  real cloudStep;        // m, step inside cloud at the camera; 0: even placement
  real emptyStep;        // m, step through clear air at the camera, >= cloudStep
  real stepGrowth;       // step length added per metre of distance, >= 0
};

// Short steps that met no cloud before the march in metres returns to long
// steps: one stray empty sample inside a cloud's ragged edge does not.
SKY_CORE_CONST int kEmptyRunToLongSteps = 2;

struct CoreFrame {
  AirFrame air;
  // The air in front of the clouds and the ground from the frame's table
  // (air_table.glsl, of shape airTable), or marched per pixel. A flag of its
  // own, not airTable's azimuths: on the GPU it is a constant of the
  // pipeline, so the way not taken is compiled out.
  bool airFromTable;
  AirTableShape airTable;
  // Whether any layer has coverage somewhere on the weather map; false: a
  // clear sky, drawn as air and ground alone (on the GPU a constant of the
  // pipeline too: the clear sky's variant has no cloud code to run).
  bool clouds;
  // Layers whose shadow falls on the clouds of the others (cloudShadow in
  // the march): air.shadowLayers, or 0 where at most one layer is drawn and
  // there is no other to shadow (on the GPU a constant of the pipeline: the
  // shadow's loop is then compiled out, where a loop that would skip the
  // layer a sample is in still runs one turn of it on lavapipe).
  int layerShadows;
  MarchParams march;
  real3 groundIrradiance;  // sky irradiance on horizontal ground, linear units
  int layerCount;
  // The frame's lightning (lightning.glsl): flashes lit, bolt segments, and
  // a pixel's angle (rad) for the bolt's width.
  int flashCount;
  int boltCount;
  real pixelAngle;
};

struct Span {
  real t0;  // empty when t1 <= t0
  real t1;
};

// One layer's contribution along a ray, alone: in-scattered radiance (not yet
// attenuated by what lies in front), transmittance, and its
// opacity-weighted mean depth (where aerial perspective is applied).
struct LayerResult {
  real3 inscatter;
  real transmittance;
  real depth;
};

struct PixelResult {
  real3 radiance;
  real transmittance;  // through the clouds only
  real depth;          // light-weighted mean distance to the clouds, m; 0 when no cloud was met
};

// Part of the ray inside one layer's shell, clipped by the ground and the
// march limits. Handles cameras below, inside and above the layer.
Span layerSpan(CoreFrame f, CoreLayer L, real mu, real tGround) {
  Roots base = intersectSphere(f.air.r, L.cBase, mu);
  Roots top = intersectSphere(f.air.r, L.cTop, mu);
  // The three cases as selects, not branches: a branch on the layer heights
  // alone (uniform values) makes lavapipe compile a shader variant for each
  // camera altitude (it inlines uniforms that decide an `if`).
  bool below = L.hBase < 0.0;
  bool inside = !below && L.hTop < 0.0;
  bool aboveHit = !below && !inside && top.hit && top.t1 > 0.0;
  // Below: inside both spheres, so both are hit; leave the base, then the top.
  // Inside: until the top, or the base if the ray reaches it first.
  // Above: from the top down to the base, or out through the top again.
  real baseFirst = (base.hit && base.t0 >= 0.0) ? base.t0 : top.t1;
  real t0 = below ? base.t1 : (aboveHit ? max(top.t0, 0.0) : 0.0);
  real t1 = below ? top.t1 : (inside ? min(top.t1, baseFirst) : (aboveHit ? baseFirst : 0.0));
  t1 = min(t1, tGround);
  t1 = min(t1, t0 + kMaxSpan_m);
  t1 = t0 > kMaxViewDistance_m ? t0 : t1;
  return Span(t0, t1);
}

// Henyey-Greenstein phase function, 1/sr; integrates to 1 over the sphere
// (formulas.md; note the 1/(4 pi), not Haggstrom's listing B.6).
real phaseHG(real cosTheta, real g) {
  real denom = 1.0 + g * g - 2.0 * g * clamp(cosTheta, -1.0, 1.0);
  return (1.0 - g * g) / (4.0 * kPi * denom * sqrt(denom));
}

// Draine's phase function (formulas.md), 1/sr: HG times (1 + alpha cos^2)
// over its mean, (1 + alpha (1 + 2 g^2) / 3), so it integrates to 1.
real phaseDraine(real cosTheta, real g, real alpha) {
  real c = clamp(cosTheta, -1.0, 1.0);
  return phaseHG(c, g) * (1.0 + alpha * c * c) / (1.0 + alpha * (1.0 + 2.0 * g * g) / 3.0);
}

// Jendersie & d'Eon 2023 fit of Mie scattering by water droplets of diameter
// d um (5 <= d <= 50): an HG lobe and a Draine lobe mixed by w.
struct MieFit {
  real gHG;
  real gD;
  real alpha;
  real w;
};

MieFit mieFit(real d) {
  return MieFit(exp(-0.0990567 / (d - 1.67154)), exp(-2.20679 / (d + 3.91029) - 0.428934),
                exp(3.62489 - 8.29288 / (d + 5.52825)), exp(-0.599085 / (d - 0.641583) - 0.664888));
}

// The fitted phase function with both eccentricities scaled by gScale (1 for
// single scattering, c^i for Wrenninge's octave i), 1/sr.
real phaseMie(real cosTheta, MieFit m, real gScale) {
  return (1.0 - m.w) * phaseHG(cosTheta, m.gHG * gScale) + m.w * phaseDraine(cosTheta, m.gD * gScale, m.alpha);
}

// A cloud type's phase function for octave eccentricity scale gScale: the
// Mie fit for its droplet diameter, or HG for ice.
real phaseCloud(real cosTheta, CloudType t, real gScale) {
  if (t.dropletDiameter_um <= 0.0) return phaseHG(cosTheta, kIceAsymmetry * gScale);
  if (!kMiePhase) return phaseHG(cosTheta, kDiffuseAsymmetry * gScale);
  return phaseMie(cosTheta, mieFit(t.dropletDiameter_um), gScale);
}

// The four octaves' phase values for the angle to the sun (cosTheta): octave
// i uses eccentricity c^i.
real4 octavePhases(real cosTheta, CloudType t) {
  real c1 = kOctaveEccentricity;
  real c2 = c1 * kOctaveEccentricity;
  real c3 = c2 * kOctaveEccentricity;
  return real4(phaseCloud(cosTheta, t, 1.0), phaseCloud(cosTheta, t, c1), phaseCloud(cosTheta, t, c2),
               phaseCloud(cosTheta, t, c3));
}

// Sun light scattered towards the viewer at a point with optical depth tauSun
// towards the sun, per unit sun radiance: Wrenninge's octave sum
// sum_i b^i p(theta, c^i g) exp(-a^i tauSun), given the octaves' phase values.
real octaveSum(real4 phases, real tauSun) {
  real a1 = kOctaveExtinction;
  real a2 = a1 * kOctaveExtinction;
  real a3 = a2 * kOctaveExtinction;
  real b1 = kOctaveContribution;
  real b2 = b1 * kOctaveContribution;
  real b3 = b2 * kOctaveContribution;
  return dot(phases * real4(1.0, b1, b2, b3), exp(-real4(1.0, a1, a2, a3) * tauSun));
}

// Optical depth towards the sun from p over the layer's light distance
// (Haggstrom's secondary march, sec. 3.2): shape noise only (no erosion,
// the cheap sample), with the coverage, type and cloud map of the primary
// sample standing for the path (a few hundred metres; map texels ~780 m).
// Heights along it rise by muSun per metre (the sun's cosine at p; the
// curvature over <= 2 km is under 0.4 m). `steps` is lightSteps, or 0 where
// there is no density: lavapipe runs every branch for all lanes of a
// subgroup, but leaves a loop once no lane is in it, so a zero trip count is
// what skips the march.
real lightOpticalDepth(real3 sunDir, real muSun, real thickness, real band, real lightDistance, LayerSampling ls,
                       CloudType t, real3 p, real ph, real c, real peakNoise, real densityScale, int lightSteps,
                       int steps) {
  real lightDt = lightDistance / real(lightSteps);
  real dph = lightDt * muSun / thickness;
  real tau = 0.0;
  for (int j = 0; j < steps; ++j) {
    real3 q = p + sunDir * ((real(j) + 0.5) * lightDt);
    real qh = ph + (real(j) + 0.5) * dph;
    real sa = shapeProfile(t, qh, c, peakNoise);
    tau += cloudShape(t, flowShape(ls, q), c, sa) * densityProfile(t, qh) * layerPresence(qh, band);
  }
  return tau * t.extinction_perm * densityScale * lightDt;
}

// Diffuse radiance in-scattered at height fraction ph of layer L (isotropic,
// so per unit phase it is the radiance itself): the sky's light and the
// sunlight scattered out of the beam above, both through the depth above.
// The depth above is the type's mean column density (columnFill) times
// coverage c and the weather density over the rest of the layer.
real3 diffuseLight(CoreLayer L, CloudType t, real ph, real c, real densityScale) {
  real tauAbove = t.extinction_perm * densityScale * c * t.columnFill * layerPresenceAbove(ph, L.band) * L.thickness;
  real transmitted = 1.0 / (1.0 + 0.75 * (1.0 - kDiffuseAsymmetry) * tauAbove);
  real scatteredOut = 1.0 - exp(-tauAbove / max(L.sunCosine, kMinSunCosine));
  return (L.skyTop + L.sunDiffuseTop * (scatteredOut * kSunDiffuseGain)) * transmitted;
}

// The density at p (height fraction ph) of layer L and what the light march
// there needs; rho 0 where there is no cloud. `cheap`: without the detail
// noise's erosion (which only removes cloud, so rho > 0 wherever the full
// density is > 0): the long steps' test for cloud.
struct CloudSample {
  real rho;
  CloudType ct;
  real coverage;      // after the cloud map and the anvil
  real peakNoise;     // the cloud map's peak value
  real densityScale;  // the weather map's density
  real blend;
  real3 flowShift;    // where its noise was read from (flow phases A and B), for the light march
  real3 flowShiftB;
};

// The noise is carried by the wind in the two phases of the flow
// (flowShape and the others): the layer's own wind, or where it varies over
// the map the local wind (its vertical part the layer's own).
LayerSampling flowAt(LayerSampling s, real3 p) {
  real3 drift = real3(s.windRef);
  if (kWindField && s.flow.w > 0.5) {
    real3 rel = sampleWindLocal(s, p) - drift;
    rel.z = 0.0;
    drift += rel;
  }
  // Phase A's shift first, or B's alone where only B shows.
  s.flowShift = drift * (s.flow.z > 0.0 ? s.flow.x : s.flow.y);
  s.flowShiftB = drift * s.flow.y;
  return s;
}

// coverageGain: the weather map's coverage is taken times this (capped at
// 1): a precipitation layer's coverage as a share of its carrier's
// (carrierFootprint), 1 otherwise.
CloudSample cloudSample(CoreLayer L, real3 p, real ph, bool cheap, real coverageGain) {
  L.sampling = flowAt(L.sampling, p);
  CloudSample cs;
  cs.rho = 0.0;
  cs.ct = L.primary;
  cs.coverage = 0.0;
  cs.peakNoise = 0.0;
  cs.densityScale = 0.0;
  cs.blend = 0.0;
  cs.flowShift = L.sampling.flowShift;
  cs.flowShiftB = L.sampling.flowShiftB;
  if (ph <= 0.0 || ph >= 1.0) return cs;
  // Empty-space skipping: a long step in a mip cell without coverage is
  // clear, known from one read.
  if (cheap && sampleMaxCoverage(L.sampling, p) <= 0.0) return cs;
  real3 weather = sampleWeather(L.sampling, p);
  if (weather.x <= 0.0) return cs;
  cs.blend = L.blends ? weather.z : 0.0;
  cs.ct = cs.blend > 0.0 ? mixCloudType(L.primary, L.secondary, cs.blend) : L.primary;
  real2 map = flowCloudMap(L.sampling, p);
  cs.peakNoise = map.y;
  cs.densityScale = weather.y;
  real cover = min(weather.x * coverageGain, 1.0);
  cs.coverage = anvilCoverage(cs.ct, ph, cover < 1.0 ? mappedCoverage(cover, map.x) : 1.0);
  real sa = shapeProfile(cs.ct, ph, cs.coverage, map.y);
  if (sa <= 0.0) return cs;
  real shape = cloudShape(cs.ct, flowShape(L.sampling, p), cs.coverage, sa);
  if (shape <= 0.0) return cs;
  real da = densityProfile(cs.ct, ph) * weather.y * layerPresence(ph, L.band);
  if (da <= 0.0 || cheap) {
    cs.rho = max(da, 0.0) * shape;
    return cs;
  }
  // Erosion leaves a full shape (1) full: the detail fetch only at the edges.
  cs.rho = (shape < 1.0 ? erodeShape(cs.ct, shape, flowDetail(L.sampling, p), cs.coverage, ph) : 1.0) * da;
  return cs;
}

// Showers under their carrier's cells: a precipitation layer whose top is
// inside a cloud layer (CoreLayer::carrier) falls only where that layer's
// cells are, seen from below: where its shape noise at kFootprintHeight of
// its shell over p is above its coverage there (after the cloud map, as
// cloudSample's threshold for the body of its cloud before erosion), rising
// to 1 over kFootprintEdge noise units inside; so showers fall under the
// cumulus that drop them and not from the clear sky between.
// carrierFootprint's x is that footprint; y the gain that makes the rain's
// own coverage a share of the carrier's (its coverage over the carrier's,
// capped at 1 by cloudSample), so that coverage c_p under cells of cover c_c
// still wets c_p of the ground. A closed carrier (coverage 1) covers
// everything. h: p's height above the camera's sphere of radius r.
SKY_CORE_CONST real kFootprintHeight = 0.2;
SKY_CORE_CONST real kFootprintEdge = 0.12;
real2 carrierFootprint(CoreLayer C, real3 p, real h, real r) {
  real3 q = p + upAt(p, r) * (kFootprintHeight * C.thickness - C.hBase - h);
  LayerSampling s = flowAt(C.sampling, q);
  real cover = sampleWeather(s, q).x;
  if (cover <= 0.0) return real2(0.0, 1.0);
  if (cover >= 1.0) return real2(1.0, 1.0);
  real c = mappedCoverage(cover, flowCloudMap(s, q).x);
  real2 shape = flowShape(s, q);
  real n = mix(shape.x, shape.y, C.primary.fibrous);
  return real2(saturate1((n - (1.0 - c)) / kFootprintEdge), 1.0 / cover);
}

// cloudSample of layer L, under its carrier's cells where it has one. The
// footprint scales the cheap density as the full one, so the cheap sample
// stays > 0 wherever the full one is (without it in the cheap sample the
// long steps found rain wherever its own noise has it and marched the
// whole shaft layer in short steps: slower). One cloudSample, the footprint
// first: lavapipe runs both sides of a branch for all lanes, and two inlined
// cloudSamples behind early returns cost more than reading the footprint
// for every sample of the rain. The carrier is read per sample of a
// precipitation layer only (a CoreLayer held live across the span's loop
// costs every layer's march).
CloudSample layerSample(CoreLayer L, real3 p, real h, real ph, bool cheap, real r) {
  real2 foot = real2(1.0);
  if (kShowers && L.carrier >= 0 && ph > 0.0 && ph < 1.0) foot = carrierFootprint(layerAt(L.carrier), p, h, r);
  CloudSample cs = cloudSample(L, p, ph, cheap, foot.y);
  cs.rho *= foot.x;
  return cs;
}

// The direct sun's mean transmittance over a broken field: a fraction c of
// the rays meets a column of optical depth tau (at sun cosine mu), the rest
// passes clear.
real brokenFieldTransmittance(real c, real tau, real mu) {
  return 1.0 - c * (1.0 - exp(-tau / mu));
}

// Transmission of sunlight and sky light down through the first `count`
// layers to the point p (camera-relative, height hp above the ground
// sphere): each layer above p (the part above p where p is inside it) by
// its coverage c and density at the middle of that part: for the direct
// beam where the sun ray crosses it, for the diffuse light straight above p
// (the sky's light and what the clouds diffuse come down from all over the
// sky above p, most of it from near the zenith; where the sun ray crosses
// is tens of kilometres away at a low sun, and a rain shaft under a storm
// was lit by the open sky beyond it). A fraction c of the rays there meets
// a cloud column of optical depth tau (the type's mean column depth times
// the density), the rest passes clear, so the mean transmittance is
// 1 - c (1 - T(tau)) with the two-stream split of diffuseLight:
// T = e^(-tau/mu) for the direct beam, t(tau) for the light the clouds
// diffuse (the mean of the transmittance over a broken field, not the
// transmittance of its mean depth, which at half cover of a cumulus
// kilometres deep would be dark). x: direct sun factor, y: diffuse factor
// for the sun's scattered part and the sky.
// Shadows at the weather map's scale (~1 km), without the noise's shapes:
// on the ground, and in the air (the shade under an overcast, the light
// shafts between regions of cloud).
// `skip`: a layer left out (the one p is marched in, whose own shadow the
// light march gives), or -1.
real2 cloudShadow(AirFrame a, int count, int skip, real3 p, real hp, real muSun) {
  real direct = 1.0;
  real diffuse = 1.0;
  real mu = max(muSun, kMinSunCosine);
  real groundRadius = a.r - a.h;
  real rp = groundRadius + hp;
  for (int k = 0; k < count; ++k) {
    if (k == skip) continue;  // before layerAt: a layer read per cloud sample is not free
    CoreLayer L = layerAt(k);
    real top = a.h - L.hTop;
    if (L.absent || hp >= top) continue;
    real lo = max(hp, a.h - L.hBase);
    real hMid = 0.5 * (lo + top);
    // Distance along the sun from p up to the height hMid (stable sphere root).
    real c2 = (hMid - hp) * (2.0 * groundRadius + hMid + hp);
    real d = c2 / (rp * mu + sqrt(rp * rp * mu * mu + c2));
    real presence = layerPresenceAbove((lo - (a.h - L.hBase)) / L.thickness, L.band);
    real3 weather = sampleWeather(L.sampling, p + a.sunDir * d);
    CloudType t = L.blends ? mixCloudType(L.primary, L.secondary, weather.z) : L.primary;
    real tau = t.extinction_perm * weather.y * t.columnFill * L.thickness * presence;
    direct *= brokenFieldTransmittance(clamp(weather.x, 0.0, 1.0), tau, mu);
    // Straight above p at hMid: p's own vertical, from the Earth's centre
    // at (0, 0, -r) in the camera-relative frame.
    real3 fromCentre = p + real3(0.0, 0.0, a.r);
    real3 overhead = fromCentre * ((groundRadius + hMid) / length(fromCentre)) - real3(0.0, 0.0, a.r);
    real3 above = sampleWeather(L.sampling, overhead);
    CloudType ta = L.blends ? mixCloudType(L.primary, L.secondary, above.z) : L.primary;
    real tauAbove = ta.extinction_perm * above.y * ta.columnFill * L.thickness * presence;
    diffuse *= 1.0 - clamp(above.x, 0.0, 1.0) * (1.0 - 1.0 / (1.0 + 0.75 * (1.0 - kDiffuseAsymmetry) * tauAbove));
  }
  return real2(direct, diffuse);
}

#include "sun_map.glsl"

// The sun's shadow in the air at p (the airCloudShadow hook's body):
// cloudShadow's, with the direct beam from the sun map where the frame has
// one (light shafts at the scale of the clouds' shapes), or from the column
// marched with the map's buildSteps per layer (the ground truth's).
real2 airSunShadow(AirFrame a, real3 p, real h, real muSun) {
  real2 shade = cloudShadow(a, a.shadowLayers, -1, p, h, muSun);
  real tau = sunDepthAbove(a, p, muSun, gSunMap.buildSteps, a.shadowLayers);
  shade.x = tau >= 0.0 ? exp(-tau) : shade.x;
  return shade;
}

// Marches one layer's span front to back; transmittanceBefore (what the
// layers in front left) only decides the early exit. Each sample stands for
// a segment of the span (evenly: span / primarySteps; in metres: the step
// there) and sits at the pixel's jitter along it.
LayerResult marchLayer(CoreFrame f, int li, real3 dir, Span s, real jitter, real transmittanceBefore) {
  CoreLayer L = layerAt(li);
  LayerResult res = LayerResult(real3(0.0), 1.0, 0.5 * (s.t0 + s.t1));
  if (L.absent) return res;
  real steps = real(f.march.primarySteps);
  real evenDt = (s.t1 - s.t0) / steps;
  bool metres = f.march.cloudStep > 0.0;
  // The phase of each octave depends on the angle to the sun only: once per
  // span for each of the layer's two types.
  real nu = dot(dir, f.air.sunDir);
  real4 phases1 = octavePhases(nu, L.primary);
  real4 phases2 = L.blends ? octavePhases(nu, L.secondary) : phases1;
  // Sunlight through the clear air at the span's two ends, at the layer's
  // base and top: per sample it is interpolated (the table varies over
  // kilometres of height and degrees of sun angle; a span spans 0.5 degrees
  // of Earth at most), which saves a table lookup per sample.
  real groundRadius = f.air.r - f.air.h;
  real baseHeight = f.air.h - L.hBase;
  real topHeight = f.air.h - L.hTop;
  real muStart = dot(upAt(dir * s.t0, f.air.r), f.air.sunDir);
  real muEnd = dot(upAt(dir * s.t1, f.air.r), f.air.sunDir);
  real3 sunBaseStart = f.air.sunIrradiance * sunTransmittance(baseHeight, muStart, groundRadius);
  real3 sunTopStart = f.air.sunIrradiance * sunTransmittance(topHeight, muStart, groundRadius);
  real3 sunBaseEnd = f.air.sunIrradiance * sunTransmittance(baseHeight, muEnd, groundRadius);
  real3 sunTopEnd = f.air.sunIrradiance * sunTransmittance(topHeight, muEnd, groundRadius);
  real spanLength = max(s.t1 - s.t0, 1e-6);
  real depthSum = 0.0;
  real weightSum = 0.0;
  // Even: fi is the sample's index along the span; a sample that meets no
  // cloud moves it on by emptyStride (1: every sample), one that does by 1.
  // Metres: segStart is where the current step begins; `longSteps` while the
  // march is in clear air.
  real fi = 0.0;
  real segStart = s.t0;
  bool longSteps = metres;
  int emptyRun = 0;
  real shortUntil = s.t0;  // the short steps go on at least to where a long step met cloud
  for (int i = 0; i < f.march.primarySteps; ++i) {
    if (metres ? segStart >= s.t1 : fi >= steps) break;
    if (transmittanceBefore * res.transmittance < f.march.minTransmittance) break;
    real step = (longSteps ? f.march.emptyStep : f.march.cloudStep) + f.march.stepGrowth * segStart;
    real len = metres ? min(step * L.stepFactor, s.t1 - segStart) : evenDt;
    real t = metres ? segStart + jitter * len : s.t0 + (fi + jitter) * evenDt;
    real3 p = dir * t;
    real h = heightAboveCameraSphere(p, f.air.r);
    real ph = (h + L.hBase) / L.thickness;
    CloudSample cs = layerSample(L, p, h, ph, longSteps, f.air.r);
    if (longSteps) {
      // Cloud ahead: march this step again in short steps (it stays at
      // segStart); clear: the whole long step is.
      if (cs.rho > 0.0) {
        longSteps = false;
        emptyRun = 0;
        shortUntil = t;
      } else {
        segStart += len;
      }
      continue;
    }
    if (cs.rho <= 0.0) {
      fi += f.march.emptyStride;
      segStart += len;
      ++emptyRun;
      longSteps = metres && emptyRun >= kEmptyRunToLongSteps && segStart > shortUntil &&
                  f.march.emptyStep > f.march.cloudStep;
      continue;
    }
    fi += 1.0;
    segStart += len;
    emptyRun = 0;
    CloudType ct = cs.ct;
    real u = (t - s.t0) / spanLength;
    real muHere = mix(muStart, muEnd, u);
    // The sun's optical depth: the layer's own light march, or (a map, the
    // column) every layer's; on the GPU the method is a pipeline constant,
    // so the ways not taken are compiled out.
    bool march = gSunMap.method == kSunMarch;
    LayerSampling lightSampling = L.sampling;
    lightSampling.flowShift = cs.flowShift;
    lightSampling.flowShiftB = cs.flowShiftB;
    real tauSun = lightOpticalDepth(f.air.sunDir, muHere, L.thickness, L.band, L.lightDistance, lightSampling, ct, p,
                                    ph, cs.coverage, cs.peakNoise, cs.densityScale, f.march.lightSteps,
                                    march && cs.rho > 0.0 ? f.march.lightSteps : 0);
    real above = sunDepthAbove(f.air, p, muHere, f.march.lightSteps, f.layerCount);
    // Past the map's last cascade, the layer's own shadow at the weather
    // map's scale (diffuseLight's column above p, as cloudShadow takes a
    // layer's), and the other layers' from cloudShadow.
    real ownAbove =
        ct.extinction_perm * cs.densityScale * ct.columnFill * layerPresenceAbove(ph, L.band) * L.thickness;
    real ownFar = -log(max(brokenFieldTransmittance(cs.coverage, ownAbove, max(muHere, kMinSunCosine)), 1e-6));
    if (!march) tauSun = above >= 0.0 ? above : ownFar;
    // Sunlight at p through the clear air above it (reddened at low sun,
    // none in the Earth's shadow) and the other layers' clouds above it
    // (cirrus over cumulus, a deck over a layer), and the sky's light from
    // all around, dimmed by those layers as well.
    real3 sun = mix(mix(sunBaseStart, sunTopStart, ph), mix(sunBaseEnd, sunTopEnd, ph), u);
    real2 shade = cloudShadow(f.air, f.layerShadows, li, p, f.air.h + h, muHere);
    // The map and the column hold the other layers' shadow in tauSun.
    shade.x = above >= 0.0 ? 1.0 : shade.x;
    real3 scattered = sun * (shade.x * octaveSum(mix(phases1, phases2, cs.blend), tauSun)) +
                      diffuseLight(L, ct, ph, cs.coverage, cs.densityScale) * (shade.y * kAmbientGain);
    if (kLightning) scattered += flashInscatter(f.flashCount, p);
    // Hillaire 2016 energy-conserving step: integral over the step of
    // sigma_s L e^{-sigma_t s} = albedo L (1 - e^{-sigma_t len}); its limit
    // as sigma_t -> 0 is sigma_s L len (scatterFraction).
    real x = ct.extinction_perm * cs.rho * len;
    real absorbed = x * scatterFraction(x);  // 1 - e^{-x}, exact near 0
    res.inscatter += scattered * (kAlbedo * absorbed) * res.transmittance;
    real weight = res.transmittance * absorbed;
    depthSum += weight * t;
    weightSum += weight;
    res.transmittance *= 1.0 - absorbed;
  }
  if (weightSum > 0.0) res.depth = depthSum / weightSum;
  return res;
}

// Lambertian ground at distance t along dir: sunlight and sky light through
// the air and the cloud layers above it.
real3 groundRadiance(CoreFrame f, real3 dir, real t) {
  real3 p = dir * t;
  real muSun = dot(upAt(p, f.air.r), f.air.sunDir);
  real3 sun = f.air.sunIrradiance * sunTransmittance(0.0, muSun, f.air.r - f.air.h) * max(muSun, 0.0);
  real2 shadow = cloudShadow(f.air, f.layerCount, -1, p, 0.0, muSun);
  real tau = sunDepthAbove(f.air, p, muSun, gSunMap.buildSteps, f.layerCount);
  shadow.x = tau >= 0.0 ? exp(-tau) : shadow.x;
  real3 light = sun * (shadow.x + (1.0 - shadow.x) * shadow.y) + f.groundIrradiance * shadow.y;
  return light * (kGroundAlbedo / kPi);
}

// The air along dir up to tEnd (airRayEnd's), at the queried distances:
// from the table or marched. Both are called, the one not wanted with no
// queries: on the GPU airFromTable is a pipeline constant, so its loops
// have no turns and are compiled out (a branch would not do: lavapipe runs
// both sides of one for every lane); on the CPU it does no work.
AirPath airAlongRay(CoreFrame f, real3 dir, real tEnd, real q[kAirQueries], int count) {
  AirPath fromTable = airPathFromTable(f.air, f.airTable, dir, tEnd, q, f.airFromTable ? count : 0);
  AirPath marched = marchAir(f.air, dir, tEnd, q, f.airFromTable ? 0 : count);
  if (f.airFromTable) return fromTable;
  return marched;
}

// What lies behind the air along dir: the ground at tEnd, or the night sky
// past the atmosphere. The ground in a loop run once or not at all: on the
// CPU a sky pixel skips it; on lavapipe it costs what a select would (one
// turn of a loop runs even when no lane enters it).
real3 backgroundRadiance(CoreFrame f, real3 dir, real tEnd) {
  real3 background = real3(kNightSkyRadiance);
  for (int once = tEnd < kFarAway_m ? 1 : 0; once > 0; --once) background = groundRadiance(f, dir, tEnd);
  return background;
}

// A pixel of a clear sky: the air and what lies behind it.
PixelResult shadeClearPixel(CoreFrame f, real3 dir) {
  real tEnd = airRayEnd(f.air, dir.z);
  real q[kAirQueries];
  for (int k = 0; k < kAirQueries; ++k) q[k] = tEnd;
  AirPath air = airAlongRay(f, dir, tEnd, q, 1);
  return PixelResult(air.inscatter[0] + backgroundRadiance(f, dir, tEnd) * air.transmittance[0], 1.0, 0.0);
}

// Radiance along dir (unit, local frame): the layers front to back, each seen
// through the air in front of it (aerial perspective at the layer's depth),
// the air's own light between them, and the ground or space behind
// (Patapom's premultiplied compositing: background times transmittance plus
// in-scattering).
PixelResult shadePixel(CoreFrame f, real3 dir, real jitter) {
  if (!f.clouds) return shadeClearPixel(f, dir);
  real mu = dir.z;
  real tEnd = airRayEnd(f.air, mu);
  bool hitsGround = tEnd < kFarAway_m;
  real tGround = hitsGround ? tEnd : kMaxViewDistance_m + kMaxSpan_m;

  Span spans[kMaxLayers];
  int order[kMaxLayers];
  // The layers' reads in a loop that ends at the frame's count, not in a
  // select over all kMaxLayers slots: lavapipe evaluates both sides of a
  // select for every lane, and in the clear sky's pipeline the count is a
  // constant 0, which compiles the loop out.
  for (int i = 0; i < int(kMaxLayers); ++i) {
    spans[i] = Span(0.0, 0.0);
    order[i] = i;
  }
  for (int i = 0; i < f.layerCount; ++i) spans[i] = layerSpan(f, layerAt(i), mu, tGround);
  // Sorted by entry distance, so layers composite front to back: a bubble
  // sort over all slots with fixed bounds and swaps by select (the unused
  // slots last), which compiles to straight-line code. With the insertion
  // sort's data-dependent inner loop lavapipe left the layers unsorted for
  // a camera above two of them (GpuVsCpu.TwoLayersWithinTolerance).
  real key[kMaxLayers];
  for (int i = 0; i < int(kMaxLayers); ++i) key[i] = i < f.layerCount ? spans[i].t0 : kFarAway_m;
  for (int pass = 0; pass < int(kMaxLayers) - 1; ++pass) {
    for (int j = 0; j < int(kMaxLayers) - 1 - pass; ++j) {
      bool swap = key[j] > key[j + 1];
      real k0 = key[j], k1 = key[j + 1];
      int o0 = order[j], o1 = order[j + 1];
      key[j] = swap ? k1 : k0;
      key[j + 1] = swap ? k0 : k1;
      order[j] = swap ? o1 : o0;
      order[j + 1] = swap ? o0 : o1;
    }
  }
  LayerResult layers[kMaxLayers];
  real q[kAirQueries];
  int n = 0;
  real cloudT = 1.0;
  for (int k = 0; k < f.layerCount; ++k) {
    Span s = spans[order[k]];
    if (s.t1 <= s.t0 || cloudT < f.march.minTransmittance) continue;
    LayerResult r = marchLayer(f, order[k], dir, s, jitter, cloudT);
    if (r.transmittance >= 1.0) continue;  // met no cloud
    layers[n] = r;
    q[n] = n > 0 ? max(r.depth, q[n - 1]) : r.depth;
    cloudT *= r.transmittance;
    ++n;
  }
  q[n] = tEnd;
  AirPath air = airAlongRay(f, dir, tEnd, q, n + 1);

  // Cloud depth (an output, not part of the light): each layer's mean depth
  // weighted by the light it takes out of the view ray, Tbefore (1 - T), so
  // the pixel's depth is the mean distance at which the clouds remove light.
  real3 radiance = real3(0.0);
  real3 airBefore = real3(0.0);
  real transmittance = 1.0;
  real depthSum = 0.0;
  for (int k = 0; k < n; ++k) {
    radiance += (air.inscatter[k] - airBefore) * transmittance;
    radiance += layers[k].inscatter * air.transmittance[k] * transmittance;
    depthSum += transmittance * (1.0 - layers[k].transmittance) * layers[k].depth;
    transmittance *= layers[k].transmittance;
    airBefore = air.inscatter[k];
  }
  radiance += (air.inscatter[n] - airBefore) * transmittance;
  radiance += backgroundRadiance(f, dir, tEnd) * air.transmittance[n] * transmittance;
  // A lightning channel, seen through the layers whose light comes from in
  // front of it and the air between.
  for (int once = kLightning && f.boltCount > 0 ? 1 : 0; once > 0; --once) {
    real2 bolt = boltRadiance(f.boltCount, f.pixelAngle, dir);
    real seen = 1.0;
    for (int k = 0; k < n; ++k) seen *= layers[k].depth < bolt.y ? layers[k].transmittance : 1.0;
    // The air up to the bolt, a few kilometres: its extinction at the
    // middle of the path, with the view ray's haze (marchAir's).
    real hMid = f.air.h + 0.5 * dir.z * bolt.y;
    real3 sigma = airExtinction(hMid) + real3(f.air.aerosolExcess * kMieExtinction_perm * mieDensity(hMid));
    radiance += flashColour() * (bolt.x * seen) * exp(-sigma * bolt.y);
  }
  real depth = transmittance < 1.0 ? depthSum / (1.0 - transmittance) : 0.0;
  return PixelResult(radiance, transmittance, depth);
}

#undef SKY_MODEL_CONST
