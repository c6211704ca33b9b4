// The map's weather overlay: one canvas over the whole view, above the
// ground and under the regions, with the selected layer's coverage as a
// translucent white field, the graticule, and the layer's wind as arrows;
// and the wind field at a height (GET /api/wind) as SVG arrows above it,
// with its legend. Redrawn after each move or zoom (hidden while a zoom
// animates) and when the weather changes (MapView.redraw).
import { request } from "./api.js";
import { coverageAt, regionWeight } from "./coverage.js";
import { el } from "./dom.js";
import { inverse, MERCATOR_MAX_LAT_DEG, normalizeLon } from "./geo.js";
import { RequestLoop } from "./request_loop.js";
import { fmt, ftFromM, ktFromMps } from "./units.js";

const L = window.L;

// Coverage is sampled on a grid this coarse (CSS px) and smoothed up: the
// field varies over kilometres, and 6 px keeps a redraw near 10 ms.
const COVERAGE_CELL_PX = 6;
// Spacing of the layer's wind arrows (CSS px).
const ARROW_SPACING_PX = 90;
// An arrow's head: its sides' length (CSS px) and their angle either side
// of the shaft (radians, about 23 degrees).
const ARROW_HEAD_PX = 7, ARROW_HEAD_HALF_ANGLE_RAD = 0.4;
// Least distance between two longitude labels (CSS px): "12.45°" is ~40 px wide.
const LABEL_GAP_PX = 56;
// Graticule labels keep clear of Leaflet's controls (CSS px): the scale bar
// in the bottom left corner (140 px wide, two lines of ~20 px, a 10 px
// margin) and the attribution in the bottom right (~150 px) with a label's
// width (~40 px) before it.
const CLEAR_LEFT_PX = 170, CLEAR_BOTTOM_PX = 60, CLEAR_RIGHT_PX = 190;
const LABEL_FONT_PX = 11;
// Graticule spacings to choose from (degrees).
const GRID_STEPS_DEG = [0.01, 0.02, 0.05, 0.1, 0.2, 0.25, 0.5, 1, 2, 5, 10, 15, 30];

// One wind arrow's points: a shaft `len_px` long centred on (x, y) pointing
// toward `toward_deg` (true, clockwise from north: Web Mercator keeps north
// up and is conformal, so a bearing is an angle on the screen), and the two
// back corners of its head. Pixels in the frame of x, y (y down). Shared by
// the layer's arrows (canvas) and the wind field's (SVG).
export function arrowGeometry(x, y, toward_deg, len_px, head_px = ARROW_HEAD_PX) {
  const a = (toward_deg * Math.PI) / 180;
  const dx = Math.sin(a) * len_px, dy = -Math.cos(a) * len_px;
  const tip = { x: x + dx / 2, y: y + dy / 2 };
  const back = Math.atan2(dy, dx);
  const corner = (side) => ({ x: tip.x - head_px * Math.cos(back + side * ARROW_HEAD_HALF_ANGLE_RAD),
    y: tip.y - head_px * Math.sin(back + side * ARROW_HEAD_HALF_ANGLE_RAD) });
  return { tail: { x: x - dx / 2, y: y - dy / 2 }, tip, left: corner(-1), right: corner(1) };
}

