// The sun's transmittance through the clouds from a map built once per frame
// in sun space (Wang's comparison of cloud self-shadowing: exponential,
// Beer and Fourier opacity maps; Patapom's deep shadow maps), or marched
// towards the sun over the whole column. Written once for the GPU
// (shaders/sun_map.comp builds the map; the cloud and air-table passes read
// it) and the CPU reference. Part of cloud_core.glsl, included after
// cloudSample and cloudShadow. Needs the hooks
//   real4 sampleSunMap(int layer, real2 uv)   // layer `layer` of the map image, bilinear, clamped to the edge
// and, with SKY_SUN_MAP_BUILDER defined, the builder's
//   void storeSunMap(real4 part0, real4 part1) // the texel being built
// and the global (a data member in C++) gSunMap: the frame's map.
//
// Geometry. The sun's rays are parallel, so every point p lies on one sun
// line, p + s z (s towards the sun); the map is a grid over the plane
// through the map's centre perpendicular to s, (u, v) = ((p - origin).U,
// (p - origin).V), cascade c
// covering |u|, |v| < extent 4^c with `size` texels a side. Along its line a
// texel stores the clouds' extinction between where the line enters the
// highest layer's top shell and where it leaves through the lowest layer's
// base shell (or the top shell again, at grazing sun), as a function of
// x in [0, 1] over that length D. The entry and D are not stored: both
// follow from the line's geometry on the curved shells (sunLine), at the
// build from the texel's line and at a lookup from the point's own, so the
// map holds at every distance, at any sun height, and a point's x is exact
// where the bilinear lookup blends neighbouring lines.

// The ways of finding the sun's optical depth at a cloud sample.
// kSunMarch: Haggstrom's secondary march over the layer's light distance
// (lightSteps samples of the shape noise, truncated: no map). The others
// see every layer's whole column above the point, with the detail noise:
// kSunColumn marches it (lightSteps samples per layer crossed; with many
// steps it is the ground truth the maps are measured against);
// the maps store per texel, per line:
// * ESM (Annen et al. 2008 as Wang uses it): exp(c x_front); T = clamp(
//   exp(c x_front) exp(-c x), 0, 1): where the cloud starts, no density.
//   1 value.
// * BSM (Wang): front x, mean extinction over the cloud, total optical
//   depth; tau = min(total, mean (x - front)). 3 values.
// * FOM (Jansen & Bavoil 2010): the extinction's Fourier series over
//   [0, 1], a0..a3 and b1..b3; tau is its integral. 7 values.
// * Deep (Lokovic & Veach 2000's deep shadow map, at fixed knots):
//   the optical depth at x = 1/8, 2/8, ... 1, linear between. 8 values.
SKY_CORE_CONST int kSunMarch = 0;
SKY_CORE_CONST int kSunColumn = 1;
SKY_CORE_CONST int kSunEsm = 2;
SKY_CORE_CONST int kSunBsm = 3;
SKY_CORE_CONST int kSunFom = 4;
SKY_CORE_CONST int kSunDeep = 5;
// ESM's sharpness c over the line's unit length (Wang stores exp(cz) in
// 16-bit floats; 32-bit ones hold exp(80)).
SKY_CORE_CONST real kEsmSharpness = 60.0;
// Largest optical depth a map returns: ESM's transmittance is clamped to
// e^-80 (a normal float) so its log stays finite. Not lower: Wrenninge's
// third octave sees e^(-tau / 8), so a clamp at 12 (e^-1.5 there) lit the
// bases of towering clouds (measured: 24 against 40 dB on the
// cumulonimbus scene, every map alike, before it was raised).
SKY_CORE_CONST real kSunMaxDepth = 80.0;
// A texel's line gets buildSteps samples per layer, times its slant through
// the layer (length over thickness) up to this: at a sun 4 degrees up, 16
// samples across 14 km of a layer left 22 dB against the 1000-step column
// on the sunset-backlit scene, 64 gave 26.6 (256: 26.8).
SKY_CORE_CONST int kSunMapSlantFactor = 4;

struct SunMap {
  int method;      // kSunMarch .. kSunDeep
  int size;        // texels per edge of a cascade
  int cascades;    // 1..4
  int buildSteps;  // samples along each texel's line per layer crossed
  real extent;     // half extent of cascade 0, m
  real3 axisU;     // unit, perpendicular to the sun, local frame
  real3 axisV;     // unit, perpendicular to the sun and axisU
  real topHeight;  // m above the ground sphere: the highest drawn layer's top
  real baseHeight; // m: the lowest drawn layer's base
  // Each cascade's centre, camera-local: the camera where that cascade was
  // last built (sun_map_plan.hpp: a camera that moved rebuilds a cascade by
  // its own extent, so the coarse ones less often than the fine).
  real3 origin;
  real3 origin1;
  real3 origin2;
  real3 origin3;
  int readSlots;   // bit c: which of the image's two maps cascade c is read from
};

