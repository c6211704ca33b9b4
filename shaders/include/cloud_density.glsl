// Cloud density, the Schneider / Haggstrom model (Haggstrom 2018, sec. 3.1,
// eq. 4-18; reference/formulas.md): weather map (server coverage, type blend,
// density) x procedural cloud map x a height profile per cloud type x
// tileable shape noise, eroded by Worley detail noise. A cloud type is a set
// of numbers (CloudType below; the table with the sources of its values is
// renderer/core/src/cloud_types.cpp), so a tile's blend between two types is a
// blend of their numbers. Shared by the GPU pass and the CPU reference.

// How far the cloud map moves partial coverage (Schneider's low-frequency
// weather channel): c' = c + A (m - 0.5) 4c(1 - c), so coverage 0 and 1 stay
// exact and 0.5 spans [0.2, 0.8]; breaks up the shape noise's repetition.
SKY_CORE_CONST real kCloudMapAmplitude = 0.6;
// Haggstrom eq. 14: the detail noise's influence falls with coverage as
// exp(-0.75 c), so dense overcast keeps its body.
SKY_CORE_CONST real kErosionCoverageFalloff = 0.75;
// Haggstrom eq. 17-18 (anvils): the shape exponent ramps over ph in
// [0.65, 0.95] and the density is reduced towards 0.2 as sqrt(ph) goes from
// 0.4 to 0.95.
SKY_CORE_CONST real kAnvilStart = 0.65, kAnvilEnd = 0.95;
SKY_CORE_CONST real kAnvilDensityStart = 0.4, kAnvilDensityEnd = 0.95, kAnvilDensityFloor = 0.2;
// Smallest shape exponent an anvil may reach: pow(0, 0) is undefined in GLSL.
SKY_CORE_CONST real kMinAnvilExponent = 1e-3;

// One cloud type's numbers (every fraction is of the layer's thickness).
struct CloudType {
  real extinction_perm;     // extinction at density 1, 1/m
  real dropletDiameter_um;  // Jendersie-d'Eon Mie fit (5-50); <= 0: ice crystals
  real baseRound;           // shape: rounded over ph in [0, baseRound] (Haggstrom eq. 5: 0.07)
  real topRoundStart;       // shape: rounds off from topRoundStart * peak to the peak (eq. 6: 0.2)
  real peak;                // highest ph the tops reach (the weather map's wh, eq. 6)
  real peakVariation;       // fraction of the peak the cloud map varies (tall and low tops)
  real anvil;               // anvil amount aa (eq. 17-18), 0 or 1
  real densityGradient;     // 1: density grows linearly with ph (eq. 8), 0: uniform
  real densityBaseFade;     // density fades in over ph in [0, this] (eq. 8: 0.15)
  real densityTopFade;      // and out over the top [1 - this, 1] (eq. 9: 0.1)
  real coverageEdge;        // width of the soft coverage threshold, noise units
  real fibrous;             // 0: billowy Perlin-Worley shape, 1: fibrous (ice) shape
  real erosion;             // detail noise's greatest influence (eq. 14: 0.35)
  real wispyHeight;         // ph where wispy erosion turns billowy (eq. 14: 1/5)
  real columnFill;          // mean of density over a cloud column, for the diffuse light's depth
  real unused;
};

CloudType mixCloudType(CloudType a, CloudType b, real w) {
  CloudType m;
  m.extinction_perm = mix(a.extinction_perm, b.extinction_perm, w);
  m.dropletDiameter_um = mix(a.dropletDiameter_um, b.dropletDiameter_um, w);
  m.baseRound = mix(a.baseRound, b.baseRound, w);
  m.topRoundStart = mix(a.topRoundStart, b.topRoundStart, w);
  m.peak = mix(a.peak, b.peak, w);
  m.peakVariation = mix(a.peakVariation, b.peakVariation, w);
  m.anvil = mix(a.anvil, b.anvil, w);
  m.densityGradient = mix(a.densityGradient, b.densityGradient, w);
  m.densityBaseFade = mix(a.densityBaseFade, b.densityBaseFade, w);
  m.densityTopFade = mix(a.densityTopFade, b.densityTopFade, w);
  m.coverageEdge = mix(a.coverageEdge, b.coverageEdge, w);
  m.fibrous = mix(a.fibrous, b.fibrous, w);
  m.erosion = mix(a.erosion, b.erosion, w);
  m.wispyHeight = mix(a.wispyHeight, b.wispyHeight, w);
  m.columnFill = mix(a.columnFill, b.columnFill, w);
  m.unused = 0.0;
  return m;
}

