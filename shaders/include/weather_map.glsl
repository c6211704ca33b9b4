// The weather map's lookups for the GPU passes that read it (the clouds and
// the reprojection): a camera-local point -> the weather anchor's frame ->
// the gnomonic plane of the anchor sphere (core_common.glsl's anchorPlane) -> texture
// coordinates of the rings: the fine ring inside its blend band, the coarse
// ring beyond, linear in the max norm between (core_common.glsl's
// ringBlendWeight, which WeatherField::sampleLayer calls too). The includer declares
// weatherTex (sampler2DArray, sky_shared.h's layout), gCamToAnchor (mat3,
// camera-local -> anchor-local), gCamInAnchor (xyz: the camera relative to
// the anchor sphere's centre, anchor frame; w: its radius), gMapScale (1 / the
// fine ring's edge) and gRings (x: 1 / the coarse ring's edge; y, z: the
// blend band in fractions of the fine ring's half extent).

bool weatherPlane(vec3 p, out vec2 plane) {
  vec3 a = anchorPlane(gCamToAnchor, gCamInAnchor.xyz, gCamInAnchor.w, p);
  plane = a.xy;
  return a.z > 0.0;
}

// Texture layer `base` of the fine ring (a cover slice, or kWindMapLayers +
// a slice) and its coarse ring's layer (+ kMaxLayers) at a plane point.
vec4 sampleMapLayer(vec2 plane, float base) {
  float w = ringBlendWeight(plane, 2.0 * gMapScale, gRings.y, gRings.z);
  vec4 v = vec4(0.0);
  if (w < 1.0) v = textureLod(weatherTex, vec3(plane * gMapScale + 0.5, base), 0.0);
  if (w > 0.0) v = mix(v, textureLod(weatherTex, vec3(plane * gRings.x + 0.5, base + float(kMaxLayers)), 0.0), w);
  return v;
}

// A layer's wind at a plane point, in the anchor's east/north (m/s).
vec2 mapWind(float slice, vec2 plane) {
  return windFromTexel(sampleMapLayer(plane, float(kWindMapLayers) + slice));
}

// The same at a camera-local point, in the camera's frame (horizontal);
// `fallback` behind the anchor sphere's horizon.
vec3 mapWindLocal(float slice, vec3 p, vec3 fallback) {
  vec2 plane;
  if (!weatherPlane(p, plane)) return fallback;
  // Anchor east/north back to the camera's frame (the rotation's transpose).
  return vec3(mapWind(slice, plane), 0.0) * gCamToAnchor;
}
