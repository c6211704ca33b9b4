// The console's map: a canvas drawn here, no tiles. An azimuthal equidistant
// view about a focus point (north up at the focus) with a graticule, the
// selected layer's coverage as a translucent overlay, its wind as arrows,
// every region's edge and transition perimeter, the region tool's draft with
// its handles, and each connected renderer as an aircraft at its camera
// position and heading. Drag pans, the wheel zooms; in a placing mode a click
// (or a drag, for its size) puts a storm cell or a clearing there.
import { coverageAt, regionEdgeDistance_m, regionOutline, regionPoint, regionWeight } from "./coverage.js";
import { direct, Projection } from "./geo.js";
import { fmt, ftFromM } from "./units.js";

// Coverage is sampled on a grid this coarse (CSS px) and smoothed up: the
// field varies over kilometres, and 6 px keeps a redraw near 10 ms.
const COVERAGE_CELL_PX = 6;
// Spacing of the wind arrows (CSS px).
const ARROW_SPACING_PX = 90;
// Zoom limits (metres per CSS pixel): 5 m/px shows a few km, 20 km/px a hemisphere.
const MIN_SCALE_MPP = 5, MAX_SCALE_MPP = 20000;
// A press that moves less than this is a click, not a drag (CSS px).
const CLICK_SLOP_PX = 4;
// Handles are grabbed within this distance (CSS px).
const HANDLE_GRAB_PX = 9;
// A renderer whose last report is older than this is drawn as stale.
const STALE_AFTER_S = 5;
// Least distance between two longitude labels (CSS px): "12.45°" is ~40 px wide.
const LABEL_GAP_PX = 56;
// Graticule spacings to choose from (degrees).
const GRID_STEPS_DEG = [0.01, 0.02, 0.05, 0.1, 0.2, 0.25, 0.5, 1, 2, 5, 10, 15, 30];

export class MapView {
  // data: {state(), renderers(), draft(), selectedLayer(), selectedRegion(), canEdit()}
  // on: {place(kind, lat, lon, half_m), placed(), reshape(shape), pick(regionId), cursor(text),
  //      view(focus, scale)}
  constructor(canvas, data, on) {
    Object.assign(this, { canvas, data, on });
    this.ctx = canvas.getContext("2d");
    this.focus = { lat_deg: 46.0, lon_deg: 13.0 };
    this.scale_mpp = 250;
    this.mode = "pan";  // "pan", "storm", "clearing"
    this.proj = new Projection(this.focus.lat_deg, this.focus.lon_deg);
    this.coverageKey = null;
    this.coverageCanvas = document.createElement("canvas");
    this.dirty = true;
    this.drag = null;
    new ResizeObserver(() => this.resize()).observe(canvas);
    canvas.addEventListener("pointerdown", (e) => this.pointerDown(e));
    canvas.addEventListener("pointermove", (e) => this.pointerMove(e));
    canvas.addEventListener("pointerup", (e) => this.pointerUp(e));
    canvas.addEventListener("pointercancel", () => { this.drag = null; });
    canvas.addEventListener("pointerleave", () => this.on.cursor(""));
    canvas.addEventListener("wheel", (e) => this.wheel(e), { passive: false });
    this.resize();
    const frame = () => {
      if (this.dirty) this.draw();
      requestAnimationFrame(frame);
    };
    requestAnimationFrame(frame);
  }

  redraw() { this.dirty = true; }

  setView(lat_deg, lon_deg, scale_mpp = this.scale_mpp) {
    this.focus = { lat_deg: Math.max(-89.9, Math.min(89.9, lat_deg)), lon_deg };
    this.scale_mpp = Math.max(MIN_SCALE_MPP, Math.min(MAX_SCALE_MPP, scale_mpp));
    this.proj = new Projection(this.focus.lat_deg, this.focus.lon_deg);
    this.on.view(this.focus, this.scale_mpp);
    this.redraw();
  }

  setMode(mode) {
    this.mode = mode;
    this.canvas.dataset.mode = mode;
    this.redraw();
  }

  resize() {
    const r = this.canvas.getBoundingClientRect();
    this.w = Math.max(1, r.width);
    this.h = Math.max(1, r.height);
    const dpr = window.devicePixelRatio || 1;
    this.canvas.width = Math.round(this.w * dpr);
    this.canvas.height = Math.round(this.h * dpr);
    this.ctx.setTransform(dpr, 0, 0, dpr, 0, 0);
    this.coverageKey = null;
    this.redraw();
  }