real4 sampleSunMap(int layer, real2 uv);

// The frame's map: a global on the GPU (loadFrameGlobals sets it, its
// method from a pipeline constant); in C++ a data member its includer
// declares with a value.
#ifndef __cplusplus
SunMap gSunMap;
#endif

// Image layers a cascade of the map takes (two RGBA parts at most).
int sunMapParts(int method) {
  return method == kSunFom || method == kSunDeep ? 2 : (method >= kSunEsm ? 1 : 0);
}

bool sunMapIsMap(int method) { return method >= kSunEsm; }

// The roots of z^2 + 2 b z - c2 = 0, upper and lower, without cancellation
// (their product is -c2).
real2 sunRoots(real b, real c2) {
  real q = sqrt(max(b * b + c2, 0.0));
  real upper = b > 0.0 ? c2 / (b + q) : q - b;
  real lower = b < 0.0 ? -c2 / (q - b) : -b - q;
  return real2(upper, lower);
}

// The line through a point at height hRef above the ground sphere (radius
// groundRadius) where the sun's cosine is mu: distances towards the sun
// from the point to the sphere at height H are the roots of
// z^2 + 2 (g + hRef) mu z - (H - hRef)(2g + H + hRef) = 0.
struct SunLine {
  real entry;   // distance towards the sun from the point to the top entry, m
  real span;    // D, m; 0 where the line misses the shells
};

SunLine sunLineAt(real hRef, real mu, real groundRadius, real top, real base) {
  real b = (groundRadius + hRef) * mu;
  real cTop = (top - hRef) * (2.0 * groundRadius + top + hRef);
  real cBase = (base - hRef) * (2.0 * groundRadius + base + hRef);
  bool hitsTop = b * b + cTop >= 0.0;
  bool hitsBase = b * b + cBase >= 0.0;
  real2 t = sunRoots(b, cTop);
  real2 s = sunRoots(b, cBase);
  real exit = hitsBase ? s.x : t.y;
  return SunLine(t.x, hitsTop ? max(t.x - exit, 0.0) : 0.0);
}

// What a column accumulates: the optical depth of the samples met, their
// first and last x, and each method's sums (see the method list).
struct SunColumn {
  real tau;
  real front;
  real back;
  real4 part0;
  real4 part1;
};

// The column with one sample of optical depth dtau at x added, the sample
// standing for x +- halfStep, and the sums `method` stores (no in/out
// parameters: the file is C++ too; on the GPU the method is a pipeline
// constant, so the others' sums are compiled out).
SunColumn sunColumnAdd(SunColumn c, int method, real x, real halfStep, real dtau) {
  if (dtau <= 0.0) return c;
  c.tau += dtau;
  c.front = min(c.front, max(x - halfStep, 0.0));
  c.back = max(c.back, min(x + halfStep, 1.0));
  if (method == kSunFom) {
    real w = 2.0 * kPi * x;
    c.part0 += 2.0 * dtau * real4(1.0, cos(w), cos(2.0 * w), cos(3.0 * w));
    c.part1 += 2.0 * dtau * real4(sin(w), sin(2.0 * w), sin(3.0 * w), 0.0);
  }
  if (method == kSunDeep) {
    // The sample adds to every knot past it.
    c.part0 += dtau * real4(x < 0.125 ? 1.0 : 0.0, x < 0.25 ? 1.0 : 0.0, x < 0.375 ? 1.0 : 0.0, x < 0.5 ? 1.0 : 0.0);
    c.part1 += dtau * real4(x < 0.625 ? 1.0 : 0.0, x < 0.75 ? 1.0 : 0.0, x < 0.875 ? 1.0 : 0.0, 1.0);
  }
  return c;
}

