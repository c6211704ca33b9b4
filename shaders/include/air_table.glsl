// The sky and aerial perspective from a table built once per frame (Hillaire
// 2020's sky-view table and aerial-perspective volume in one): for a grid of
// directions around the camera, the air's light and transmittance from the
// camera to a series of distances along each, so a pixel reads the air in
// front of its clouds and the ground in a few lookups instead of marching it.
// Written once for the GPU (shaders/air_table.comp builds it, clouds.comp
// reads it) and the CPU reference (which builds and reads it in double).
// Needs atmosphere_core.glsl, and the hook
//   real4 sampleAirTable(int part, real3 uvw)  // part 0..2 of the table, trilinear:
//                                              // u repeats, v and w clamp to the edge
// and, with SKY_AIR_TABLE_BUILDER defined, the builder's hook
//   void storeAirTable(int slice, real4 part0, real4 part1, real4 part2)
//
// Layout (camera-local directions: x east, y north, z up):
// * u: azimuth, atan2(north, east) over a full turn, repeating;
// * v: zenith angle, the upper half of the rows the sky down to the
//   horizon (from above the atmosphere only its limb), the lower half the
//   ground from the horizon down; each half
//   packs its rows towards the horizon (v - 1/2 goes as the square root of
//   the angle from the horizon), where the sky changes fastest, and a lookup
//   stays inside its half so the sky never blends with the ground;
// * w: distance along the ray through the air, slice k at the fraction
//   (k / (slices - 1))^2 of the ray's air (closer together near the camera,
//   where clouds are most often met), slice 0 at the camera;
// * the three parts hold the sums of airSourceAt's three terms: x, y, z of
//   part 0 Rayleigh, of part 1 aerosol, of part 2 multiple scattering; the w
//   of the three parts the transmittance in R, G and B.
// The phase functions multiply the sums at lookup, so the sun's glare and
// the sky's brightening towards the sun are exact at every pixel; what the
// table interpolates is the sunlight and shadow along the rays, smooth in
// direction (the clouds' shadow is at the weather map's scale, ~1 km).

struct AirTableShape {
  int azimuths;  // > 0; 0 in CoreFrame: no table, the air is marched per pixel
  int zeniths;   // even
  int slices;    // >= 2
};

// Zenith angle of the horizon seen from the camera, rad (>= pi/2).
real airTableHorizon(AirFrame a) {
  return acos(clamp(-sqrt(max(a.cGround, 0.0)) / a.r, -1.0, 1.0));
}

// Zenith angle from which on the sky's rays meet the air, rad: 0 inside
// the atmosphere; from above it, the angle of the rays that graze its top,
// so the sky's rows all lie on the limb and none on empty space.
real airTableSkyStart(AirFrame a) {
  real top = a.r - a.h + kAtmosphereHeight_m;
  return a.h > kAtmosphereHeight_m ? kPi - asin(clamp(top / a.r, 0.0, 1.0)) : 0.0;
}

// The table's v of a direction at zenith angle theta, on the sky side
// (from theta0 to the horizon thetaH) or the ground side of the horizon.
real airTableV(real theta, real theta0, real thetaH, bool ground) {
  if (!ground) return 0.5 * (1.0 - sqrt(clamp(1.0 - (theta - theta0) / max(thetaH - theta0, 1e-6), 0.0, 1.0)));
  return 0.5 + 0.5 * sqrt(clamp((theta - thetaH) / max(kPi - thetaH, 1e-6), 0.0, 1.0));
}

// Where a view ray along mu meets the ground sphere, or kFarAway_m when it
// misses it.
real airRayEnd(AirFrame a, real mu) {
  Roots g = intersectSphere(a.r, a.cGround, mu);
  return (g.hit && g.t1 > 0.0) ? max(g.t0, 0.0) : kFarAway_m;
}

// The direction of column (i, j) of the table: its texel centre inverted
// through airTableV.
real3 airTableDirection(AirFrame a, AirTableShape t, int i, int j) {
  real thetaH = airTableHorizon(a);
  real theta0 = airTableSkyStart(a);
  real v = (real(j) + 0.5) / real(t.zeniths);
  real theta = j < t.zeniths / 2 ? theta0 + (thetaH - theta0) * (1.0 - (1.0 - 2.0 * v) * (1.0 - 2.0 * v))
                                 : thetaH + (kPi - thetaH) * (2.0 * v - 1.0) * (2.0 * v - 1.0);
  real phi = 2.0 * kPi * ((real(i) + 0.5) / real(t.azimuths) - 0.5);
  real s = sin(theta);
  return real3(s * cos(phi), s * sin(phi), cos(theta));
}

