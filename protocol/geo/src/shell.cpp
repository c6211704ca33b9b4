// Numerically stable ray-sphere intersection (see shell.hpp for the contract).
#include "sky/geo/shell.hpp"

#include <algorithm>
#include <cmath>

namespace sky::geo {

SphereSpan intersectSphere(double r_m, double heightAbove_m, double mu) {
  // |o + t d|^2 = R^2 with |o| = r, o.d = r mu:  t^2 + 2 r mu t + c = 0,
  // c = r^2 - R^2 = h (2r - h) with h = r - R (exact from altitudes).
  mu = std::clamp(mu, -1.0, 1.0);
  const double b = r_m * mu;
  const double c = heightAbove_m * (2.0 * r_m - heightAbove_m);
  const double disc = b * b - c;
  if (disc < 0.0) return {};
  // Citardauq form: avoid subtracting nearly equal numbers for grazing rays.
  const double q = -(b + std::copysign(std::sqrt(disc), b));
  double t0 = q;
  double t1 = q != 0.0 ? c / q : 0.0;
  if (t0 > t1) std::swap(t0, t1);
  return {true, t0, t1};
}

}  // namespace sky::geo