  // Screen (CSS px from the canvas's top left) <-> surface.
  toScreen(lat_deg, lon_deg) {
    const { x_m, y_m } = this.proj.forward(lat_deg, lon_deg);
    return { x: this.w / 2 + x_m / this.scale_mpp, y: this.h / 2 - y_m / this.scale_mpp };
  }
  toSurface(x, y) {
    return this.proj.inverse((x - this.w / 2) * this.scale_mpp, (this.h / 2 - y) * this.scale_mpp);
  }
  eventPoint(e) {
    const r = this.canvas.getBoundingClientRect();
    return { x: e.clientX - r.left, y: e.clientY - r.top };
  }

  // ---- interaction ----

  handles() {
    const d = this.data.draft();
    if (!d || !(d.size_x_m > 0) || !this.data.canEdit()) return [];
    const edge = regionPoint(d, d.size_x_m / 2, 0);
    const outer = regionPoint(d, d.size_x_m / 2 + Math.max(0, d.transition_m || 0), 0);
    return [
      { kind: "size", ...this.toScreen(edge.lat_deg, edge.lon_deg) },
      { kind: "transition", ...this.toScreen(outer.lat_deg, outer.lon_deg) },
    ];
  }

  pointerDown(e) {
    const p = this.eventPoint(e);
    this.canvas.setPointerCapture(e.pointerId);
    const handle = this.handles().find((h) => Math.hypot(h.x - p.x, h.y - p.y) <= HANDLE_GRAB_PX);
    if (handle) {
      this.drag = { kind: handle.kind, start: p, region: this.data.draft() };
    } else if ((this.mode === "storm" || this.mode === "clearing") && this.data.canEdit()) {
      this.drag = { kind: "place", start: p, centre: this.toSurface(p.x, p.y) };
    } else {
      this.drag = { kind: "pan", start: p, focus: { ...this.focus }, moved: false };
    }
  }

  pointerMove(e) {
    const p = this.eventPoint(e);
    const s = this.toSurface(p.x, p.y);
    this.on.cursor(`${fmt(s.lat_deg, 4)}°, ${fmt(s.lon_deg, 4)}°`);
    this.canvas.style.cursor = this.handles().some((h) => Math.hypot(h.x - p.x, h.y - p.y) <= HANDLE_GRAB_PX) ? "grab" : "";
    const d = this.drag;
    if (!d) return;
    const moved = Math.hypot(p.x - d.start.x, p.y - d.start.y) > CLICK_SLOP_PX;
    if (d.kind === "pan") {
      if (!moved && !d.moved) return;
      d.moved = true;
      // Keep the surface point under the press under the pointer.
      const start = new Projection(d.focus.lat_deg, d.focus.lon_deg);
      const c = start.inverse((d.start.x - p.x) * this.scale_mpp, (p.y - d.start.y) * this.scale_mpp);
      this.setView(c.lat_deg, c.lon_deg);
    } else if (d.kind === "place") {
      if (!moved) return;
      d.dragged = true;
      const half_m = Math.hypot(p.x - d.start.x, p.y - d.start.y) * this.scale_mpp;
      this.on.place(this.mode, d.centre.lat_deg, d.centre.lon_deg, half_m);
    } else {
      // A handle: its distance from the region's centre, along the region's x axis.
      const r = d.region;
      const c = this.toScreen(r.center_lat_deg, r.center_lon_deg);
      const dist_m = Math.hypot(p.x - c.x, p.y - c.y) * this.scale_mpp;
      if (d.kind === "size") {
        const half = Math.max(50, dist_m);
        const k = half / (r.size_x_m / 2);
        this.on.reshape({ size_x_m: r.size_x_m * k, size_y_m: r.size_y_m * k, corner_radius_m: (r.corner_radius_m || 0) * k });
      } else {
        this.on.reshape({ transition_m: Math.max(0, dist_m - r.size_x_m / 2) });
      }
    }
  }

  pointerUp(e) {
    const d = this.drag;
    this.drag = null;
    if (!d) return;
    const p = this.eventPoint(e);
    if (d.kind === "place") {
      if (!d.dragged) this.on.place(this.mode, d.centre.lat_deg, d.centre.lon_deg, null);
      this.on.placed();
    } else if (d.kind === "pan" && !d.moved) {
      // A click: pick the region under it (innermost first).
      const s = this.toSurface(p.x, p.y);
      const hit = this.data.state().regions
        .map((r) => ({ r, d: regionEdgeDistance_m(r, s.lat_deg, s.lon_deg) }))
        .filter((x) => x.d <= 0).sort((a, b) => a.d - b.d)[0];
      if (hit) this.on.pick(hit.r.id);
    }
  }