// data: {state(), selectedLayer(), layerWind()} (MapView's, and whether the
// layer's own arrows are drawn); pane: the Leaflet pane.
export const WeatherOverlay = L.Layer.extend({
  initialize(data, pane) {
    this.data = data;
    L.setOptions(this, { pane });  // its own options, not the prototype's
  },
  onAdd(map) {
    this.canvas = L.DomUtil.create("canvas", "sky-overlay leaflet-zoom-hide");
    this.getPane().appendChild(this.canvas);
    map.on("moveend zoomend resize viewreset", this.redraw, this);
    this.redraw();
  },
  onRemove(map) {
    L.DomUtil.remove(this.canvas);
    map.off("moveend zoomend resize viewreset", this.redraw, this);
  },
  redraw() {
    if (!this._map) return;
    const size = this._map.getSize();
    const dpr = window.devicePixelRatio || 1;
    L.DomUtil.setPosition(this.canvas, this._map.containerPointToLayerPoint([0, 0]));
    if (this.canvas.width !== Math.round(size.x * dpr) || this.canvas.height !== Math.round(size.y * dpr)) {
      this.canvas.width = Math.round(size.x * dpr);
      this.canvas.height = Math.round(size.y * dpr);
      this.canvas.style.width = `${size.x}px`;
      this.canvas.style.height = `${size.y}px`;
    }
    const g = this.canvas.getContext("2d");
    g.setTransform(dpr, 0, 0, dpr, 0, 0);
    g.clearRect(0, 0, size.x, size.y);
    this.drawOverlay(g, size.x, size.y);
  },

  drawOverlay(g, w, h) {
    const state = this.data.state();
    const layerId = this.data.selectedLayer();
    if (state && layerId !== null) this.drawCoverage(g, w, h, state, layerId);
    this.drawGraticule(g, w, h);
    if (state && layerId !== null && this.data.layerWind()) this.drawWind(g, w, h, state, layerId);
  },

  surfaceAt(x, y) {
    const p = this._map.containerPointToLatLng([x, y]);
    return { lat_deg: p.lat, lon_deg: normalizeLon(p.lng) };
  },

  drawCoverage(g, w, h, state, layerId) {
    const cols = Math.ceil(w / COVERAGE_CELL_PX), rows = Math.ceil(h / COVERAGE_CELL_PX);
    const cells = this.coverageCanvas || (this.coverageCanvas = document.createElement("canvas"));
    // Sampled again only when the weather, the layer or the view changed
    // (a redraw for the region tool's draft or a renderer keeps it).
    const c = this._map.getCenter();
    const key = JSON.stringify([state.layers, state.regions, layerId, c.lat, c.lng, this._map.getZoom(), cols, rows]);
    if (key !== this.coverageKey) {
      this.coverageKey = key;
      this.sampleCoverage(cells, cols, rows, state, layerId);
    }
    g.imageSmoothingEnabled = true;
    g.drawImage(cells, 0, 0, cols * COVERAGE_CELL_PX, rows * COVERAGE_CELL_PX);
  },

  sampleCoverage(cells, cols, rows, state, layerId) {
    cells.width = cols;
    cells.height = rows;
    const cg = cells.getContext("2d");
    const img = cg.createImageData(cols, rows);
    for (let j = 0; j < rows; ++j) {
      for (let i = 0; i < cols; ++i) {
        const s = this.surfaceAt((i + 0.5) * COVERAGE_CELL_PX, (j + 0.5) * COVERAGE_CELL_PX);
        const v = coverageAt(state, layerId, s.lat_deg, s.lon_deg);
        const o = 4 * (j * cols + i);
        // White cloud over the dark ground, opacity with coverage.
        img.data[o] = 236; img.data[o + 1] = 242; img.data[o + 2] = 250;
        img.data[o + 3] = Math.round(170 * Math.max(0, Math.min(1, v)));
      }
    }
    cg.putImageData(img, 0, 0);
  },

  drawGraticule(g, w, h) {
    const b = this._map.getBounds();
    const south = Math.max(-MERCATOR_MAX_LAT_DEG, b.getSouth()), north = Math.min(MERCATOR_MAX_LAT_DEG, b.getNorth());
    const span = Math.max(north - south, 0.001);
    const step = GRID_STEPS_DEG.find((s) => span / s <= 8) || 30;
    g.save();
    g.strokeStyle = "rgba(150, 180, 210, 0.3)";
    g.fillStyle = "rgba(190, 210, 230, 0.85)";
    g.lineWidth = 1;
    g.font = `${LABEL_FONT_PX}px system-ui, sans-serif`;
    // Web Mercator: parallels are horizontal lines, meridians vertical.
    for (let lat = Math.ceil(south / step) * step; lat <= north; lat += step) {
      const y = Math.round(this._map.latLngToContainerPoint([lat, b.getWest()]).y) + 0.5;
      g.beginPath(); g.moveTo(0, y); g.lineTo(w, y); g.stroke();
      if (y > LABEL_FONT_PX && y < h - CLEAR_BOTTOM_PX) g.fillText(`${fmt(lat, 2)}°`, 4, y - 3);
    }
    let lastLabel_px = -Infinity;  // labels closer than LABEL_GAP_PX are left out
    for (let lon = Math.ceil(b.getWest() / step) * step; lon <= b.getEast(); lon += step) {
      const x = Math.round(this._map.latLngToContainerPoint([b.getSouth(), lon]).x) + 0.5;
      g.beginPath(); g.moveTo(x, 0); g.lineTo(x, h); g.stroke();
      if (x > CLEAR_LEFT_PX && x < w - CLEAR_RIGHT_PX && x - lastLabel_px >= LABEL_GAP_PX) {
        const shown = normalizeLon(lon);
        g.fillText(`${fmt(shown === -180 ? 180 : shown, 2)}°`, x + 3, h - 6);
        lastLabel_px = x;
      }
    }
    g.restore();
  },

  // The wind of the layer at a point: a region's own layer where the region
  // outweighs the global weather, else the global layer's.
  windAt(state, layerId, lat_deg, lon_deg) {
    let best = null, bestW = 0.5;
    for (const r of state.regions) {
      const l = r.layers.find((x) => x.id === layerId);
      if (!l) continue;
      const w = regionWeight(r, lat_deg, lon_deg);
      if (w >= bestW) { best = l; bestW = w; }
    }
    if (best) return best.coverage > 0 ? best.wind : null;
    const gl = state.layers.find((x) => x.id === layerId);
    return gl ? gl.wind : null;
  },

  drawWind(g, w, h, state, layerId) {
    g.save();
    g.strokeStyle = "rgba(120, 230, 160, 0.85)";
    g.fillStyle = g.strokeStyle;
    g.lineWidth = 1.5;
    for (let y = ARROW_SPACING_PX / 2; y < h; y += ARROW_SPACING_PX) {
      for (let x = ARROW_SPACING_PX / 2; x < w; x += ARROW_SPACING_PX) {
        const s = this.surfaceAt(x, y);
        const wind = this.windAt(state, layerId, s.lat_deg, s.lon_deg);
        if (!wind || wind.speed_mps <= 0) continue;
        // Arrows point downwind (the wind blows from from_deg); Mercator
        // keeps north up everywhere. Length grows with speed, 2 px per m/s
        // from 10 px, at most 40.
        const p = arrowGeometry(x, y, wind.from_deg + 180, Math.min(40, 10 + 2 * wind.speed_mps));
        g.beginPath();
        g.moveTo(p.tail.x, p.tail.y);
        g.lineTo(p.tip.x, p.tip.y);
        g.stroke();
        g.beginPath();
        g.moveTo(p.tip.x, p.tip.y);
        g.lineTo(p.left.x, p.left.y);
        g.lineTo(p.right.x, p.right.y);
        g.closePath();
        g.fill();
      }
    }
    g.restore();
  },
});

