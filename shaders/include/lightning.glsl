// Lightning's light, written once for the GPU and the CPU reference
// (included by cloud_core.glsl; the includer defines the hooks):
//   real4 flashAt(int k)       // flash k lit this frame: xyz its light's centre, camera-local
//                              // (m); w its intensity, linear units x m^2 (irradiance at 1 m)
//   real4 boltStartAt(int k)   // bolt segment k: xyz its start, camera-local (m); w the
//                              // channel's intensity per metre, linear units x m (per sr)
//   real3 boltEndAt(int k)     // its end
// The counts and a pixel's angle are CoreFrame's (flashCount, boltCount,
// pixelAngle). The CPU side (renderer/core/src/flash_setup.cpp) turns the
// server's flashes into these: power from the flash's strokes over the
// frame's exposure, positions from geodetic.
//
// A flash lights its cloud from inside: the irradiance I / d^2 of a point
// source, carried into the cloud over kFlashGlow_m (the flash's light is
// scattered many times before it leaves the cloud; this length stands for
// that diffusion, a scale chosen to give the glow a storm cell's size, not
// a transport solution), scattered isotropically (1 / 4 pi) by the march's
// samples like the sun's light. The channel of a cloud-to-ground flash is a
// line source seen directly: its intensity per metre over the distance,
// spread across kBoltBlurPixels of the image (a real channel is centimetres
// wide; what a camera records is its blur).

real4 flashAt(int k);
real4 boltStartAt(int k);
real3 boltEndAt(int k);

// The glow's reach inside the cloud (m) and a core radius that keeps the
// point source finite at its centre (m): a flash channel is hundreds of
// metres long, not a point.
SKY_CORE_CONST real kFlashGlow_m = 1500.0;
SKY_CORE_CONST real kFlashCore_m = 150.0;
// A lightning channel's light: a hot plasma (near 30000 K at its peak),
// bluish white; in the renderer's linear RGB.
real3 flashColour() { return real3(0.85, 0.9, 1.0); }
// The drawn channel's width: a Gaussian of this many pixels' standard
// deviation (wide enough to be sampled at every pixel it crosses).
SKY_CORE_CONST real kBoltBlurPixels = 0.7;

// Light per unit scattering coefficient at p from the frame's flashes:
// their irradiance times the isotropic phase.
real3 flashInscatter(int count, real3 p) {
  real sum = 0.0;
  for (int k = 0; k < count; ++k) {
    real4 fl = flashAt(k);
    real3 d = p - real3(fl);
    real dd = dot(d, d);
    sum += fl.w * exp(-sqrt(dd) / kFlashGlow_m) / (dd + kFlashCore_m * kFlashCore_m);
  }
  return flashColour() * (sum / (4.0 * kPi));
}

// The standard normal's cumulative distribution, to within 0.01 (the
// logistic approximation, slope 1.702): GLSL has no erf.
real normalCdf(real x) { return 1.0 / (1.0 + exp(-1.702 * x)); }

// The bolt's radiance along dir and the distance it is seen at (the
// distance of its brightest segment; 0 with none). Each segment is a line
// source convolved with the blur's Gaussian: across it the Gaussian of the
// ray's angle from its line, along it the Gaussian's integral over its
// length, so a straight channel cut into segments draws as one line (no
// double light where two segments meet).
real2 boltRadiance(int count, real pixelAngle, real3 dir) {
  real radiance = 0.0;
  real best = 0.0;
  real depth = 0.0;
  real sigma = max(kBoltBlurPixels * pixelAngle, 1e-6);
  for (int k = 0; k < count; ++k) {
    real4 a = boltStartAt(k);
    real3 a3 = real3(a);
    real3 u = boltEndAt(k) - a3;
    // Closest points of the segment's line and the ray: s along the
    // segment (0 at its start, 1 at its end), unclamped. A segment along
    // the ray shows as a point, of no length across the view: skipped.
    real ud = dot(u, dir);
    real across2 = dot(u, u) - ud * ud;
    if (across2 < 1e-6) continue;
    real s = (dot(a3, dir) * ud - dot(a3, u)) / across2;
    real3 q = a3 + u * s;
    real t = dot(q, dir);
    if (t <= 0.0) continue;
    real3 off = q - dir * t;
    real angle = sqrt(dot(off, off)) / t;
    real across = sqrt(across2) / t;  // the segment's angular length across the view
    real window = normalCdf(s * across / sigma) - normalCdf((s - 1.0) * across / sigma);
    real g = exp(-0.5 * (angle * angle) / (sigma * sigma)) / (2.5066282746310002 * sigma);
    real r = a.w / t * g * window;
    radiance += r;
    if (r > best) {
      best = r;
      depth = t;
    }
  }
  return real2(radiance, depth);
}
