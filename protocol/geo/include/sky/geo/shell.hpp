// Ray against a spherical cloud shell about the Earth's centre, in double
// precision. The same algebra runs in float on the GPU (shaders/), where the
// cancellation-prone term is precomputed here in double.
#pragma once

namespace sky::geo {

// Distances along a ray to where it is inside the sphere of radius R.
// tNear <= tFar; when the ray misses, hit is false. t may be negative (behind).
struct SphereSpan {
  bool hit = false;
  double tNear = 0;
  double tFar = 0;
};

// Ray from a point at distance r_m from the sphere's centre, whose direction
// makes cos(zenith) = mu with the outward radial direction (mu in [-1, 1]),
// against the sphere of radius R_m. heightAbove_m = r_m - R_m must be given
// separately, computed where it is exact (from altitudes, not from two large
// radii), because (r - R)(r + R) is the term that loses precision otherwise.
SphereSpan intersectSphere(double r_m, double heightAbove_m, double mu);

}  // namespace sky::geo