// ---- the wind field at a height (GET /api/wind) ----

// The endpoint's ranges (server/API.md, GET /api/wind).
export const WIND_ALT_LIMITS_M = [-1000, 20000];
const WIND_RADIUS_LIMITS_M = [1000, 2e6];
// The field is asked again this long after the map stops (ms): a drag or a
// few wheel notches make one request, not one per step.
const WIND_SETTLE_MS = 300;
// ... and this often while shown (ms): the weather clock runs, and a loaded
// forecast evolves with it without a state message to say so.
const WIND_REFRESH_MS = 5000;
// The cap asked for reaches the view's farthest corner with this margin, so
// the cells at the corners have their arrows too.
const WIND_RADIUS_MARGIN = 1.1;
// An arrow is this fraction of the arrows' spacing long at full speed and
// half that when calm, within these bounds (CSS px); below CALM_MPS it is a
// dot (no direction to show).
const WIND_ARROW_FILL = 0.85, WIND_ARROW_MIN_PX = 10, WIND_ARROW_MAX_PX = 48, WIND_FULL_LENGTH_MPS = 50;
const CALM_MPS = 0.1;
// A click or the pointer within this distance of an arrow's shaft picks it (CSS px).
const WIND_PICK_PX = 8;
// Colour by speed (m/s, RGB): blue calm air through green and yellow to the
// red and magenta of a jet stream's core (50-75 m/s, about 100-150 kt);
// linear between stops, the last colour beyond.
const WIND_COLOUR_STOPS = [[0, [95, 168, 255]], [10, [111, 224, 160]], [20, [242, 225, 78]], [35, [255, 154, 60]],
  [50, [255, 79, 109]], [75, [224, 64, 251]]];