real saturate1(real v) {
  return clamp(v, 0.0, 1.0);
}

// Coverage in [0, 1] after the cloud map m in [0, 1] moved it; 0 and 1 are fixed points.
real mappedCoverage(real coverage, real m) {
  return clamp(coverage + kCloudMapAmplitude * (m - 0.5) * 4.0 * coverage * (1.0 - coverage), 0.0, 1.0);
}

// How far into the anvil zone ph is, times the anvil amount: 0 below
// kAnvilStart (and for types without an anvil), the amount above kAnvilEnd.
real anvilRamp(CloudType t, real ph) {
  return t.anvil * saturate1((ph - kAnvilStart) / (kAnvilEnd - kAnvilStart));
}

// Coverage c raised towards 1 in the anvil zone (ph in [0.65, 0.95]) by the
// anvil amount: an anvil spreads over the whole storm cell the weather map
// gives (Haggstrom's eq. 17 spreads only where the map already has cloud;
// a storm cell's tiles are mostly its anvil's footprint). c = 0 stays 0.
real anvilCoverage(CloudType t, real ph, real c) {
  if (c <= 0.0) return 0.0;
  return mix(c, 1.0, anvilRamp(t, ph));
}

// Shape-altering height function SA (Haggstrom eq. 5-7, with anvils eq. 17)
// at height fraction ph, for coverage c and the cloud map's peak value
// peakNoise in [0, 1]. 0 outside the layer. An anvil's top is flat: over the
// anvil zone the top rounding gives way to 1 (by the anvil ramp), so the
// anvil reaches the layer top wherever the tower's varied peak wh ends
// (Haggstrom's wh is one weather-map value per cell; ours varies with the
// cloud map, and eq. 17's exponent cannot lift SA = 0 above wh).
real shapeProfile(CloudType t, real ph, real c, real peakNoise) {
  if (ph <= 0.0 || ph >= 1.0) return 0.0;
  real wh = t.peak * (1.0 - t.peakVariation * (1.0 - peakNoise));
  real bottom = saturate1(ph / t.baseRound);
  real top = saturate1((wh - ph) / (wh * (1.0 - t.topRoundStart)));
  real ramp = anvilRamp(t, ph);
  real sa = bottom * mix(top, 1.0, ramp);
  if (ramp > 0.0 && sa > 0.0) sa = pow(sa, max(1.0 - ramp * c, kMinAnvilExponent));
  return sa;
}

// Density-altering height function DA (Haggstrom eq. 8-10, anvils eq. 18)
// without the weather density, in [0, 1].
real densityProfile(CloudType t, real ph) {
  if (ph <= 0.0 || ph >= 1.0) return 0.0;
  real da = mix(1.0, ph, t.densityGradient) * saturate1(ph / t.densityBaseFade) *
            saturate1((1.0 - ph) / t.densityTopFade);
  if (t.anvil > 0.0) {
    real reduce = saturate1(mix(1.0, kAnvilDensityFloor,
                                (sqrt(ph) - kAnvilDensityStart) / (kAnvilDensityEnd - kAnvilDensityStart)));
    da *= mix(1.0, reduce, t.anvil);
  }
  return da;
}

// The shape before erosion, in [0, 1] (Haggstrom eq. 15 with a soft
// threshold of width coverageEdge): noise times SA above 1 - c. With the
// shape noise uniform in [0, 1], coverage is the fraction of the volume that
// is cloud, and coverage 0 is exactly empty (noise * SA <= 1).
real cloudShape(CloudType t, real2 shapeNoise, real c, real sa) {
  if (c <= 0.0 || sa <= 0.0) return 0.0;
  real n = mix(shapeNoise.x, shapeNoise.y, t.fibrous);
  return saturate1((n * sa - (1.0 - c)) / t.coverageEdge);
}

// Erosion by the detail noise dn in [0, 1] (Haggstrom eq. 14, 16): wispy
// (inverted) at the base turning billowy above wispyHeight, weaker with
// coverage.
real erodeShape(CloudType t, real shape, real dn, real c, real ph) {
  real modifier = t.erosion * exp(-kErosionCoverageFalloff * c) * mix(dn, 1.0 - dn, saturate1(ph / t.wispyHeight));
  return saturate1((shape - modifier) / (1.0 - modifier));
}
