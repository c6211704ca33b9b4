// The cloud model, written once in the subset GLSL and C++ share: camera rays,
// ray-shell spans, density, phase function, the per-step integration and the
// march. Included by shaders/clouds.comp (real = float) and, inside a class
// body, by renderer/core/src/cpu_reference.cpp (real = double).
// The includer defines real, real2, real3, uint, SKY_CORE_CONST, kMaxLayers and
// the two texture hooks before including this file:
//   real2 sampleWeather(int layer, real3 pLocal)  // (coverage, density), 0 outside the map
//   real  sampleNoise(int layer, real3 pLocal)    // tileable shape noise in [0, 1]
//   real  sampleCloudMap(int layer, real3 pLocal) // the same noise at a larger, incommensurate period
// pLocal is camera-relative, local frame: x east, y north, z up (m).

SKY_CORE_CONST real kPi = 3.14159265358979323846;

// Extinction per unit density, 1/m. formulas.md: cumulus sigma_t ~ 0.05-0.15,
// stratus 0.01-0.05; the low end keeps a 48-step march from aliasing edges.
SKY_CORE_CONST real kExtinctionPerDensity_perm = 0.05;
// Single-scattering albedo of cloud droplets in the visible (formulas.md: 0.999+).
SKY_CORE_CONST real kAlbedo = 0.999;
// Cloud droplet diameter for the Jendersie-d'Eon fitted Mie phase function,
// um: the fit holds for 5-50; 10 um is a typical cumulus droplet (effective
// radius ~5-10 um), and formulas.md lists the fitted parameters there.
SKY_CORE_CONST real kDropletDiameter_um = 10.0;
// Wrenninge 2015 multiple-scattering octaves: octave i scales the extinction
// towards the sun by a^i, its contribution by b^i and the phase eccentricity
// by c^i; a <= b keeps the sum energy-conserving. a = b = c = 0.5 as in
// formulas.md; 4 octaves (Ford uses 8; the 5th adds under 3 %).
SKY_CORE_CONST int kScatterOctaves = 4;
SKY_CORE_CONST real kOctaveExtinction = 0.5;
SKY_CORE_CONST real kOctaveContribution = 0.5;
SKY_CORE_CONST real kOctaveEccentricity = 0.5;
// Primary samples per layer span; fixed so cost is predictable (lavapipe.md:
// ~9.5 ns per primary step, 60-130 lookups per pixel fit a 33 ms frame).
SKY_CORE_CONST int kPrimarySteps = 48;
// Light samples towards the sun (Haggstrom 2018: 4 was the best trade).
SKY_CORE_CONST int kLightSteps = 4;
// Distance the light march covers, m (Haggstrom: about half a cumulus layer).
SKY_CORE_CONST real kLightMarchDistance_m = 500.0;
// Longest span marched through one layer, m: beyond this a grazing ray's
// samples would be more than ~1.2 km apart and only add noise.
SKY_CORE_CONST real kMaxSpan_m = 60000.0;
// Spans starting farther than this are not marched, m: the weather map reaches
// 100 km (gnomonic half extent), its corners about 141 km.
SKY_CORE_CONST real kMaxViewDistance_m = 150000.0;
// Early exit once the view ray keeps less than 1 % of the background.
SKY_CORE_CONST real kMinTransmittance = 0.01;
// Width of the soft coverage threshold in noise units: density ramps from 0 at
// noise = 1 - coverage to full at 1 - coverage + kCoverageEdge, so coverage 0 is
// exactly empty and coverage 1 is nearly solid.
SKY_CORE_CONST real kCoverageEdge = 0.25;
// Height profile inside a layer (fractions of the thickness): rounded base and
// a thinner top, the shape of Haggstrom's SA term without the weather inputs.
SKY_CORE_CONST real kProfileBottomFade = 0.1;
SKY_CORE_CONST real kProfileTopFade = 0.2;
// How far the cloud map moves partial coverage (Schneider's low-frequency
// weather channel): c' = c + A (m - 0.5) 4c(1 - c), so coverage 0 and 1 stay
// exact and 0.5 spans [0.2, 0.8]; breaks up the noise's 5 km repetition.
SKY_CORE_CONST real kCloudMapAmplitude = 0.6;
// Ambient light at a layer's base relative to its top (the base sees the dark
// ground and is shadowed by the cloud above it).
SKY_CORE_CONST real kAmbientBottomFactor = 0.3;
// Optical depth below which a step uses the sigma_t -> 0 limit of its integral.
SKY_CORE_CONST real kSmallOpticalDepth = 1e-4;
// 2^-24: maps the top 24 bits of a hash to [0, 1) exactly in float.
SKY_CORE_CONST real kInv2Pow24 = 5.9604644775390625e-8;
// Background radiances (linear, arbitrary units shared with the sun): a plain
// zenith-to-horizon gradient and a darker ground until the atmosphere arrives.
SKY_CORE_CONST real kSkyZenithR = 0.20, kSkyZenithG = 0.38, kSkyZenithB = 0.80;
SKY_CORE_CONST real kSkyHorizonR = 0.62, kSkyHorizonG = 0.72, kSkyHorizonB = 0.85;
SKY_CORE_CONST real kGroundR = 0.16, kGroundG = 0.15, kGroundB = 0.12;