// The legend's bar spans the stops (0-75 m/s, 0-146 kt); its ticks in each
// unit system, within the bar.
const LEGEND_TICKS = { m: [0, 25, 50, 75], ft: [0, 50, 100, 140] };
const LEGEND_W_PX = 160, LEGEND_H_PX = 26, LEGEND_BAR_H_PX = 8;

// The colour of a wind speed (m/s) as a CSS rgb().
function windColour(speed_mps) {
  const stops = WIND_COLOUR_STOPS;
  let k = 1;
  while (k < stops.length - 1 && speed_mps > stops[k][0]) ++k;
  const [s0, c0] = stops[k - 1], [s1, c1] = stops[k];
  const t = Math.max(0, Math.min(1, (speed_mps - s0) / (s1 - s0)));
  return `rgb(${c0.map((c, i) => Math.round(c + (c1[i] - c) * t)).join(", ")})`;
}

// A height as the operator reads it: units "m" (m, m/s) or "ft" (ft, kt).
const heightText = (alt_m, units) => (units === "ft" ? `${fmt(ftFromM(alt_m))} ft` : `${fmt(alt_m)} m`);

// The legend in the map's bottom right corner: the height, the speed scale.
const WindLegend = L.Control.extend({
  options: { position: "bottomright" },
  onAdd() {
    this.title = el("div", { class: "wind-legend-title" });
    this.bar = el("canvas", { class: "wind-legend-bar", "aria-hidden": "true" });
    return el("div", { class: "wind-legend", id: "wind-legend" }, this.title, this.bar);
  },
  update(text, units) {
    this.title.textContent = text;
    const dpr = window.devicePixelRatio || 1;
    this.bar.width = LEGEND_W_PX * dpr;
    this.bar.height = LEGEND_H_PX * dpr;
    this.bar.style.width = `${LEGEND_W_PX}px`;
    this.bar.style.height = `${LEGEND_H_PX}px`;
    const g = this.bar.getContext("2d");
    g.setTransform(dpr, 0, 0, dpr, 0, 0);
    const top_mps = WIND_COLOUR_STOPS[WIND_COLOUR_STOPS.length - 1][0];
    const pad = 8, span = LEGEND_W_PX - 2 * pad;
    for (let i = 0; i < span; ++i) {
      g.fillStyle = windColour((i / span) * top_mps);
      g.fillRect(pad + i, 0, 1, LEGEND_BAR_H_PX);
    }
    g.fillStyle = "#c7d3df";
    g.font = "10px system-ui, sans-serif";
    g.textAlign = "center";
    const perMps = units === "ft" ? ktFromMps(1) : 1;
    for (const t of LEGEND_TICKS[units]) {
      const x = pad + (t / perMps / top_mps) * span;
      g.fillRect(Math.round(x), LEGEND_BAR_H_PX, 1, 3);
      g.fillText(String(t), x, LEGEND_H_PX - 3);
    }
    this.getContainer().setAttribute("aria-label",
      `${text}; colour scale 0 to ${fmt(top_mps * perMps)} ${units === "ft" ? "kt" : "m/s"}`);
  },
});

