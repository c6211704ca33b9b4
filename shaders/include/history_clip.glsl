// Variance clipping of a reprojected history (Salvi 2016, after Karis 2014):
// the history of a pixel is trusted only as far as it lies inside the box
// the pixels drawn this frame around it span; outside, it is moved along
// the line to the box's centre onto the box. The space is chosen for the
// bright and dark edges of clouds: radiance compressed by 1 / (1 + its
// largest channel), so a sunlit edge next to a dark base does not stretch
// the box over everything between them, then YCoCg, where a box follows
// brightness and hue rather than red, green and blue; the transmittance
// (alpha) is the fourth axis, as it is what tells cloud from sky.
// Written in the subset GLSL and C++ share (core_common.glsl); the C++ unit
// test (tests/unit/renderer/history_clip_test.cpp) compiles it in double.

// Radiance (rgb) and transmittance (a) into the clipping space.
real4 historyClipSpace(real4 c) {
  real m = max(max(max(c.x, c.y), c.z), real(0.0));
  real3 t = real3(c.x, c.y, c.z) / (real(1.0) + m);
  return real4(real(0.25) * t.x + real(0.5) * t.y + real(0.25) * t.z, real(0.5) * t.x - real(0.5) * t.z,
               real(-0.25) * t.x + real(0.5) * t.y - real(0.25) * t.z, c.w);
}

// The inverse of historyClipSpace. A point of the box may lie where no
// colour maps to (compressed channels reach 1 only at infinite radiance):
// the largest channel is kept below 1 - 1/1024, radiance below 1023.
real4 historyFromClipSpace(real4 y) {
  real3 t = real3(y.x + y.y - y.z, y.x + y.z, y.x - y.y - y.z);
  t = max(t, real3(0.0));
  real m = min(max(max(t.x, t.y), t.z), real(1.0) - real(1.0) / real(1024.0));
  real3 c = t / (real(1.0) - m);
  return real4(c.x, c.y, c.z, y.w);
}

// The box of a neighbourhood, built one sample at a time in clipping space.
struct HistoryBox {
  real4 lo;    // the samples' smallest value per axis
  real4 hi;    // and largest
  real4 sum;   // their sum
  real4 sum2;  // and the sum of their squares
  real count;
};

HistoryBox historyBoxEmpty() {
  HistoryBox b;
  b.lo = real4(1e30);
  b.hi = real4(-1e30);
  b.sum = real4(0.0);
  b.sum2 = real4(0.0);
  b.count = real(0.0);
  return b;
}

HistoryBox historyBoxAdd(HistoryBox b, real4 sampleInClipSpace) {
  b.lo = min(b.lo, sampleInClipSpace);
  b.hi = max(b.hi, sampleInClipSpace);
  b.sum += sampleInClipSpace;
  b.sum2 += sampleInClipSpace * sampleInClipSpace;
  b.count += real(1.0);
  return b;
}

// The history h (radiance and transmittance) clipped to the box: mean +-
// gamma standard deviations per axis, inside the samples' own range (so it
// never reaches a value none of them has). Unchanged when it lies inside,
// or when the box holds no sample.
real4 clipHistory(HistoryBox b, real4 h, real gamma) {
  if (b.count < real(1.0)) return h;
  real4 mean = b.sum / b.count;
  real4 sigma = sqrt(max(b.sum2 / b.count - mean * mean, real4(0.0)));
  real4 lo = max(b.lo, mean - gamma * sigma);
  real4 hi = min(b.hi, mean + gamma * sigma);
  real4 centre = real(0.5) * (lo + hi);
  real4 halfExtent = max(real(0.5) * (hi - lo), real4(1e-6));
  real4 y = historyClipSpace(h);
  real4 v = y - centre;
  real4 r = abs(v) / halfExtent;
  real outside = max(max(r.x, r.y), max(r.z, r.w));
  if (outside <= real(1.0)) return h;
  return historyFromClipSpace(centre + v / outside);
}
