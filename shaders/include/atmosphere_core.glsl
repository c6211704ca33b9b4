// The clear-sky atmosphere, written once for the GPU pass and the CPU side
// (the transmittance table, the per-frame ambient light and the reference
// integrator): exponential Rayleigh and Mie profiles and an ozone layer
// (Bruneton 2017, "A qualitative and quantitative evaluation of 8 clear sky
// models", and Hillaire 2020, "A scalable and production ready sky and
// atmosphere rendering technique"; values in reference/formulas.md), the
// transmittance-table parametrisation, sunlight with the Earth's shadow, and
// single scattering marched along a view ray with queries at cloud depths
// (aerial perspective), with Hillaire 2020's multiple-scattering term.
// Needs core_common.glsl, and two texture hooks:
//   real3 sampleTransmittanceLut(real2 uv)        // transmittance to the top, bilinear
//   real3 sampleMultipleScatteringLut(real2 uv)   // multiple-scattering radiance, bilinear
// Heights are above the local ground sphere (m); mu is the cosine of the
// angle from the local vertical.

// Planet and atmosphere radii of the tables, m (Bruneton 2017: 6360 km and
// 6420 km). The renderer's ground is the local sphere under the camera
// (6335-6400 km); the tables' fixed radius changes a horizontal path through
// the atmosphere by under 0.3 % (path ~ sqrt(R)), below what they resolve.
SKY_CORE_CONST real kAtmosphereBottomRadius_m = 6360000.0;
SKY_CORE_CONST real kAtmosphereHeight_m = 60000.0;
// Rayleigh scattering at sea level for R, G, B, 1/m, and its scale height
// (formulas.md, Bruneton 2017 / Hillaire 2020); air does not absorb here.
SKY_CORE_CONST real kRayleighR_perm = 5.802e-6, kRayleighG_perm = 13.558e-6, kRayleighB_perm = 33.1e-6;
SKY_CORE_CONST real kRayleighScaleHeight_m = 8000.0;
// Mie (aerosol) scattering and extinction at sea level, 1/m, grey; scale
// height; Cornette-Shanks asymmetry (formulas.md: g ~ 0.8).
SKY_CORE_CONST real kMieScattering_perm = 3.996e-6;
SKY_CORE_CONST real kMieExtinction_perm = 4.40e-6;
SKY_CORE_CONST real kMieScaleHeight_m = 1200.0;
SKY_CORE_CONST real kMieG = 0.8;
// Ozone absorption at the layer's peak, 1/m (formulas.md), in a tent profile
// rising from 10 km to its peak at 25 km and falling to 0 at 40 km (Bruneton
// 2017's ozone layer).
SKY_CORE_CONST real kOzoneR_perm = 0.650e-6, kOzoneG_perm = 1.881e-6, kOzoneB_perm = 0.085e-6;
SKY_CORE_CONST real kOzonePeak_m = 25000.0;
SKY_CORE_CONST real kOzoneHalfWidth_m = 15000.0;
// Angular radius of the sun, rad (0.2666 degrees at 1 AU): the sun sets over
// this angle instead of at once, so light fades smoothly at the terminator.
SKY_CORE_CONST real kSunAngularRadius_rad = 0.004653;
// Transmittance table size: mu across (width), height up (height), as in
// Bruneton 2017's reference (256 x 64): under 3e-3 relative interpolation
// error above the horizon (tests/unit/renderer/atmosphere_test.cpp measures
// 2.8e-3, worst for grazing rays from the ground).
SKY_CORE_CONST int kTransmittanceLutWidth = 256;
SKY_CORE_CONST int kTransmittanceLutHeight = 64;
// Steps of a view ray through the air, quadratically spaced (denser near the
// camera, where aerial perspective is sampled most): 16 keeps the sky within
// ~1 % of a 2000-step integral above the horizon (atmosphere_test.cpp) at
// ~15 % of a 320x180 frame on lavapipe.
SKY_CORE_CONST int kAirSteps = 16;
// Multiple-scattering table (Hillaire 2020, sec. 5.5): 32 x 32 over (sun
// cosine, height), each texel from 16 x 16 equal-solid-angle directions of
// 20 steps (Hillaire's 64 directions are up to 18 % off a fine integral of
// the same definition at low sun, 256 within 8 %: atmosphere_test.cpp).
SKY_CORE_CONST int kMultipleScatteringLutSize = 32;
SKY_CORE_CONST int kMultipleScatteringSide = 16;  // directions: side x side
SKY_CORE_CONST int kMultipleScatteringDirections = kMultipleScatteringSide * kMultipleScatteringSide;
SKY_CORE_CONST int kMultipleScatteringSteps = 20;
// Ground albedo the multiple scattering sees (the renderer's ground, 0.1).
SKY_CORE_CONST real kAirGroundAlbedo = 0.1;
// Distances a view ray reports the air's in-scattering and transmittance at:
// one per cloud layer plus the end of the ray.
SKY_CORE_CONST int kAirQueries = 5;