// The wind field at one height over the view: asked for after a move ends,
// every WIND_REFRESH_MS and when the weather changes, at most one request in
// flight; drawn as one SVG arrow per answered point, downwind, coloured and
// lengthened by speed. pane: the Leaflet pane (above the overlay's canvas).
export const WindFieldLayer = L.Layer.extend({
  initialize(pane) {
    L.setOptions(this, { pane });
    this.shown = false;
    this.alt_m = 1500;
    this.units = "m";
    this.answer = null;   // the last answer drawn: GET /api/wind's body and its query
    this.error = null;
    this.drawn = [];      // [{x, y, tail, tip, arrow}] in container px, for picking
    this.loop = new RequestLoop({
      wanted: () => this.shown && !!this._map,
      send: async () => {
        const q = this.query();
        return { q, r: await request("GET", `/api/wind?lat_deg=${q.lat_deg.toFixed(5)}&lon_deg=${q.lon_deg.toFixed(5)}` +
          `&alt_m=${fmt(q.alt_m, 2)}&radius_m=${q.radius_m}`) };
      },
      answered: ({ q, r }) => this.answered(q, r),
      settle_ms: WIND_SETTLE_MS, refresh_ms: WIND_REFRESH_MS, pauseHidden: true,
    });
  },
  onAdd(map) {
    this.svg = L.SVG.create("svg");
    this.svg.setAttribute("class", "wind-field leaflet-zoom-hide");
    this.getPane().appendChild(this.svg);
    this.legend = new WindLegend();
    map.on("moveend zoomend resize viewreset", this.moved, this);
    this.loop.start();
    this.redraw();
  },
  onRemove(map) {
    L.DomUtil.remove(this.svg);
    if (this.shown) this.legend.remove();
    map.off("moveend zoomend resize viewreset", this.moved, this);
    this.loop.stop();
  },

  // Shows or hides the field; alt_m (MSL, WIND_ALT_LIMITS_M) and units ("m"
  // or "ft") for what is asked next and how the legend reads.
  set({ shown = this.shown, alt_m = this.alt_m, units = this.units }) {
    const ask = shown && (!this.shown || alt_m !== this.alt_m);
    if (shown !== this.shown && this._map) shown ? this.legend.addTo(this._map) : this.legend.remove();
    Object.assign(this, { shown, alt_m, units });
    if (!shown) {
      this.answer = null;
      this.error = null;
      this.loop.cancel();
    }
    if (ask) this.loop.ask();
    this.redraw();
  },

  // The weather changed (a state message): ask again.
  weatherChanged() {
    this.loop.ask();
  },

  moved() {
    this.redraw();
    this.loop.moved();
  },

  // The cap that covers the view: its centre, and the distance to its
  // farthest corner or edge (the API's bounds).
  query() {
    const map = this._map, size = map.getSize(), c = map.getCenter();
    const lat_deg = Math.max(-90, Math.min(90, c.lat)), lon_deg = normalizeLon(c.lng);
    let far_m = 0;
    for (const [fx, fy] of [[0, 0], [0.5, 0], [1, 0], [0, 0.5], [1, 0.5], [0, 1], [0.5, 1], [1, 1]]) {
      const p = map.containerPointToLatLng([fx * size.x, fy * size.y]);
      far_m = Math.max(far_m, inverse(lat_deg, lon_deg, p.lat, p.lng).distance_m);
    }
    const radius_m = Math.round(Math.max(WIND_RADIUS_LIMITS_M[0], Math.min(WIND_RADIUS_LIMITS_M[1], far_m * WIND_RADIUS_MARGIN)));
    return { lat_deg, lon_deg, alt_m: this.alt_m, radius_m, capped: far_m * WIND_RADIUS_MARGIN > WIND_RADIUS_LIMITS_M[1] };
  },

  // GET /api/wind's answer to the query q: drawn, or why not in the legend.
  answered(q, r) {
    if (r.ok && r.body && Array.isArray(r.body.arrows)) {
      this.answer = { ...r.body, query: q };
      this.error = null;
    } else {
      this.error = r.status === 404 ? "this server has no wind field (GET /api/wind: 404)"
        : `wind field not loaded: ${(r.body && r.body.error) || `HTTP ${r.status}`}`;
    }
    this.redraw();
  },

  redraw() {
    if (!this._map) return;
    const map = this._map, size = map.getSize();
    L.DomUtil.setPosition(this.svg, map.containerPointToLayerPoint([0, 0]));
    this.svg.setAttribute("width", size.x);
    this.svg.setAttribute("height", size.y);
    this.svg.setAttribute("viewBox", `0 0 ${size.x} ${size.y}`);
    this.svg.replaceChildren();
    this.drawn = [];
    const a = this.shown ? this.answer : null;
    this.svg.dataset.altM = a ? String(a.alt_m) : "";
    this.svg.dataset.count = a ? String(a.arrows.length) : "0";
    if (this.shown) this.legend.update(this.legendText(), this.units);
    if (!a) return;
    // Arrows' spacing on the screen: the cap's area shared by its points, in
    // CSS px at the view's centre.
    const c = map.getCenter(), east = map.containerPointToLatLng(map.latLngToContainerPoint(c).add([100, 0]));
    const mpp = inverse(c.lat, c.lng, east.lat, east.lng).distance_m / 100;
    const spacing_px = Math.sqrt((Math.PI * a.query.radius_m ** 2) / Math.max(1, a.arrows.length)) / mpp;
    const full_px = Math.max(WIND_ARROW_MIN_PX, Math.min(WIND_ARROW_MAX_PX, WIND_ARROW_FILL * spacing_px));
    const ref = c.lng;
    for (const arrow of a.arrows) {
      const p = map.latLngToContainerPoint([arrow.lat_deg, ref + normalizeLon(arrow.lon_deg - ref)]);
      if (p.x < -full_px || p.y < -full_px || p.x > size.x + full_px || p.y > size.y + full_px) continue;
      const path = L.SVG.create("path");
      const colour = windColour(arrow.speed_mps);
      path.setAttribute("stroke", colour);
      path.dataset.lat = String(arrow.lat_deg);
      path.dataset.lon = String(arrow.lon_deg);
      if (arrow.speed_mps < CALM_MPS) {
        path.setAttribute("class", "wind-arrow wind-calm");
        path.setAttribute("d", `M${p.x - 2} ${p.y}a2 2 0 1 0 4 0a2 2 0 1 0 -4 0`);
        this.drawn.push({ x: p.x, y: p.y, tail: p, tip: p, arrow });
      } else {
        const len = full_px * (0.5 + 0.5 * Math.min(1, arrow.speed_mps / WIND_FULL_LENGTH_MPS));
        const g = arrowGeometry(p.x, p.y, arrow.from_deg + 180, len);
        const xy = (q) => `${q.x.toFixed(2)} ${q.y.toFixed(2)}`;
        path.setAttribute("class", "wind-arrow");
        path.setAttribute("fill", colour);
        path.setAttribute("d", `M${xy(g.tail)}L${xy(g.tip)}M${xy(g.tip)}L${xy(g.left)}L${xy(g.right)}Z`);
        this.drawn.push({ x: p.x, y: p.y, tail: g.tail, tip: g.tip, arrow });
      }
      this.svg.append(path);
    }
  },

  legendText() {
    if (this.error) return this.error;
    const a = this.answer;
    if (!a) return `wind at ${heightText(this.alt_m, this.units)}: asking…`;
    return `wind at ${heightText(a.alt_m, this.units)} MSL, ${this.units === "ft" ? "kt" : "m/s"}` +
      (a.query.capped ? " (within 2000 km)" : "") + (a.varying_layers.length ? "" : ", uniform per layer");
  },

  // The drawn arrow whose shaft passes within WIND_PICK_PX of a container
  // point, or null.
  pick(pt) {
    let best = null, bestD = WIND_PICK_PX;
    for (const d of this.drawn) {
      const vx = d.tip.x - d.tail.x, vy = d.tip.y - d.tail.y, l2 = vx * vx + vy * vy;
      const t = l2 > 0 ? Math.max(0, Math.min(1, ((pt.x - d.tail.x) * vx + (pt.y - d.tail.y) * vy) / l2)) : 0;
      const dist = Math.hypot(pt.x - (d.tail.x + t * vx), pt.y - (d.tail.y + t * vy));
      if (dist <= bestD) { best = d.arrow; bestD = dist; }
    }
    return best;
  },

  // One arrow in words: speed in both units, where from and where to, vertical.
  describe(arrow) {
    const vertical = arrow.vertical_mps;
    return `${fmt(arrow.speed_mps, 1)} m/s (${fmt(ktFromMps(arrow.speed_mps))} kt) from ${fmt(arrow.from_deg)}°` +
      ` toward ${fmt((arrow.from_deg + 180) % 360)}°, vertical ${vertical > 0 ? "+" : ""}${fmt(vertical, 2)} m/s`;
  },

  // A popup at the arrow: its point, height and wind.
  popup(arrow) {
    const a = this.answer;
    const body = el("div", { class: "station-popup wind-popup" },
      el("b", {}, `Wind at ${fmt(a.alt_m)} m (${fmt(ftFromM(a.alt_m))} ft) MSL`),
      el("div", {}, `${fmt(arrow.lat_deg, 3)}°, ${fmt(arrow.lon_deg, 3)}°`),
      el("div", { class: "wind-popup-value" }, this.describe(arrow)));
    L.popup({ className: "station-popup-wrap", maxWidth: 320 })
      .setLatLng([arrow.lat_deg, this._map.getCenter().lng + normalizeLon(arrow.lon_deg - this._map.getCenter().lng)])
      .setContent(body).openOn(this._map);
  },
});
