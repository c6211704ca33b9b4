// A falling drop or flake seen over an exposure: how much of a pixel it
// covers. Written in the subset GLSL and C++ share (see cloud_core.glsl for
// what an includer defines): near_precip.comp draws with it, the tests
// compile it as C++.
//
// The drop's centre moves at a steady rate from a to b (pixels) during the
// exposure, and a pixel's share of the exposure spent under the drop is
// what it covers: a streak is fainter the longer it is (Garg and Nayar
// 2004, "Detection and removal of rain from videos": a drop stays on a
// pixel for a fraction of the exposure). The drop's image, of radius r, is
// drawn as a tent along and across its path, as wide as the drop and at
// least a pixel each way, whose integral is the drop's area pi r^2: a tent
// a pixel wide sums to its integral over pixel centres wherever it sits,
// so a thin streak keeps its brightness as it moves across the pixels
// instead of flickering. Coverage past 1 (a drop wider than a pixel that
// hardly moves) is cut to 1. Otherwise the coverage integrates over the
// image to the drop's area, whatever the path: its light is spread, not made.

// The integral of a tent of half-width w and unit area from -w to x.
real tentCdf(real x, real w) {
  real u = clamp(x / w, -1.0, 1.0);
  return u < 0.0 ? 0.5 * (1.0 + u) * (1.0 + u) : 1.0 - 0.5 * (1.0 - u) * (1.0 - u);
}

// The path given as its start a, unit direction dir and length len (the
// pass gets them so; a path shorter than 1e-3 px counts as still).
real streakCoverageAlong(real2 p, real2 a, real2 dir, real len, real r) {
  real w = max(r, 1.0);
  real2 ap = p - a;
  real across = ap.x * dir.y - ap.y * dir.x;
  if (abs(across) >= w) return 0.0;
  real acrossWeight = (1.0 - abs(across) / w) / w;
  real along = dot(ap, dir);
  // The tent along the path, averaged over the drop's places on it.
  real alongWeight = len < 1e-3 ? max(1.0 - abs(along) / w, 0.0) / w
                                : (tentCdf(along, w) - tentCdf(along - len, w)) / len;
  return min(3.14159265358979323846 * r * r * acrossWeight * alongWeight, 1.0);
}

// The path from a to b.
real streakCoverage(real2 p, real2 a, real2 b, real r) {
  real2 ab = b - a;
  real len = length(ab);
  return streakCoverageAlong(p, a, len < 1e-3 ? real2(1.0, 0.0) : ab / len, len, r);
}
