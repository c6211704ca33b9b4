// Pieces of the shared model that the atmosphere and the clouds both use:
// hashing, camera rays, the weather map's projection, exact ray-sphere
// distances for Earth-sized spheres, and the energy-conserving integral of a scattering step. Written in the
// subset GLSL and C++ share (see cloud_core.glsl for what an includer defines).

SKY_CORE_CONST real kPi = 3.14159265358979323846;
// 2^-24: maps the top 24 bits of a hash to [0, 1) exactly in float.
SKY_CORE_CONST real kInv2Pow24 = 5.9604644775390625e-8;
// Optical depth below which a step uses the sigma_t -> 0 limit of its integral:
// there (1 - e^-x) / x = 1 - x/2 + O(x^2), so the limit's relative error is
// under 5e-5, below float's resolution of the sums it feeds.
SKY_CORE_CONST real kSmallOpticalDepth = 1e-4;
// Each cascade of the sun map (sun_map.glsl) covers this times the half
// extent of the one before; here because the planner of its rebuilds
// (renderer/core/src/sun_map_plan.cpp) scales its thresholds by it.
SKY_CORE_CONST real kSunCascadeRatio = 4.0;

struct Roots {
  bool hit;
  real t0;  // t0 <= t1
  real t1;
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

// An image's view frustum as the tangents of its four edges' angles from the
// view axis: x left, y right, z up, w down, left and down negative (CIGI 3.3
// View Definition's half-angles, tan of each); a symmetric view of vertical
// field of view v and aspect a is (-t a, t a, t, -t) with t = tan(v / 2).
// The image plane at unit distance along the axis spans [x, y] to the right
// and [w, z] up; image position (u, v) in pixels (0 at the top-left corner,
// of a width x height image) lies at its point frustumPoint.
real2 frustumPoint(real4 frustum, real u, real v, real width, real height) {
  return real2(mix(frustum.x, frustum.y, u / width), mix(frustum.z, frustum.w, v / height));
}

// The inverse of frustumPoint: the image position (pixels, continuous, pixel
// centres at +0.5) of the image-plane point s (tangents right and up).
real2 frustumPixel(real4 frustum, real2 s, real width, real height) {
  return real2((s.x - frustum.x) / (frustum.y - frustum.x) * width, (frustum.z - s.y) / (frustum.z - frustum.w) * height);
}

// View ray through the centre of pixel (px, py), top row first; camera axes in
// the local frame, the frustum as above.
real3 cameraRay(real3 forward, real3 right, real3 down, real4 frustum, real px, real py, real width, real height) {
  real2 s = frustumPoint(frustum, px + 0.5, py + 0.5, width, height);
  return normalize(forward + right * s.x - down * s.y);
}

// The weather map's plane: the gnomonic projection of a camera-local point p
// onto the plane tangent to the weather anchor's sphere at the anchor,
// x = R q.x / q.z and y = R q.y / q.z, with q the point in the anchor's frame
// relative to the sphere's centre (the camera's position there: camInAnchor).
// Returns (x, y, q.z): the plane point holds where q.z > 0, on the anchor's
// side of the sphere (behind it the projection folds over). The GPU passes
// (weather_map.glsl) and the CPU reference project through this one function.
real3 anchorPlane(real3x3 camToAnchor, real3 camInAnchor, real radius, real3 p) {
  real3 q = camToAnchor * p + camInAnchor;
  real s = radius / q.z;
  return real3(q.x * s, q.y * s, q.z);
}

// The coarse ring's weight at a point of the weather map's plane: 0 inside
// the blend band's start, 1 past its end, linear in the max norm between;
// invFineHalf is 1 / the fine ring's half extent, start and end are
// fractions of it (weather_field.hpp's rings). The GPU passes
// (weather_map.glsl) and WeatherField's CPU readers blend through this one
// function.
real ringBlendWeight(real2 plane, real invFineHalf, real start, real end) {
  real e = max(abs(plane.x), abs(plane.y)) * invFineHalf;
  return clamp((e - start) / (end - start), 0.0, 1.0);
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

// Whether a view ray along v (camera-local, z up, any length) from the
// camera at distance r from the centre meets the sphere of constant c ahead:
// intersectSphere(r, c, normalize(v).z)'s hit with t1 > 0, worked out
// without the normalisation, the square root and the division, for passes
// that only classify pixels (the upscale's ground test). Inside the sphere
// (c < 0) every ray meets it; on or outside it, the ray goes down and not
// above the horizon: mu < 0 and mu <= -sqrt(c) / r, that is v.z < 0 and
// v.z^2 r^2 >= c |v|^2.
bool rayMeetsSphere(real3 v, real r, real c) {
  if (c < real(0.0)) return true;
  return v.z < real(0.0) && v.z * v.z * (r * r) >= c * dot(v, v);
}

// rayMeetsSphere for a ray from o (camera-local, m) instead of the camera:
// the previous frame's camera, whose rays the reprojection's history was
// drawn along. The ray's origin from the centre is m = o + (0, 0, r), and
// it meets the sphere ahead where c' = |m|^2 - R^2 < 0 (inside), or where
// b = m.v < 0 and b^2 >= c' |v|^2. c' is c + (2 r + o.z) o.z + |o.xy|^2,
// kept apart from r^2 as c is; with o = 0 this is rayMeetsSphere.
bool rayFromMeetsSphere(real3 o, real3 v, real r, real c) {
  real cFrom = c + (real(2.0) * r + o.z) * o.z + o.x * o.x + o.y * o.y;
  if (cFrom < real(0.0)) return true;
  real b = dot(o, v) + r * v.z;
  return b < real(0.0) && b * b >= cFrom * dot(v, v);
}

// Height of p above the sphere through the camera, m, without forming
// |p - centre| - r from two Earth-sized numbers: (|q|^2 - r^2) / (|q| + r).
real heightAboveCameraSphere(real3 p, real r) {
  real num = 2.0 * r * p.z + dot(p, p);
  return num / (sqrt(max(r * r + num, 0.0)) + r);
}

// Local vertical at p (camera-relative, centre at -r z): unit.
real3 upAt(real3 p, real r) {
  return normalize(real3(p.x, p.y, p.z + r));
}

// (1 - e^-x) / x for optical depth x >= 0, with its x -> 0 limit: the
// fraction of a step's length that a unit source at its start scatters out
// to its end (Hillaire 2016, "Physically based sky, atmosphere and cloud
// rendering in Frostbite", sec. 5.6.3: integral of S e^(-sigma s) over the
// step is S (1 - e^(-sigma d)) / sigma = S d f(sigma d)).
real scatterFraction(real x) {
  return x > kSmallOpticalDepth ? (1.0 - exp(-x)) / x : 1.0 - 0.5 * x;
}

real3 scatterFraction3(real3 x) {
  return real3(scatterFraction(x.x), scatterFraction(x.y), scatterFraction(x.z));
}