// Distance standing for "past the atmosphere" for rays that miss the ground, m.
SKY_CORE_CONST real kFarAway_m = 1.0e9;
// Radiance of the night sky without the sun (airglow and starlight, ~2e-4
// cd/m^2 at a dark site against ~1e4 cd/m^2 for a clear day sky), in the
// renderer's linear units where a day sky is ~0.5: ~1e-8. Keeps astronomical
// night finite and not exactly zero.
SKY_CORE_CONST real kNightSkyRadiance = 1.0e-8;

// Koschmieder's visual range: an object's contrast falls to the 2 %
// threshold after an optical depth of -ln 0.02 = 3.912, so V = 3.912 / beta
// for the extinction beta at 550 nm (Koschmieder 1924; WMO-No. 8 uses this
// threshold for meteorological visibility).
SKY_CORE_CONST real kKoschmiederDepth = 3.912;

struct AirFrame {
  real r;             // camera distance from the local ground sphere's centre, m
  real h;             // camera height above the ground sphere, m (>= 0)
  real cGround;       // h (2r - h), m^2
  real cTop;          // (h - H) (2r - (h - H)) for the atmosphere top at height H, m^2
  real3 sunDir;       // unit, local frame
  real3 sunIrradiance;  // at the top of the atmosphere, linear units
  int airSteps;         // steps of marchAir (MarchSettings::airSteps); 0: kAirSteps
  // Aerosol along the view ray beyond the standard profile, as a fraction of
  // it (0: the standard Mie profile; -1: none): what a host's visibility
  // makes of the haze (aerosolExcessForVisibility). Only the view ray's
  // march sees it; the tables (sunlight, multiple scattering) keep the
  // standard aerosol.
  real aerosolExcess;
  // Cloud layers whose shadow the march's sunlight passes through (the
  // clouds' shadow in the air: the shade under an overcast, light shafts);
  // 0: none. Only with cloud_core.glsl, which defines SKY_CLOUD_SHADOWED_AIR
  // (and lets the layers shadow each other by the same count).
  int shadowLayers;
};

// The aerosol excess (AirFrame::aerosolExcess) that gives sea-level air a
// Koschmieder visibility of visibility_m (> 0) in green: Rayleigh G plus the
// scaled Mie extinction equal 3.912 / V. The standard profile's own
// visibility is 3.912 / (13.558e-6 + 4.40e-6) = 218 km; a longer one gives
// pure Rayleigh air (-1), the clearest this model has.
real aerosolExcessForVisibility(real visibility_m) {
  real beta = kKoschmiederDepth / max(visibility_m, 1.0);
  return max(beta - kRayleighG_perm, 0.0) / kMieExtinction_perm - 1.0;
}

// Cumulative single scattering and transmittance of the air from the camera
// to each queried distance (inscatter[i] is radiance per unit sun irradiance
// already multiplied in, i.e. linear units).
struct AirPath {
  real3 inscatter[kAirQueries];
  real3 transmittance[kAirQueries];
};

real3 rayleighScattering(real h) {
  return real3(kRayleighR_perm, kRayleighG_perm, kRayleighB_perm) * exp(-max(h, 0.0) / kRayleighScaleHeight_m);
}

real mieDensity(real h) {
  return exp(-max(h, 0.0) / kMieScaleHeight_m);
}

real ozoneDensity(real h) {
  return max(1.0 - abs(h - kOzonePeak_m) / kOzoneHalfWidth_m, 0.0);
}

// Extinction of clear air at height h, 1/m per channel.
real3 airExtinction(real h) {
  return rayleighScattering(h) + real3(kMieExtinction_perm * mieDensity(h)) +
         real3(kOzoneR_perm, kOzoneG_perm, kOzoneB_perm) * ozoneDensity(h);
}

// Rayleigh phase function, 1/sr: 3 (1 + nu^2) / (16 pi).
real phaseRayleigh(real nu) {
  real c = clamp(nu, -1.0, 1.0);
  return 3.0 * (1.0 + c * c) / (16.0 * kPi);
}

