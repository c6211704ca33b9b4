// The weather radar on the map (GET /api/radar): the reflectivity round the
// view's centre, from the same tiles the renderers draw, as an image in the
// usual weather radar colours over the map's ground. Asked for after a move
// ends, every RADAR_REFRESH_MS and when the weather changes, at most one
// request in flight (request_loop.js).
import { request } from "./api.js";
import { direct, inverse, normalizeLon } from "./geo.js";
import { RequestLoop } from "./request_loop.js";

const L = window.L;

// Cells a side of the picture asked for, and the API's range (km).
const RADAR_SIZE = 128;
const RADAR_RANGE_KM = [1, 300];
// Asked again this long after the map stops, and this often while shown
// (ms): the wind field's times (weather_overlay.js), for the same reasons.
const RADAR_SETTLE_MS = 300, RADAR_REFRESH_MS = 5000;

// From 5 dBZ in 5-dBZ steps, the last from 70 up: the renderer's
// --radar pictures use the same (renderer/app/src/radar_image.cpp).
export const RADAR_SCALE = [[4, 233, 231], [1, 159, 244], [3, 0, 244], [2, 253, 2], [1, 197, 1], [0, 142, 0],
  [253, 248, 2], [229, 188, 0], [253, 149, 0], [253, 0, 0], [212, 0, 0], [188, 0, 0], [248, 0, 253],
  [255, 255, 255]];

// The colour of a reflectivity (dBZ), or null below 5 dBZ.
export function radarColour(dbz) {
  if (!(dbz >= 5)) return null;
  return RADAR_SCALE[Math.min(Math.floor((dbz - 5) / 5), RADAR_SCALE.length - 1)];
}

export const RadarLayer = L.Layer.extend({
  initialize(pane) {
    L.setOptions(this, { pane });
    this.shown = false;
    this.answer = null;  // the last answer drawn
    this.loop = new RequestLoop({
      wanted: () => this.shown && !!this._map,
      send: async () => {
        const q = this.query();
        const url = `/api/radar?lat=${q.lat.toFixed(5)}&lon=${q.lon.toFixed(5)}&range_km=${q.range_km}&size=${RADAR_SIZE}`;
        return { r: await request("GET", url), url };
      },
      answered: ({ r, url }) => {
        if (r.ok && r.body && Array.isArray(r.body.dbz)) this.draw(r.body, url);
      },
      settle_ms: RADAR_SETTLE_MS, refresh_ms: RADAR_REFRESH_MS,
    });
  },
  onAdd(map) {
    map.on("moveend zoomend resize", this.loop.moved, this.loop);
    this.loop.start();
  },
  onRemove(map) {
    map.off("moveend zoomend resize", this.loop.moved, this.loop);
    this.clear();
    this.loop.stop();
  },

  set(shown) {
    if (shown === this.shown) return;
    this.shown = shown;
    if (shown) this.loop.ask();
    else {
      this.loop.cancel();
      this.clear();
    }
  },

  weatherChanged() {
    this.loop.ask();
  },

  clear() {
    if (this.image) this.image.remove();
    this.image = null;
    this.answer = null;
    const c = this._map && this._map.getContainer();
    if (c) for (const k of ["radarEchoes", "radarMaxDbz", "radarQuery"]) delete c.dataset[k];
  },

  // The radar at the view's centre, its range the view's farthest edge.
  query() {
    const map = this._map, size = map.getSize(), c = map.getCenter();
    const lat = Math.max(-89, Math.min(89, c.lat)), lon = normalizeLon(c.lng);
    let far_m = 0;
    for (const [fx, fy] of [[0.5, 0], [1, 0.5], [0.5, 1], [0, 0.5]]) {
      const p = map.containerPointToLatLng([fx * size.x, fy * size.y]);
      far_m = Math.max(far_m, inverse(lat, lon, p.lat, p.lng).distance_m);
    }
    const range_km = Math.max(RADAR_RANGE_KM[0], Math.min(RADAR_RANGE_KM[1], Math.round(far_m / 1000)));
    return { lat, lon, range_km };
  },

  draw(answer, url) {
    const n = answer.size, canvas = document.createElement("canvas");
    canvas.width = n;
    canvas.height = n;
    const g = canvas.getContext("2d"), img = g.createImageData(n, n);
    for (let i = 0; i < n; ++i)
      for (let j = 0; j < n; ++j) {
        const c = radarColour(answer.dbz[i][j]), k = (i * n + j) * 4;
        if (!c) continue;
        img.data.set([c[0], c[1], c[2], 255], k);
      }
    g.putImageData(img, 0, 0);
    // The picture's square (the radar's tangent plane) placed by its edges'
    // midpoints, a half side from the radar: within a percent at 300 km.
    const half_m = answer.range_km * 1000, at = (az) => direct(answer.lat_deg, answer.lon_deg, az, half_m);
    const east = answer.lon_deg + normalizeLon(at(90).lon_deg - answer.lon_deg);
    const west = answer.lon_deg + normalizeLon(at(270).lon_deg - answer.lon_deg);
    const bounds = [[at(180).lat_deg, west], [at(0).lat_deg, east]];
    if (this.image) this.image.remove();
    this.image = L.imageOverlay(canvas.toDataURL(), bounds, { pane: this.options.pane, className: "radar-image", opacity: 0.8 })
      .addTo(this._map);
    this.answer = answer;
    const c = this._map.getContainer();
    c.dataset.radarEchoes = String(answer.echoes);
    c.dataset.radarMaxDbz = answer.max_dbz === null ? "" : String(answer.max_dbz);
    c.dataset.radarQuery = url;
  },
});