  wheel(e) {
    e.preventDefault();
    const p = this.eventPoint(e);
    const before = this.toSurface(p.x, p.y);
    const k = Math.exp(Math.max(-1, Math.min(1, e.deltaY / 300)));
    this.scale_mpp = Math.max(MIN_SCALE_MPP, Math.min(MAX_SCALE_MPP, this.scale_mpp * k));
    // Keep the point under the pointer where it was.
    const proj = new Projection(before.lat_deg, before.lon_deg);
    const c = proj.inverse(-(p.x - this.w / 2) * this.scale_mpp, (p.y - this.h / 2) * this.scale_mpp);
    this.setView(c.lat_deg, c.lon_deg);
  }

  // ---- drawing ----

  draw() {
    this.dirty = false;
    const g = this.ctx;
    g.clearRect(0, 0, this.w, this.h);
    g.fillStyle = "#1b2a3a";
    g.fillRect(0, 0, this.w, this.h);
    const state = this.data.state();
    const layerId = this.data.selectedLayer();
    if (state && layerId !== null) this.drawCoverage(state, layerId);
    this.drawGraticule();
    if (state) {
      this.drawRegions(state);
      if (layerId !== null) this.drawWind(state, layerId);
    }
    this.drawDraft();
    this.drawRenderers(this.data.renderers() || []);
    this.drawFocusAndScale();
  }

  drawCoverage(state, layerId) {
    const cols = Math.ceil(this.w / COVERAGE_CELL_PX), rows = Math.ceil(this.h / COVERAGE_CELL_PX);
    const key = JSON.stringify([state.layers, state.regions, layerId, this.focus, this.scale_mpp, cols, rows]);
    if (key !== this.coverageKey) {
      this.coverageKey = key;
      const c = this.coverageCanvas;
      c.width = cols;
      c.height = rows;
      const cg = c.getContext("2d");
      const img = cg.createImageData(cols, rows);
      for (let j = 0; j < rows; ++j) {
        for (let i = 0; i < cols; ++i) {
          const s = this.toSurface((i + 0.5) * COVERAGE_CELL_PX, (j + 0.5) * COVERAGE_CELL_PX);
          const v = coverageAt(state, layerId, s.lat_deg, s.lon_deg);
          const o = 4 * (j * cols + i);
          // White cloud over the dark ground, opacity with coverage.
          img.data[o] = 236; img.data[o + 1] = 242; img.data[o + 2] = 250;
          img.data[o + 3] = Math.round(200 * Math.max(0, Math.min(1, v)));
        }
      }
      cg.putImageData(img, 0, 0);
    }
    const g = this.ctx;
    g.imageSmoothingEnabled = true;
    g.drawImage(this.coverageCanvas, 0, 0, cols * COVERAGE_CELL_PX, rows * COVERAGE_CELL_PX);
  }

  // The visible extent in degrees, from the corners and edge midpoints.
  extent() {
    const pts = [];
    for (const fx of [0, 0.5, 1]) for (const fy of [0, 0.5, 1]) pts.push(this.toSurface(fx * this.w, fy * this.h));
    const lats = pts.map((p) => p.lat_deg);
    // Longitudes relative to the focus, so the antimeridian does not wrap.
    const dl = pts.map((p) => ((p.lon_deg - this.focus.lon_deg + 540) % 360) - 180);
    return { latMin: Math.min(...lats), latMax: Math.max(...lats), dlMin: Math.min(...dl), dlMax: Math.max(...dl) };
  }