#ifdef SKY_AIR_TABLE_BUILDER
void storeAirTable(int slice, real4 part0, real4 part1, real4 part2);

// Fills the column of direction dir: one energy-conserving step per slice
// interval (Hillaire 2016, as marchAir), the source at the step's middle.
void buildAirTableColumn(AirFrame a, AirTableShape t, real3 dir) {
  AirSegment seg = airSegment(a, dir, airRayEnd(a, dir.z));
  real extent = max(seg.t1 - seg.t0, 0.0);
  real3 rayleigh = real3(0.0);
  real3 mie = real3(0.0);
  real3 multiple = real3(0.0);
  real3 transmittance = real3(1.0);
  storeAirTable(0, real4(rayleigh, 1.0), real4(mie, 1.0), real4(multiple, 1.0));
  real last = real(t.slices - 1);
  for (int k = 1; k < t.slices; ++k) {
    real u0 = real(k - 1) / last;
    real u1 = real(k) / last;
    real s0 = seg.t0 + extent * u0 * u0;
    real s1 = seg.t0 + extent * u1 * u1;
    real ds = s1 - s0;
    if (ds > 0.0) {
      AirSource src = airSourceAt(a, dir, 0.5 * (s0 + s1));
      real3 w = transmittance * ds * scatterFraction3(src.extinction * ds);
      rayleigh += w * src.rayleigh;
      mie += w * src.mie;
      multiple += w * src.multiple;
      transmittance *= exp(-src.extinction * ds);
    }
    storeAirTable(k, real4(rayleigh, transmittance.x), real4(mie, transmittance.y),
                  real4(multiple, transmittance.z));
  }
}
#endif

real4 sampleAirTable(int part, real3 uvw);

// The air along dir (unit) up to tEnd (airRayEnd's), reported at the
// queried distances as marchAir reports them, read from the table: between
// two slices linear in distance.
AirPath airPathFromTable(AirFrame a, AirTableShape t, real3 dir, real tEnd, real q[kAirQueries], int count) {
  AirPath path;
  for (int k = 0; k < kAirQueries; ++k) {
    path.inscatter[k] = real3(0.0);
    path.transmittance[k] = real3(1.0);
  }
  AirSegment seg = airSegment(a, dir, tEnd);
  if (seg.t1 <= seg.t0) return path;
  real nu = dot(dir, a.sunDir);
  real pR = phaseRayleigh(nu);
  real pM = phaseCornetteShanks(nu, kMieG);
  bool planar = abs(dir.x) + abs(dir.y) > 0.0;
  real u = planar ? atan(dir.y, dir.x) / (2.0 * kPi) + 0.5 : 0.0;
  real thetaH = airTableHorizon(a);
  bool ground = tEnd < kFarAway_m;
  real edge = 0.5 / real(t.zeniths);
  real v = airTableV(acos(clamp(dir.z, -1.0, 1.0)), airTableSkyStart(a), thetaH, ground);
  v = ground ? clamp(v, 0.5 + edge, 1.0 - edge) : clamp(v, edge, 0.5 - edge);
  real last = real(t.slices - 1);
  for (int k = 0; k < count; ++k) {
    if (q[k] <= seg.t0) continue;
    real x = clamp((q[k] - seg.t0) / (seg.t1 - seg.t0), 0.0, 1.0);
    real slice = min(floor(sqrt(x) * last), last - 1.0);
    real d0 = (slice / last) * (slice / last);
    real d1 = ((slice + 1.0) / last) * ((slice + 1.0) / last);
    real w = (slice + clamp((x - d0) / (d1 - d0), 0.0, 1.0) + 0.5) / real(t.slices);
    real4 r = sampleAirTable(0, real3(u, v, w));
    real4 m = sampleAirTable(1, real3(u, v, w));
    real4 s = sampleAirTable(2, real3(u, v, w));
    path.inscatter[k] = real3(r) * pR + real3(m) * pM + real3(s);
    path.transmittance[k] = real3(r.w, m.w, s.w);
  }
  return path;
}
