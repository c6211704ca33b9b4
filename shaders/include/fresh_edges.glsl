// Fresh edges (TemporalSettings::freshEdges): in a turn, what comes into view
// at the image's edges has no history, and an interleaved frame would
// upscale it from 1 pixel of each n x n block, a coarse band that the
// history then carries for frames. The frame draws those edges at every
// pixel instead, as four bands: left and right over the full height, top
// and bottom between them, widths (left, right, top, bottom) in pixels
// (temporal_plan.cpp measures them). The bands' pixels are numbered left
// band first, row by row, then right, top, bottom: the cloud pass writes
// sample k after the packed pixels of the frame, the reprojection finds it
// there. No preset turns it on: measured on the bench's camera paths it
// costs more than it gains (docs/motion.md). Written in the subset GLSL and
// C++ share (core_common.glsl); the C++ unit test
// (tests/unit/renderer/fresh_edges_test.cpp) compiles it.

// Pixels in the four bands of a width x height image.
uint freshEdgeCount(uvec4 edges, uvec2 size) {
  uint middle = size.x - edges.x - edges.y;
  return (edges.x + edges.y) * size.y + middle * (edges.z + edges.w);
}

// The number of pixel p in the bands, -1 when it lies in none.
int freshEdgeIndex(ivec2 p, uvec4 edges, uvec2 size) {
  int w = int(size.x), h = int(size.y);
  int l = int(edges.x), r = int(edges.y), t = int(edges.z), b = int(edges.w);
  int middle = w - l - r;
  int k = -1;
  if (p.x < l)
    k = p.y * l + p.x;
  else if (p.x >= w - r)
    k = l * h + p.y * r + (p.x - (w - r));
  else if (p.y < t)
    k = (l + r) * h + p.y * middle + (p.x - l);
  else if (p.y >= h - b)
    k = (l + r) * h + t * middle + (p.y - (h - b)) * middle + (p.x - l);
  return k;
}

// The pixel numbered k (0 <= k < freshEdgeCount). Divisors are kept >= 1:
// lavapipe evaluates every branch for every lane, and an integer division
// by zero would trap.
ivec2 freshEdgePixel(int k, uvec4 edges, uvec2 size) {
  int w = int(size.x), h = int(size.y);
  int l = int(edges.x), r = int(edges.y), t = int(edges.z), b = int(edges.w);
  int middle = max(w - l - r, 1);
  int left = l * h, right = r * h, top = t * (w - l - r);
  if (k < left) return ivec2(k % max(l, 1), k / max(l, 1));
  k -= left;
  if (k < right) return ivec2(w - r + k % max(r, 1), k / max(r, 1));
  k -= right;
  if (k < top) return ivec2(l + k % middle, k / middle);
  k -= top;
  return ivec2(l + k % middle, h - b + k / middle);
}