  drawGraticule() {
    const g = this.ctx;
    const e = this.extent();
    const span = Math.max(e.latMax - e.latMin, 0.001);
    const step = GRID_STEPS_DEG.find((s) => span / s <= 8) || 30;
    const latStart = Math.ceil(Math.max(-90, e.latMin - step) / step) * step;
    const lonMin = this.focus.lon_deg + e.dlMin, lonMax = this.focus.lon_deg + e.dlMax;
    const lonStep = step;
    g.save();
    g.strokeStyle = "rgba(150, 180, 210, 0.35)";
    g.fillStyle = "rgba(190, 210, 230, 0.8)";
    g.lineWidth = 1;
    g.font = "11px system-ui, sans-serif";
    const n = 48;
    for (let lat = latStart; lat <= Math.min(90, e.latMax + step); lat += step) {
      g.beginPath();
      for (let k = 0; k <= n; ++k) {
        const p = this.toScreen(lat, lonMin - lonStep + ((lonMax - lonMin + 2 * lonStep) * k) / n);
        k ? g.lineTo(p.x, p.y) : g.moveTo(p.x, p.y);
      }
      g.stroke();
      const l = this.toScreen(lat, this.toSurface(4, this.h / 2).lon_deg);
      if (l.y > 12 && l.y < this.h - 4) g.fillText(`${fmt(lat, 2)}°`, 4, l.y - 3);
    }
    const lonStart = Math.ceil((lonMin - lonStep) / lonStep) * lonStep;
    let lastLabel_px = -Infinity;  // labels closer than LABEL_GAP_PX are left out
    for (let lon = lonStart; lon <= lonMax + lonStep; lon += lonStep) {
      g.beginPath();
      for (let k = 0; k <= n; ++k) {
        const p = this.toScreen(e.latMin - step + ((e.latMax - e.latMin + 2 * step) * k) / n, lon);
        k ? g.lineTo(p.x, p.y) : g.moveTo(p.x, p.y);
      }
      g.stroke();
      const b = this.toScreen(this.toSurface(this.w / 2, this.h - 4).lat_deg, lon);
      const shown = ((lon + 540) % 360) - 180;
      if (b.x > 30 && b.x < this.w - 30 && b.x - lastLabel_px >= LABEL_GAP_PX) {
        g.fillText(`${fmt(shown, 2)}°`, b.x + 3, this.h - 6);
        lastLabel_px = b.x;
      }
    }
    g.restore();
  }

  path(points) {
    const g = this.ctx;
    g.beginPath();
    points.forEach((pt, k) => {
      const p = this.toScreen(pt.lat_deg, pt.lon_deg);
      k ? g.lineTo(p.x, p.y) : g.moveTo(p.x, p.y);
    });
    g.closePath();
  }

  drawRegionShape(r, colour, selected) {
    const g = this.ctx;
    g.save();
    g.strokeStyle = colour;
    g.lineWidth = selected ? 2.5 : 1.5;
    this.path(regionOutline(r, 0));
    g.stroke();
    if (r.transition_m > 0) {
      g.setLineDash([6, 5]);
      g.lineWidth = 1;
      this.path(regionOutline(r, r.transition_m));
      g.stroke();
    }
    g.restore();
  }

  drawRegions(state) {
    const g = this.ctx;
    const selected = this.data.selectedRegion();
    for (const r of state.regions) {
      const clearing = r.layers.length > 0 && r.layers.every((l) => l.coverage === 0);
      const colour = clearing ? "#7fd1ff" : "#ffb347";
      this.drawRegionShape(r, colour, r.id === selected);
      const c = this.toScreen(r.center_lat_deg, r.center_lon_deg);
      g.fillStyle = colour;
      g.font = "12px system-ui, sans-serif";
      g.fillText(`R${r.id}${r.drifts_with_wind ? " ↝" : ""}`, c.x + 4, c.y - 4);
    }
  }

