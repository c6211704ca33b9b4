// Spherical geodesy for the console's map: distances, azimuths and the
// azimuthal equidistant projection about the map's focus point. The console
// draws; it does not decide weather, so a sphere is enough here (the server
// measures regions on the WGS84 ellipsoid; the two differ by under 0.5 %,
// less than a pixel at the map's scales).

// Mean Earth radius (IUGG R1), the sphere the server's own bounds use.
export const EARTH_RADIUS_M = 6371008.8;
// Web Mercator's latitude limit, where the map ends (the latitude whose
// Mercator y is pi: Leaflet's SphericalMercator.MAX_LATITUDE).
export const MERCATOR_MAX_LAT_DEG = 85.0511287798;
const D2R = Math.PI / 180;

// Longitude into [-180, 180).
export function normalizeLon(lon_deg) {
  const l = ((((lon_deg + 180) % 360) + 360) % 360) - 180;
  return l;
}

// Great-circle distance (m) and initial azimuth (degrees clockwise from
// north) from point 1 to point 2; haversine for the distance, which stays
// accurate for short distances.
export function inverse(lat1_deg, lon1_deg, lat2_deg, lon2_deg) {
  const p1 = lat1_deg * D2R, p2 = lat2_deg * D2R, dl = (lon2_deg - lon1_deg) * D2R;
  const s1 = Math.sin((p2 - p1) / 2), s2 = Math.sin(dl / 2);
  const h = s1 * s1 + Math.cos(p1) * Math.cos(p2) * s2 * s2;
  const distance_m = 2 * EARTH_RADIUS_M * Math.asin(Math.min(1, Math.sqrt(h)));
  const y = Math.sin(dl) * Math.cos(p2);
  const x = Math.cos(p1) * Math.sin(p2) - Math.sin(p1) * Math.cos(p2) * Math.cos(dl);
  const azimuth_deg = Math.atan2(y, x) / D2R;
  return { distance_m, azimuth_deg };
}

// The point `distance_m` from (lat, lon) along the great circle leaving at
// `azimuth_deg`.
export function direct(lat_deg, lon_deg, azimuth_deg, distance_m) {
  const p1 = lat_deg * D2R, a = azimuth_deg * D2R, d = distance_m / EARTH_RADIUS_M;
  const sp2 = Math.sin(p1) * Math.cos(d) + Math.cos(p1) * Math.sin(d) * Math.cos(a);
  const p2 = Math.asin(Math.max(-1, Math.min(1, sp2)));
  const l2 = Math.atan2(Math.sin(a) * Math.sin(d) * Math.cos(p1), Math.cos(d) - Math.sin(p1) * sp2);
  return { lat_deg: p2 / D2R, lon_deg: normalizeLon(lon_deg + l2 / D2R) };
}

// Azimuthal equidistant projection about a focus point: east (x) and north
// (y) in metres on the plane tangent at the focus, distances from the focus
// true. Exact inverse pair.
export class Projection {
  constructor(focusLat_deg, focusLon_deg) {
    this.lat0 = focusLat_deg;
    this.lon0 = focusLon_deg;
  }
  forward(lat_deg, lon_deg) {
    const { distance_m, azimuth_deg } = inverse(this.lat0, this.lon0, lat_deg, lon_deg);
    const a = azimuth_deg * D2R;
    return { x_m: distance_m * Math.sin(a), y_m: distance_m * Math.cos(a) };
  }
  inverse(x_m, y_m) {
    const distance_m = Math.hypot(x_m, y_m);
    if (distance_m === 0) return { lat_deg: this.lat0, lon_deg: this.lon0 };
    return direct(this.lat0, this.lon0, Math.atan2(x_m, y_m) / D2R, distance_m);
  }
}
