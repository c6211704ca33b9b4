// The weather texture's wind layers, decoded: written once for the GPU passes
// that read them (the clouds, the reprojection) and the CPU reference. The
// includer defines real, real2, real4 and kWindMapScale_mps (sky_shared.h).

// The wind map's texel (both components' high and low bytes, filtered) as
// the wind, m/s: each component q = (v / scale + 1) / 2 * 65535 in two bytes,
// so the filter, linear in each byte, filters the wind itself.
real2 windFromTexel(real4 t) {
  real2 q = real2(t.x * 255.0 * 256.0 + t.y * 255.0, t.z * 255.0 * 256.0 + t.w * 255.0);
  return (q / 65535.0 * 2.0 - 1.0) * real(kWindMapScale_mps);
}