  drawDraft() {
    const d = this.data.draft();
    if (!d || !(d.size_x_m > 0) || !(d.size_y_m > 0) || !Number.isFinite(d.center_lat_deg)) return;
    const g = this.ctx;
    g.save();
    g.fillStyle = "rgba(255, 120, 60, 0.12)";
    this.path(regionOutline(d, 0));
    g.fill();
    this.drawRegionShape(d, "#ff7a3c", true);
    for (const h of this.handles()) {
      g.beginPath();
      g.arc(h.x, h.y, 6, 0, 2 * Math.PI);
      g.fillStyle = h.kind === "size" ? "#ff7a3c" : "#ffd27f";
      g.fill();
      g.strokeStyle = "#1b2a3a";
      g.stroke();
    }
    g.restore();
  }

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
    const g = state.layers.find((x) => x.id === layerId);
    return g ? g.wind : null;
  }

  drawWind(state, layerId) {
    const g = this.ctx;
    g.save();
    g.strokeStyle = "rgba(120, 230, 160, 0.85)";
    g.fillStyle = g.strokeStyle;
    g.lineWidth = 1.5;
    for (let y = ARROW_SPACING_PX / 2; y < this.h; y += ARROW_SPACING_PX) {
      for (let x = ARROW_SPACING_PX / 2; x < this.w; x += ARROW_SPACING_PX) {
        const s = this.toSurface(x, y);
        const w = this.windAt(state, layerId, s.lat_deg, s.lon_deg);
        if (!w || w.speed_mps <= 0) continue;
        // Arrows point downwind (the wind blows from from_deg); length grows
        // with speed, 2 px per m/s from 10 px, at most 40.
        const len = Math.min(40, 10 + 2 * w.speed_mps);
        const a = ((w.from_deg + 180) * Math.PI) / 180;
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
  }

  drawRenderers(renderers) {
    const g = this.ctx;
    // Each renderer's area of interest (the spherical cap it subscribed).
    g.save();
    g.strokeStyle = "rgba(255, 225, 77, 0.35)";
    g.setLineDash([2, 4]);
    for (const r of renderers) {
      const a = r.area;
      if (!a || !(a.radius_m > 0) || !Number.isFinite(a.center_lat_deg)) continue;
      const ring = [];
      for (let k = 0; k < 72; ++k) ring.push(direct(a.center_lat_deg, a.center_lon_deg, k * 5, a.radius_m));
      this.path(ring);
      g.stroke();
    }
    g.restore();
    for (const r of renderers) {
      if (r.lat_deg === null || r.lon_deg === null || r.lat_deg === undefined) continue;
      const p = this.toScreen(r.lat_deg, r.lon_deg);
      if (p.x < -20 || p.y < -20 || p.x > this.w + 20 || p.y > this.h + 20) continue;
      const stale = r.last_report_age_s !== null && r.last_report_age_s > STALE_AFTER_S;
      g.save();
      g.translate(p.x, p.y);
      // Heading is true, clockwise from north; the map's north is up at the
      // focus (close enough for a symbol anywhere in view).
      g.rotate(((r.heading_deg || 0) * Math.PI) / 180);
      g.fillStyle = stale ? "#8a94a0" : "#ffe14d";
      g.strokeStyle = "#1b2a3a";
      g.lineWidth = 1;
      g.beginPath();
      // A small aircraft, nose up: fuselage, wings, tail.
      g.moveTo(0, -11); g.lineTo(2, -4); g.lineTo(11, 1); g.lineTo(11, 3); g.lineTo(2, 1); g.lineTo(1.5, 7);
      g.lineTo(5, 10); g.lineTo(5, 11.5); g.lineTo(0, 10); g.lineTo(-5, 11.5); g.lineTo(-5, 10); g.lineTo(-1.5, 7);
      g.lineTo(-2, 1); g.lineTo(-11, 3); g.lineTo(-11, 1); g.lineTo(-2, -4); g.closePath();
      g.fill();
      g.stroke();
      g.restore();
      g.fillStyle = stale ? "#8a94a0" : "#ffe14d";
      g.font = "11px system-ui, sans-serif";
      const alt = r.alt_m === null || r.alt_m === undefined ? "" : ` ${fmt(ftFromM(r.alt_m))} ft`;
      g.fillText(`${r.channel || r.id}${alt}${stale ? " (stale)" : ""}`, p.x + 13, p.y + 4);
    }
  }

  drawFocusAndScale() {
    const g = this.ctx;
    g.save();
    // Focus cross.
    g.strokeStyle = "rgba(255,255,255,0.5)";
    g.beginPath();
    g.moveTo(this.w / 2 - 6, this.h / 2); g.lineTo(this.w / 2 + 6, this.h / 2);
    g.moveTo(this.w / 2, this.h / 2 - 6); g.lineTo(this.w / 2, this.h / 2 + 6);
    g.stroke();
    // Scale bar: the round length nearest 120 px.
    const target_m = 120 * this.scale_mpp;
    const pow = 10 ** Math.floor(Math.log10(target_m));
    const len_m = [1, 2, 5, 10].map((k) => k * pow).reduce((a, b) => (Math.abs(b - target_m) < Math.abs(a - target_m) ? b : a));
    const px = len_m / this.scale_mpp;
    const x0 = 12, y0 = this.h - 26;
    g.strokeStyle = "#e8eef5";
    g.lineWidth = 2;
    g.beginPath();
    g.moveTo(x0, y0 - 4); g.lineTo(x0, y0); g.lineTo(x0 + px, y0); g.lineTo(x0 + px, y0 - 4);
    g.stroke();
    g.fillStyle = "#e8eef5";
    g.font = "11px system-ui, sans-serif";
    g.fillText(len_m >= 1000 ? `${fmt(len_m / 1000)} km (${fmt(len_m / 1852, 1)} NM)` : `${fmt(len_m)} m`, x0 + px + 6, y0);
    // North arrow.
    g.beginPath();
    g.moveTo(this.w - 20, 14); g.lineTo(this.w - 26, 30); g.lineTo(this.w - 20, 26); g.lineTo(this.w - 14, 30);
    g.closePath();
    g.fill();
    g.fillText("N", this.w - 24, 44);
    g.restore();
  }
}
