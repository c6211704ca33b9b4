// A layer's coverage over the map, computed from GET /api/state the way the
// server derives its coverage tiles (server/src/snapshot_builder.cpp): a
// global layer is uniform; a region (CIGI Environmental Region Control: a
// rounded rectangle with a transition perimeter) carries its own layers, and
// across the perimeter its layer blends into the global one with a smoothstep
// of the distance (sky/weather/region.hpp, regionWeight).
import { direct, inverse } from "./geo.js";

const D2R = Math.PI / 180;

// Signed distance (m) from a surface point to the region's edge in the
// region's own frame: negative inside, 0 on the edge, positive outside.
// y is along azimuth rotation_deg, x a quarter turn clockwise of it.
export function regionEdgeDistance_m(region, lat_deg, lon_deg) {
  const { distance_m, azimuth_deg } = inverse(region.center_lat_deg, region.center_lon_deg, lat_deg, lon_deg);
  const a = (azimuth_deg - (region.rotation_deg || 0)) * D2R;
  const u = Math.abs(distance_m * Math.sin(a)), v = Math.abs(distance_m * Math.cos(a));
  const rc = region.corner_radius_m || 0;
  const qx = u - (region.size_x_m / 2 - rc), qy = v - (region.size_y_m / 2 - rc);
  const outside = Math.hypot(Math.max(qx, 0), Math.max(qy, 0));
  const inside = Math.min(Math.max(qx, qy), 0);
  return outside + inside - rc;
}

// How much the region's weather replaces the global weather: 1 inside, 0
// beyond the perimeter, smoothstep between.
export function regionWeight(region, lat_deg, lon_deg) {
  const d = regionEdgeDistance_m(region, lat_deg, lon_deg);
  if (d <= 0) return 1;
  const t_m = region.transition_m || 0;
  if (d >= t_m) return 0;
  const t = 1 - d / t_m;
  return t * t * (3 - 2 * t);
}

// Every layer id the state holds (global first, then region-only ones).
export function layerIds(state) {
  const ids = [];
  for (const l of state.layers) if (!ids.includes(l.id)) ids.push(l.id);
  for (const r of state.regions) for (const l of r.layers) if (!ids.includes(l.id)) ids.push(l.id);
  return ids;
}

// Coverage [0, 1] of layer `layerId` at a point: the global value, moved
// towards the weighted mean of the regions' values by their summed weight
// (capped at 1), as the server's tiles carry it. A layer only regions have is
// 0 outside them.
export function coverageAt(state, layerId, lat_deg, lon_deg) {
  const global = state.layers.find((l) => l.id === layerId);
  const base = global ? global.coverage : 0;
  let sumW = 0, sum = 0;
  for (const r of state.regions) {
    const layer = r.layers.find((l) => l.id === layerId);
    if (!layer) continue;
    const w = regionWeight(r, lat_deg, lon_deg);
    if (w <= 0) continue;
    sumW += w;
    sum += w * layer.coverage;
  }
  if (sumW <= 0) return base;
  const w = Math.min(sumW, 1);
  return base + w * (sum / sumW - base);
}

// Points (lat, lon) around the region's edge grown outward by grow_m (0: the
// edge; transition_m: the outer edge of the perimeter): a rounded rectangle
// whose corner radius grows with it, walked in the region's frame and carried
// onto the sphere from the centre.
export function regionOutline(region, grow_m, pointsPerCorner = 12) {
  const rc = (region.corner_radius_m || 0) + grow_m;
  const hx = region.size_x_m / 2 + grow_m, hy = region.size_y_m / 2 + grow_m;
  const cx = hx - rc, cy = hy - rc;  // corner centres at (+-cx, +-cy)
  const corners = [[cx, cy, 0], [cx, -cy, 90], [-cx, -cy, 180], [-cx, cy, 270]];
  const out = [];
  for (const [x0, y0, start] of corners) {
    for (let k = 0; k <= pointsPerCorner; ++k) {
      // Angles clockwise from +y, as azimuths are.
      const ang = (start + (90 * k) / pointsPerCorner) * D2R;
      const x = x0 + rc * Math.sin(ang), y = y0 + rc * Math.cos(ang);
      out.push(regionPoint(region, x, y));
    }
  }
  return out;
}

// The surface point at (x, y) metres in the region's frame.
export function regionPoint(region, x_m, y_m) {
  const azimuth = (region.rotation_deg || 0) + Math.atan2(x_m, y_m) / D2R;
  return direct(region.center_lat_deg, region.center_lon_deg, azimuth, Math.hypot(x_m, y_m));
}