// Marches the line o + s z (o camera-local at height hO, sun cosine muO
// there) from its entry down to zLow (0: to o itself; entry - D: the whole
// line), `steps` samples per layer crossed, each layer over its own part of
// the line, times the part's length over the layer's thickness up to
// `slantFactor` (1: `steps` at any sun); x of a sample is (entry - z) / D.
// The part sums are those `method` stores (sunColumnAdd).
SunColumn sunColumnMarch(AirFrame a, real3 o, real hO, real muO, SunLine line, real zLow, int steps, int layers,
                         int method, int slantFactor) {
  SunColumn c;
  c.tau = 0.0;
  c.front = 1.0;
  c.back = 0.0;
  c.part0 = real4(0.0);
  c.part1 = real4(0.0);
  real groundRadius = a.r - a.h;
  real b = (groundRadius + hO) * muO;
  real invLength = 1.0 / max(line.span, 1e-6);
  for (int k = 0; k < layers; ++k) {
    CoreLayer L = layerAt(k);
    if (L.absent) continue;
    real top = a.h - L.hTop;
    real base = a.h - L.hBase;
    real cTop = (top - hO) * (2.0 * groundRadius + top + hO);
    real cBase = (base - hO) * (2.0 * groundRadius + base + hO);
    if (b * b + cTop < 0.0) continue;
    real2 t = sunRoots(b, cTop);
    real2 s = sunRoots(b, cBase);
    real z1 = t.x;
    real z0 = max(b * b + cBase >= 0.0 ? s.x : t.y, zLow);
    if (z1 <= z0) continue;
    int n = steps * int(clamp(floor((z1 - z0) / L.thickness + 0.5), 1.0, real(slantFactor)));
    real dz = (z1 - z0) / real(n);
    for (int i = 0; i < n; ++i) {
      real z = z1 - (real(i) + 0.5) * dz;
      real3 q = o + a.sunDir * z;
      real hq = heightAboveCameraSphere(q, a.r);
      real ph = (hq + L.hBase) / L.thickness;
      CloudSample cs = layerSample(L, q, hq, ph, false, a.r);
      real dtau = cs.ct.extinction_perm * cs.rho * dz;
      c = sunColumnAdd(c, method, (line.entry - z) * invLength, 0.5 * dz * invLength, dtau);
    }
  }
  return c;
}

// The map's encoding of a texel's column: the two parts it stores.
struct SunParts {
  real4 part0;
  real4 part1;
};

SunParts sunMapEncode(int method, SunColumn c) {
  SunParts e = SunParts(real4(0.0), real4(0.0));
  bool any = c.tau > 0.0;
  if (method == kSunEsm) e.part0.x = exp(kEsmSharpness * (any ? c.front : 1.0));
  // BSM's mean extinction over at least 1/64 of the line: one thin sample
  // does not make it infinite.
  if (method == kSunBsm)
    e.part0 = real4(any ? c.front : 1.0, any ? c.tau / max(c.back - c.front, 1.0 / 64.0) : 0.0, c.tau, 0.0);
  if (method == kSunFom || method == kSunDeep) e = SunParts(c.part0, c.part1);
  return e;
}

// The optical depth at x from a texel's parts.
real sunMapDecode(int method, real4 part0, real4 part1, real x) {
  x = clamp(x, 0.0, 1.0);
  real tau = 0.0;
  if (method == kSunEsm) tau = -log(clamp(part0.x * exp(-kEsmSharpness * x), exp(-kSunMaxDepth), 1.0));
  if (method == kSunBsm) tau = min(part0.z, part0.y * max(x - part0.x, 0.0));
  if (method == kSunFom) {
    real w = 2.0 * kPi * x;
    real4 sn = real4(sin(w), sin(2.0 * w), sin(3.0 * w), 0.0) / (2.0 * kPi * real4(1.0, 2.0, 3.0, 1.0));
    real4 cs = (real4(1.0) - real4(cos(w), cos(2.0 * w), cos(3.0 * w), 1.0)) / (2.0 * kPi * real4(1.0, 2.0, 3.0, 1.0));
    tau = 0.5 * part0.x * x + dot(real3(part0.y, part0.z, part0.w), real3(sn)) +
          dot(real3(part1.x, part1.y, part1.z), real3(cs));
  }
  if (method == kSunDeep) {
    // Knot k (1..8) at x = k / 8, 0 at x = 0, linear between: a sum of
    // hat functions (an indexed array would cost lavapipe a memory round
    // trip).
    real f = x * 8.0;
    tau = dot(part0, max(real4(0.0), real4(1.0) - abs(real4(f) - real4(1.0, 2.0, 3.0, 4.0)))) +
          dot(part1, max(real4(0.0), real4(1.0) - abs(real4(f) - real4(5.0, 6.0, 7.0, 8.0))));
  }
  return clamp(tau, 0.0, kSunMaxDepth);
}

// The point p's place in the map: its cascade's image layer (of part 0) and
// texture coordinates; layer -1 outside the last cascade.
struct SunMapPlace {
  int layer;
  real2 uv;
};