// Cornette-Shanks phase function for aerosols (as in Bruneton 2017), 1/sr:
// 3 (1 - g^2) (1 + nu^2) / (8 pi (2 + g^2) (1 + g^2 - 2 g nu)^1.5).
real phaseCornetteShanks(real nu, real g) {
  real c = clamp(nu, -1.0, 1.0);
  real denom = 1.0 + g * g - 2.0 * g * c;
  return 3.0 * (1.0 - g * g) * (1.0 + c * c) / (8.0 * kPi * (2.0 + g * g) * denom * sqrt(denom));
}

// Distance from height h along mu to the top of the atmosphere (the point is
// inside it, 0 <= h <= H), m, by the stable sphere root.
real distanceToAtmosphereTop(real h, real mu) {
  real hAbove = h - kAtmosphereHeight_m;
  Roots top = intersectSphere(kAtmosphereBottomRadius_m + h, hAbove * (2.0 * (kAtmosphereBottomRadius_m + h) - hAbove), mu);
  return max(top.t1, 0.0);
}

// Texture coordinates of (h, mu) in the transmittance table (Bruneton 2017,
// sec. 4: x_r = rho / rho_top, x_mu = (d - d_min) / (d_max - d_min) with rho
// the distance to the horizon and d the distance to the top), mapped onto
// texel centres so the table's edges are sampled exactly.
real2 transmittanceUv(real h, real mu) {
  real hc = clamp(h, 0.0, kAtmosphereHeight_m);
  real rhoTop = sqrt(kAtmosphereHeight_m * (2.0 * kAtmosphereBottomRadius_m + kAtmosphereHeight_m));
  real rho = sqrt(hc * (2.0 * kAtmosphereBottomRadius_m + hc));
  real dMin = kAtmosphereHeight_m - hc;
  real dMax = rho + rhoTop;
  real xMu = dMax > dMin ? (distanceToAtmosphereTop(hc, mu) - dMin) / (dMax - dMin) : 0.0;
  real xR = rho / rhoTop;
  real w = real(kTransmittanceLutWidth);
  real hh = real(kTransmittanceLutHeight);
  return real2(0.5 / w + clamp(xMu, 0.0, 1.0) * (1.0 - 1.0 / w), 0.5 / hh + clamp(xR, 0.0, 1.0) * (1.0 - 1.0 / hh));
}

// Transmittance of clear air from height h along mu to the top, by direct
// integration with `steps` midpoint steps (the table's source; the CPU
// builds the table with it in double precision).
real3 transmittanceToTop(real h, real mu, int steps) {
  real r = kAtmosphereBottomRadius_m + h;
  real d = distanceToAtmosphereTop(h, mu);
  real dt = d / real(steps);
  real3 depth = real3(0.0);
  for (int i = 0; i < steps; ++i) {
    real t = (real(i) + 0.5) * dt;
    real num = t * t + 2.0 * r * mu * t;
    real hi = h + num / (sqrt(max(r * r + num, 0.0)) + r);
    depth += airExtinction(hi) * dt;
  }
  return exp(-depth);
}

// Fraction of the sun's disc above the horizon of a point at height h above
// a ground sphere of radius groundRadius, for the sun at cosine muSun from
// the vertical (Bruneton 2017's smooth terminator).
real sunVisibility(real h, real muSun, real groundRadius) {
  real hc = max(h, 0.0);
  real sinHorizon = groundRadius / (groundRadius + hc);
  real cosHorizon = -sqrt(hc * (2.0 * groundRadius + hc)) / (groundRadius + hc);
  real edge = sinHorizon * kSunAngularRadius_rad;
  return smoothstep(-edge, edge, muSun - cosHorizon);
}

// Sunlight reaching height h (sun at cosine muSun from the vertical) through
// the air, per unit irradiance at the top: the table's transmittance times
// the visible fraction of the disc.
real3 sunTransmittance(real h, real muSun, real groundRadius) {
  real vis = sunVisibility(h, muSun, groundRadius);
  if (vis <= 0.0) return real3(0.0);
  return sampleTransmittanceLut(transmittanceUv(h, clamp(muSun, -1.0, 1.0))) * vis;
}

// Texture coordinates of (sun cosine, height) in the multiple-scattering
// table, on texel centres (Hillaire 2020: u = 0.5 + 0.5 muS, v = h / H).
real2 multipleScatteringUv(real h, real muSun) {
  real n = real(kMultipleScatteringLutSize);
  real u = clamp(0.5 + 0.5 * muSun, 0.0, 1.0);
  real v = clamp(h / kAtmosphereHeight_m, 0.0, 1.0);
  return real2(0.5 / n + u * (1.0 - 1.0 / n), 0.5 / n + v * (1.0 - 1.0 / n));
}

