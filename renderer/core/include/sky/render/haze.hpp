// Visibility and the haze of the air between the camera and what it sees:
// Koschmieder's visual range and the aerosol a host's visibility puts in the
// view ray's march (shaders/include/atmosphere_core.glsl, where both are
// written once for the shader and the C++).
#pragma once

namespace sky::render {

// Koschmieder visual range, m, of air of extinction extinction_perm (1/m at
// 550 nm, >= 0): 3.912 / extinction; 1e9 m (past the atmosphere) for 0.
double koschmiederVisibility_m(double extinction_perm);

// The aerosol beyond the standard profile, as a fraction of it, that makes
// sea-level air's visibility visibility_m (m, > 0; clamped to >= 1 m):
// -1 (no aerosol) for 218 km and more, ~14 at 50 km, ~3300 at 250 m.
double aerosolExcessForVisibility(double visibility_m);

}  // namespace sky::render