real3 sunCascadeOrigin(SunMap m, int c) {
  return c == 0 ? m.origin : (c == 1 ? m.origin1 : (c == 2 ? m.origin2 : m.origin3));
}

// The image layer of cascade c's part 0 in the map of its slot (the image
// holds two maps, one read while the other is built).
int sunMapLayer(SunMap m, int c, int slot) {
  return (slot * m.cascades + c) * sunMapParts(m.method);
}

SunMapPlace sunMapPlace(SunMap m, real3 p) {
  real extent = m.extent;
  SunMapPlace at = SunMapPlace(-1, real2(0.0));
  // The first cascade whose texel centres reach past p (the last: whose
  // edge does), each around its own centre.
  for (int c = 0; c < m.cascades; ++c) {
    real3 d = p - sunCascadeOrigin(m, c);
    real2 plane = real2(dot(d, m.axisU), dot(d, m.axisV));
    real reach = max(abs(plane.x), abs(plane.y));
    bool inside = at.layer < 0 && reach <= (c == m.cascades - 1 ? extent : extent * (1.0 - 1.0 / real(m.size)));
    at.layer = inside ? sunMapLayer(m, c, (m.readSlots >> c) & 1) : at.layer;
    at.uv = inside ? plane / (2.0 * extent) + 0.5 : at.uv;
    extent *= kSunCascadeRatio;
  }
  return at;
}

// The optical depth towards the sun at p (camera-local, sun cosine muSun
// there) from the map; 0 above the highest top; -1 outside the last
// cascade, where the map knows nothing and the caller estimates the shadow
// at the weather map's scale (cloudShadow).
real sunMapDepth(AirFrame a, SunMap m, real3 p, real muSun) {
  SunMapPlace at = sunMapPlace(m, p);
  if (at.layer < 0) return -1.0;
  real groundRadius = a.r - a.h;
  real hp = heightAboveCameraSphere(p, a.r) + a.h;
  SunLine line = sunLineAt(hp, muSun, groundRadius, m.topHeight, m.baseHeight);
  if (line.span <= 0.0 || hp >= m.topHeight) return 0.0;
  real4 part0 = sampleSunMap(at.layer, at.uv);
  real4 part1 = sunMapParts(m.method) > 1 ? sampleSunMap(at.layer + 1, at.uv) : real4(0.0);
  return sunMapDecode(m.method, part0, part1, line.entry / line.span);
}

// The optical depth towards the sun at p by marching its whole column
// (kSunColumn), `steps` samples per layer crossed.
real sunColumnDepth(AirFrame a, SunMap m, real3 p, real muSun, int steps, int layers) {
  real hp = heightAboveCameraSphere(p, a.r) + a.h;
  SunLine line = sunLineAt(hp, muSun, a.r - a.h, m.topHeight, m.baseHeight);
  return sunColumnMarch(a, p, hp, muSun, line, 0.0, steps, layers, kSunColumn, 1).tau;
}

// The optical depth towards the sun at p by the frame's map or column
// (`columnSteps` per layer, over the first `layers`); -1 where the method
// has none (the march) or the map does not reach p: the caller's estimate
// at the weather map's scale stands.
real sunDepthAbove(AirFrame a, real3 p, real muSun, int columnSteps, int layers) {
  real tau = sunMapIsMap(gSunMap.method) ? sunMapDepth(a, gSunMap, p, muSun) : -1.0;
  if (gSunMap.method == kSunColumn) tau = sunColumnDepth(a, gSunMap, p, muSun, columnSteps, layers);
  return tau;
}

#ifdef SKY_SUN_MAP_BUILDER
void storeSunMap(real4 part0, real4 part1);

// Builds texel (i, j) of cascade `cascade`: marches its line, encodes it
// and stores it.
void buildSunMapTexel(AirFrame a, SunMap m, int layers, int cascade, int i, int j) {
  real extent = m.extent * pow(kSunCascadeRatio, real(cascade));
  real2 plane = ((real2(real(i), real(j)) + 0.5) / real(m.size) - 0.5) * (2.0 * extent);
  real3 o = m.origin + m.axisU * plane.x + m.axisV * plane.y;
  real hO = heightAboveCameraSphere(o, a.r) + a.h;
  real muO = dot(upAt(o, a.r), a.sunDir);
  SunLine line = sunLineAt(hO, muO, a.r - a.h, m.topHeight, m.baseHeight);
  SunColumn c = sunColumnMarch(a, o, hO, muO, line, line.entry - line.span, m.buildSteps, layers, m.method,
                               kSunMapSlantFactor);
  SunParts e = sunMapEncode(m.method, c);
  storeSunMap(e.part0, e.part1);
}
#endif