struct CoreLayer {
  real hBase;      // camera height above the layer base, m (negative below)
  real hTop;       // camera height above the layer top, m
  real cBase;      // hBase (2r - hBase), m^2
  real cTop;       // hTop (2r - hTop), m^2
  real thickness;  // m, > 0
};

struct CoreFrame {
  real r;        // camera distance from the (local) Earth centre, m
  real cGround;  // hGround (2r - hGround), m^2; hGround = camera altitude
  real3 sunDir;  // unit, local frame
  real3 sunRadiance;
  real3 ambient;
  int layerCount;
  CoreLayer layers[kMaxLayers];
};

struct Roots {
  bool hit;
  real t0;  // t0 <= t1
  real t1;
};

struct Span {
  real t0;  // empty when t1 <= t0
  real t1;
};

struct MarchState {
  real3 inscatter;
  real transmittance;
  // Cloud depth output (not part of the light): sum over steps of the
  // distance times the light the step removed from the view ray, and the sum
  // of those weights; depth = depthSum / depthWeight.
  real depthSum;
  real depthWeight;
};

struct PixelResult {
  real3 radiance;
  real transmittance;
  real depth;  // transmittance-weighted distance to the cloud, m; 0 when no cloud was met
};

// PCG hash (Jarzynski & Olano 2020, "Hash Functions for GPU Rendering", pcg).
uint hashPcg(uint x) {
  uint state = x * 747796405u + 2891336453u;
  uint word = ((state >> ((state >> 28u) + 4u)) ^ state) * 277803737u;
  return (word >> 22u) ^ word;
}

// Per-pixel sample offset in [0, 1): depends on the pixel only, so a frame is
// reproducible (no frame index, no clock).
real pixelJitter(uint px, uint py) {
  return real(hashPcg(px + hashPcg(py)) >> 8u) * kInv2Pow24;
}

// View ray through the centre of pixel (px, py), top row first; camera axes in
// the local frame, tanHalfFov of the vertical field of view, aspect = w / h.
real3 cameraRay(real3 forward, real3 right, real3 down, real tanHalfFov, real aspect,
                real px, real py, real width, real height) {
  real sx = ((px + 0.5) / width * 2.0 - 1.0) * tanHalfFov * aspect;
  real sy = (1.0 - (py + 0.5) / height * 2.0) * tanHalfFov;
  return normalize(forward + right * sx - down * sy);
}

// Ray from a point at distance r from the centre against the sphere with
// c = h (2r - h) (h = height above it, exact from altitudes); mu = cos zenith.
// Stable (citardauq) form, as protocol/geo/src/shell.cpp.
Roots intersectSphere(real r, real c, real mu) {
  real b = r * mu;
  real disc = b * b - c;
  if (disc < 0.0) return Roots(false, 0.0, 0.0);
  real s = sqrt(disc);
  real q = -(b + (b >= 0.0 ? s : -s));
  real ta = q;
  real tb = q != 0.0 ? c / q : 0.0;
  return Roots(true, min(ta, tb), max(ta, tb));
}