// Hillaire 2020's multiple scattering at height h for the sun at cosine
// muSun, per unit sun irradiance: the second-order radiance L2 (sunlight
// scattered once, isotropically, from all around, plus the lit ground) over
// 1 - f, f the fraction of isotropic light the surrounding air scatters back
// (the sum of all further orders, L2 (1 + f + f^2 + ...)). Built into a table
// on the CPU; the sky march adds sigma_s times it. Directions: a grid of
// equal solid angle, uniform in mu and phi.
real3 multipleScattering(real h, real muSun) {
  real R = kAtmosphereBottomRadius_m;
  real r = R + h;
  real3 sunDir = real3(sqrt(max(1.0 - muSun * muSun, 0.0)), 0.0, muSun);
  real3 L2 = real3(0.0);
  real3 f = real3(0.0);
  int side = kMultipleScatteringSide;
  for (int k = 0; k < kMultipleScatteringDirections; ++k) {
    real mu = 1.0 - 2.0 * (real(k / side) + 0.5) / real(side);
    real phi = 2.0 * kPi * (real(k - (k / side) * side) + 0.5) / real(side);
    real s = sqrt(max(1.0 - mu * mu, 0.0));
    real3 dir = real3(s * cos(phi), s * sin(phi), mu);
    // To the ground (if the ray meets it: downwards, inside its horizon; at
    // h = 0 at once) or the top. Never through the Earth.
    real cGround = h * (2.0 * r - h);
    Roots ground = intersectSphere(r, cGround, mu);
    bool hitsGround = mu < 0.0 && ground.hit;
    real tMax = hitsGround ? max(ground.t0, 0.0) : distanceToAtmosphereTop(h, mu);
    real dt = tMax / real(kMultipleScatteringSteps);
    real3 transmittance = real3(1.0);
    real3 Li = real3(0.0);
    real3 fi = real3(0.0);
    for (int j = 0; j < kMultipleScatteringSteps; ++j) {
      real3 x = real3(0.0, 0.0, r) + dir * ((real(j) + 0.5) * dt);
      real rx = length(x);
      real hx = rx - R;
      real3 sigmaS = rayleighScattering(hx) + real3(kMieScattering_perm * mieDensity(hx));
      real3 sigmaT = airExtinction(hx);
      real3 sun = sunTransmittance(hx, dot(x / rx, sunDir), R);
      real3 part = scatterFraction3(sigmaT * dt) * dt;  // (1 - e^{-sigma dt}) / sigma
      Li += transmittance * sigmaS * sun * part / (4.0 * kPi);
      fi += transmittance * sigmaS * part;
      transmittance *= exp(-sigmaT * dt);
    }
    if (hitsGround) {
      real3 g = real3(0.0, 0.0, r) + dir * tMax;
      real muGround = dot(normalize(g), sunDir);
      Li += transmittance * sunTransmittance(0.0, muGround, R) * max(muGround, 0.0) * (kAirGroundAlbedo / kPi);
    }
    L2 += Li / real(kMultipleScatteringDirections);
    f += fi / real(kMultipleScatteringDirections);
  }
  return L2 / (real3(1.0) - f);
}

#ifdef SKY_CLOUD_SHADOWED_AIR
// Hook (defined by cloud_core.glsl's includers): how much of the sunlight
// reaches the air at p (camera-relative, height h above the ground sphere,
// sun cosine muSun there) through the clouds above it: x the direct beam,
// y the light the clouds scatter on (what the multiple-scattering term of
// the air carries).
real2 airCloudShadow(AirFrame a, real3 p, real h, real muSun);
#endif

// The part of a view ray along dir inside the atmosphere, up to tEnd (the
// ground, or past the atmosphere): from the camera (or where the ray enters
// from above) to where it leaves the top or meets tEnd; t1 <= t0 when the
// ray misses the air.
struct AirSegment {
  real t0;
  real t1;
};

AirSegment airSegment(AirFrame a, real3 dir, real tEnd) {
  AirSegment s;
  s.t0 = 0.0;
  s.t1 = 0.0;
  Roots top = intersectSphere(a.r, a.cTop, dir.z);
  bool inside = a.h < kAtmosphereHeight_m;
  if (!inside && !(top.hit && top.t1 > 0.0)) return s;
  s.t0 = inside ? 0.0 : max(top.t0, 0.0);
  s.t1 = min(top.hit ? top.t1 : 0.0, tEnd);
  return s;
}

