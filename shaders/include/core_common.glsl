// Pieces of the shared model that the atmosphere and the clouds both use:
// hashing, camera rays, exact ray-sphere distances for Earth-sized spheres,
// and the energy-conserving integral of a scattering step. Written in the
// subset GLSL and C++ share (see cloud_core.glsl for what an includer defines).

SKY_CORE_CONST real kPi = 3.14159265358979323846;
// 2^-24: maps the top 24 bits of a hash to [0, 1) exactly in float.
SKY_CORE_CONST real kInv2Pow24 = 5.9604644775390625e-8;
// Optical depth below which a step uses the sigma_t -> 0 limit of its integral:
// there (1 - e^-x) / x = 1 - x/2 + O(x^2), so the limit's relative error is
// under 5e-5, below float's resolution of the sums it feeds.
SKY_CORE_CONST real kSmallOpticalDepth = 1e-4;

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