// Height of p above the sphere through the camera, m, without forming
// |p - centre| - r from two Earth-sized numbers: (|q|^2 - r^2) / (|q| + r).
real heightAboveCameraSphere(real3 p, real r) {
  real num = 2.0 * r * p.z + dot(p, p);
  return num / (sqrt(max(r * r + num, 0.0)) + r);
}

// Part of the ray inside one layer's shell, clipped by the ground and the
// march limits. Handles cameras below, inside and above the layer.
Span layerSpan(CoreFrame f, CoreLayer L, real mu, real tGround) {
  Roots base = intersectSphere(f.r, L.cBase, mu);
  Roots top = intersectSphere(f.r, L.cTop, mu);
  real t0 = 0.0;
  real t1 = 0.0;
  if (L.hBase < 0.0) {
    // Below: inside both spheres, so both are hit; leave the base, then the top.
    t0 = base.t1;
    t1 = top.t1;
  } else if (L.hTop < 0.0) {
    // Inside: until the top, or the base if the ray reaches it first.
    t1 = top.t1;
    if (base.hit && base.t0 >= 0.0) t1 = min(t1, base.t0);
  } else if (top.hit && top.t1 > 0.0) {
    // Above: from the top down to the base, or out through the top again.
    t0 = max(top.t0, 0.0);
    t1 = (base.hit && base.t0 >= 0.0) ? base.t0 : top.t1;
  }
  t1 = min(t1, tGround);
  t1 = min(t1, t0 + kMaxSpan_m);
  if (t0 > kMaxViewDistance_m) t1 = t0;
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

// Sun light scattered towards the viewer at a point with optical depth tauSun
// towards the sun, per unit sun radiance: Wrenninge's octave sum
// sum_i b^i p(theta, c^i g) exp(-a^i tauSun), given the octaves' phase values.
real octaveSum(real phases[kScatterOctaves], real tauSun) {
  real sum = 0.0;
  real a = 1.0;
  real b = 1.0;
  for (int i = 0; i < kScatterOctaves; ++i) {
    sum += b * phases[i] * exp(-a * tauSun);
    a *= kOctaveExtinction;
    b *= kOctaveContribution;
  }
  return sum;
}

// Vertical profile in [0, 1] for ph = height fraction within the layer; 0
// outside [0, 1].
real heightProfile(real ph) {
  return clamp(ph / kProfileBottomFade, 0.0, 1.0) * clamp((1.0 - ph) / kProfileTopFade, 0.0, 1.0);
}

// Coverage in [0, 1] after the cloud map m in [0, 1] moved it; 0 and 1 are fixed points.
real mappedCoverage(real coverage, real m) {
  return clamp(coverage + kCloudMapAmplitude * (m - 0.5) * 4.0 * coverage * (1.0 - coverage), 0.0, 1.0);
}

// Density in [0, 1] from shape noise n in [0, 1], coverage in [0, 1], the
// layer's density multiplier and the height fraction ph. Coverage 0 gives
// exactly 0 (n <= 1); the remap follows Ford's N - (1 - coverage).
real cloudDensity(real n, real coverage, real density, real ph) {
  if (coverage <= 0.0) return 0.0;
  real shaped = clamp((n - (1.0 - coverage)) / kCoverageEdge, 0.0, 1.0);
  return shaped * heightProfile(ph) * density;
}

real3 skyBackground(real3 dir, bool hitsGround) {
  if (hitsGround) return real3(kGroundR, kGroundG, kGroundB);
  real t = sqrt(clamp(dir.z, 0.0, 1.0));
  return mix(real3(kSkyHorizonR, kSkyHorizonG, kSkyHorizonB), real3(kSkyZenithR, kSkyZenithG, kSkyZenithB), t);
}

// Marches one layer's span front to back, continuing state st.
MarchState marchLayer(CoreFrame f, int li, real3 dir, Span s, real jitter, MarchState st) {
  CoreLayer L = f.layers[li];
  real dt = (s.t1 - s.t0) / real(kPrimarySteps);
  // The phase of each octave depends on the angle to the sun only: once per span.
  MieFit mie = mieFit(kDropletDiameter_um);
  real phases[kScatterOctaves];
  real gScale = 1.0;
  for (int o = 0; o < kScatterOctaves; ++o) {
    phases[o] = phaseMie(dot(dir, f.sunDir), mie, gScale);
    gScale *= kOctaveEccentricity;
  }
  real lightDt = kLightMarchDistance_m / real(kLightSteps);
  for (int i = 0; i < kPrimarySteps; ++i) {
    if (st.transmittance < kMinTransmittance) break;
    real3 p = dir * (s.t0 + (real(i) + jitter) * dt);
    real ph = (heightAboveCameraSphere(p, f.r) + L.hBase) / L.thickness;
    if (heightProfile(ph) <= 0.0) continue;
    real2 weather = sampleWeather(li, p);
    if (weather.x <= 0.0) continue;
    if (weather.x < 1.0) weather.x = mappedCoverage(weather.x, sampleCloudMap(li, p));
    real rho = cloudDensity(sampleNoise(li, p), weather.x, weather.y, ph);
    if (rho <= 0.0) continue;
    // Optical depth towards the sun; the coverage of the primary sample stands
    // for the light path (it is a few hundred metres, the map's texel ~780 m).
    real tauSun = 0.0;
    for (int j = 0; j < kLightSteps; ++j) {
      real3 q = p + f.sunDir * ((real(j) + 0.5) * lightDt);
      real qh = (heightAboveCameraSphere(q, f.r) + L.hBase) / L.thickness;
      if (heightProfile(qh) <= 0.0) continue;
      tauSun += kExtinctionPerDensity_perm * cloudDensity(sampleNoise(li, q), weather.x, weather.y, qh) * lightDt;
    }
    real sigmaT = kExtinctionPerDensity_perm * rho;
    real ambientScale = mix(kAmbientBottomFactor, 1.0, clamp(ph, 0.0, 1.0));
    real3 scattered = f.sunRadiance * octaveSum(phases, tauSun) + f.ambient * ambientScale;
    // Hillaire 2016 energy-conserving step: integral over the step of
    // sigma_s L e^{-sigma_t s} = albedo L (1 - e^{-sigma_t dt}); its limit as
    // sigma_t -> 0 is sigma_s L dt.
    real stepT = exp(-sigmaT * dt);
    real3 gained = sigmaT * dt > kSmallOpticalDepth ? scattered * (kAlbedo * (1.0 - stepT))
                                                    : scattered * (kAlbedo * sigmaT * dt);
    st.inscatter += gained * st.transmittance;
    real removed = st.transmittance * (1.0 - stepT);
    st.depthSum += removed * (s.t0 + (real(i) + jitter) * dt);
    st.depthWeight += removed;
    st.transmittance *= stepT;
  }
  return st;
}

// Radiance along dir (unit, local frame): background times transmittance plus
// what the layers scatter in (Patapom's premultiplied form).
PixelResult shadePixel(CoreFrame f, real3 dir, real jitter) {
  real mu = dir.z;
  Roots ground = intersectSphere(f.r, f.cGround, mu);
  bool hitsGround = ground.hit && ground.t1 > 0.0;
  real tGround = hitsGround ? max(ground.t0, 0.0) : kMaxViewDistance_m + kMaxSpan_m;

  Span spans[kMaxLayers];
  int order[kMaxLayers];
  for (int i = 0; i < int(kMaxLayers); ++i) {
    spans[i] = i < f.layerCount ? layerSpan(f, f.layers[i], mu, tGround) : Span(0.0, 0.0);
    order[i] = i;
  }
  // Insertion sort by entry distance, so layers composite front to back.
  for (int i = 1; i < f.layerCount; ++i) {
    for (int j = i; j > 0 && spans[order[j - 1]].t0 > spans[order[j]].t0; --j) {
      int tmp = order[j];
      order[j] = order[j - 1];
      order[j - 1] = tmp;
    }
  }
  MarchState st = MarchState(real3(0.0), 1.0, 0.0, 0.0);
  for (int k = 0; k < f.layerCount; ++k) {
    Span s = spans[order[k]];
    if (s.t1 > s.t0) st = marchLayer(f, order[k], dir, s, jitter, st);
  }
  real depth = st.depthWeight > 0.0 ? st.depthSum / st.depthWeight : 0.0;
  return PixelResult(skyBackground(dir, hitsGround) * st.transmittance + st.inscatter, st.transmittance, depth);
}
