// The map's weather overlay: one canvas over the whole view, above the
// ground and under the regions, with the selected layer's coverage as a
// translucent white field, the graticule, and the layer's wind as arrows.
// Redrawn after each move or zoom (hidden while a zoom animates) and when
// the weather changes (MapView.redraw).
import { coverageAt, regionWeight } from "./coverage.js";
import { MERCATOR_MAX_LAT_DEG, normalizeLon } from "./geo.js";
import { fmt } from "./units.js";

const L = window.L;

// Coverage is sampled on a grid this coarse (CSS px) and smoothed up: the
// field varies over kilometres, and 6 px keeps a redraw near 10 ms.
const COVERAGE_CELL_PX = 6;
// Spacing of the wind arrows (CSS px).
const ARROW_SPACING_PX = 90;
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

// data: {state(), selectedLayer()}, as MapView's; pane: the Leaflet pane.
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
    if (state && layerId !== null) this.drawWind(g, w, h, state, layerId);
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
        const len = Math.min(40, 10 + 2 * wind.speed_mps);
        const a = ((wind.from_deg + 180) * Math.PI) / 180;
        const dx = Math.sin(a) * len, dy = -Math.cos(a) * len;
        g.beginPath();
        g.moveTo(x - dx / 2, y - dy / 2);
        g.lineTo(x + dx / 2, y + dy / 2);
        g.stroke();
        const hx = x + dx / 2, hy = y + dy / 2, ha = Math.atan2(dy, dx);
        g.beginPath();
        g.moveTo(hx, hy);
        g.lineTo(hx - 7 * Math.cos(ha - 0.4), hy - 7 * Math.sin(ha - 0.4));
        g.lineTo(hx - 7 * Math.cos(ha + 0.4), hy - 7 * Math.sin(ha + 0.4));
        g.closePath();
        g.fill();
      }
    }
    g.restore();
  },
});