// What the air at distance t along dir adds per unit length, split by its
// angular dependence (the phase functions depend only on the angle between
// dir and the sun, constant along the ray, so they can multiply the sums
// afterwards, which lets a table store the sums for every sun angle):
// Rayleigh and aerosol single scattering without their phase, and the
// isotropic multiple scattering (Hillaire 2020, eq. 11), each through the
// clouds' shadow; and the extinction there.
struct AirSource {
  real3 extinction;  // 1/m
  real3 rayleigh;    // times phaseRayleigh
  real3 mie;         // times phaseCornetteShanks
  real3 multiple;    // isotropic
};

AirSource airSourceAt(AirFrame a, real3 dir, real t) {
  real3 p = dir * t;
  real h = heightAboveCameraSphere(p, a.r) + a.h;
  real muSun = dot(upAt(p, a.r), a.sunDir);
  real3 sun = a.sunIrradiance * sunTransmittance(h, muSun, a.r - a.h);
#ifdef SKY_CLOUD_SHADOWED_AIR
  real2 shade = a.shadowLayers > 0 ? airCloudShadow(a, p, h, muSun) : real2(1.0);
#else
  real2 shade = real2(1.0);
#endif
  real3 rayleigh = rayleighScattering(h);
  real mie = (1.0 + a.aerosolExcess) * kMieScattering_perm * mieDensity(h);
  AirSource src;
  src.extinction = airExtinction(h) + real3(a.aerosolExcess * kMieExtinction_perm * mieDensity(h));
  src.rayleigh = rayleigh * sun * shade.x;
  src.mie = real3(mie) * sun * shade.x;
  src.multiple = (rayleigh + real3(mie)) * sampleMultipleScatteringLut(multipleScatteringUv(h, muSun)) *
                 a.sunIrradiance * shade.y;
  return src;
}

// Sunlight scattered by the air along dir from the camera, with
// the camera's air to distance tEnd (the ground, or past the atmosphere),
// reported at the queried distances q[0..count) (ascending, any values: a
// query before the air starts reports nothing yet, past tEnd the whole path).
// Each step integrates its source energy-conservingly (Hillaire 2016) and a
// query inside a step takes the exact part of that step.
AirPath marchAir(AirFrame a, real3 dir, real tEnd, real q[kAirQueries], int count) {
  AirPath path;
  for (int k = 0; k < kAirQueries; ++k) {
    path.inscatter[k] = real3(0.0);
    path.transmittance[k] = real3(1.0);
  }
  AirSegment seg = airSegment(a, dir, tEnd);
  real tA = seg.t0;
  real tB = seg.t1;
  if (tB <= tA) return path;
  real nu = dot(dir, a.sunDir);
  real pR = phaseRayleigh(nu);
  real pM = phaseCornetteShanks(nu, kMieG);
  real3 inscatter = real3(0.0);
  real3 transmittance = real3(1.0);
  int next = 0;
  // Queries before the air starts see nothing.
  while (next < count && q[next] <= tA) ++next;
  // No queries, no march: a caller that wants the air table's answer
  // instead passes none (compiled out where that is a constant).
  int steps = count > 0 ? (a.airSteps > 0 ? a.airSteps : kAirSteps) : 0;
  for (int i = 0; i < steps; ++i) {
    real u0 = real(i) / real(steps);
    real u1 = real(i + 1) / real(steps);
    real s0 = tA + (tB - tA) * u0 * u0;
    real s1 = tA + (tB - tA) * u1 * u1;
    AirSource src = airSourceAt(a, dir, 0.5 * (s0 + s1));
    real3 sigmaT = src.extinction;
    real3 source = src.rayleigh * pR + src.mie * pM + src.multiple;
    // Queries inside this step: the exact part of the step up to each.
    while (next < count && q[next] < s1) {
      real d = q[next] - s0;
      path.inscatter[next] = inscatter + transmittance * source * d * scatterFraction3(sigmaT * d);
      path.transmittance[next] = transmittance * exp(-sigmaT * d);
      ++next;
    }
    real ds = s1 - s0;
    inscatter += transmittance * source * ds * scatterFraction3(sigmaT * ds);
    transmittance *= exp(-sigmaT * ds);
  }
  for (int k = next; k < count; ++k) {
    path.inscatter[k] = inscatter;
    path.transmittance[k] = transmittance;
  }
  return path;
}
