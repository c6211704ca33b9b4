// How much of a layer's cloud is present at a height: written once in the
// subset GLSL and C++ share, for the renderer's density (shaders/include/
// cloud_core.glsl) and the point query that answers CIGI and the HTTP API
// (protocol/weather/src/query.cpp), so the image and the answers agree at a
// layer's edges. The includer defines `real` and GLSL's clamp and min.
//
// A layer's shell is its cloud from base to top with its transition band
// (CIGI 3.3 Weather Control's Transition Band) below the base and above the
// top. ph is the height's fraction of the shell, band the band's fraction of
// the shell at each end (in [0, 0.5)). The cloud is whole from base to top
// and fades linearly to nothing across each band; with no band, whole over
// the shell, its ends included.
real layerPresence(real ph, real band) {
  if (ph < 0.0 || ph > 1.0) return 0.0;
  if (band <= 0.0) return 1.0;
  return clamp(min(ph, 1.0 - ph) / band, 0.0, 1.0);
}

// The presence's integral from ph to the shell's top, in shell fractions:
// the part of a column of the shell above ph that is cloud (1 - ph with no
// band; 1 - band from the shell's bottom).
real layerPresenceAbove(real ph, real band) {
  real x = clamp(ph, 0.0, 1.0);
  if (band <= 0.0) return 1.0 - x;
  real below = x <= band ? 0.5 * x * x / band
               : (x <= 1.0 - band ? x - 0.5 * band : 1.0 - band - 0.5 * (1.0 - x) * (1.0 - x) / band);
  return 1.0 - band - below;
}
