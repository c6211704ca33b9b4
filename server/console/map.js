// The console's map, on Leaflet (leaflet.js, loaded by index.html as
// window.L): Web Mercator with north up, Natural Earth land, coastlines and
// borders (basemap.js), a graticule and the selected layer's coverage and
// wind on a canvas overlay, the wind field at a height when shown (both
// weather_overlay.js), every region's edge and transition perimeter, the
// region tool's draft with its size and perimeter handles, the METAR
// stations coloured by flight category (stations.js), each connected
// renderer as an aircraft at its camera position and heading, and the recent
// lightning flashes (lightning.js). Leaflet pans
// and zooms; in a placing mode a click (or a press and drag, for its size)
// puts a storm cell or a clearing there.
//
// Longitudes: Leaflet draws a longitude where it is numerically, so every
// shape is given longitudes continuous along it and within 180 degrees of
// the view's centre (a region across the antimeridian is one shape, on the
// side the operator looks at). Latitudes beyond Web Mercator's 85.05 degrees
// are drawn at that edge (Leaflet clamps them), and said so.
import { BaseMap } from "./basemap.js";
import { regionEdgeDistance_m, regionOutline, regionPoint } from "./coverage.js";
import { direct, inverse, MERCATOR_MAX_LAT_DEG, normalizeLon } from "./geo.js";
import { StationLayer } from "./stations.js";
import { fmt, ftFromM } from "./units.js";
import { LightningLayer } from "./lightning.js";
import { RadarLayer } from "./radar.js";
import { WeatherOverlay, WindFieldLayer } from "./weather_overlay.js";

const L = window.L;

// Zoom limits: at 2 the world is 1024 px wide; at 15 a pixel is about 3 m at 46 N.
const MIN_ZOOM = 2, MAX_ZOOM = 15;
// The view holds quarter levels; the keyboard's +/- move by half.
const ZOOM_SNAP = 0.25, ZOOM_DELTA = 0.5;
// Wheel travel per zoom level in Leaflet's formula (its default is 60): a
// wheel notch (100 px in Chromium) zooms by 0.75 levels (measured), not 1.25.
const WHEEL_PX_PER_ZOOM = 120;
// A press that moves less than this is a click, not a drag (CSS px).
const CLICK_SLOP_PX = 4;
// A renderer whose last report is older than this is drawn as stale.
const STALE_AFTER_S = 5;
// Panes above Leaflet's tile pane (200) and below its marker pane (600): the
// ground, then coverage, wind and graticule, then the regions' outlines,
// then lightning flashes (under the aircraft and stations, which are clicked).
const PANES = [["basemap", 250], ["coverage", 350], ["regions", 420], ["flashes", 450]];
// Names of stations and aircraft are shown from this zoom in (about 2.4 km
// per CSS px at 46 N below it: a hundred stations' names would overlap).
const LABELS_FROM_ZOOM = 6;
// The region ids the server gives METAR stations (server/API.md, POST /api/metar).
const METAR_REGION_IDS = [40000, 65535];
// How far inside the map's edge a symbol beyond it is drawn (CSS px): half
// the aircraft symbol.
const EDGE_INSET_PX = 12;
// How far beyond the view regions and areas are drawn (a fraction of the
// view each side): a pan of half the view shows them at once.
const SHAPES_MARGIN = 0.5;
// One nautical mile (m), for the scale bar's second line.
const NAUTICAL_MILE_M = 1852;

// A longitude moved by whole turns to within 180 degrees of `ref_deg`.
const near = (lon_deg, ref_deg) => ref_deg + normalizeLon(lon_deg - ref_deg);

// Points (lat, lon) as Leaflet LatLngs with continuous longitudes, the first
// within 180 degrees of ref_deg.
function continuous(points, ref_deg) {
  let prev = ref_deg;
  return points.map((p) => {
    prev = near(p.lon_deg, prev);
    return L.latLng(p.lat_deg, prev);
  });
}

// The scale bar in kilometres and nautical miles (Leaflet's control, with
// its imperial line reading NM instead of miles).
const NauticalScale = L.Control.Scale.extend({
  _updateImperial(maxMeters) {
    const nm = maxMeters / NAUTICAL_MILE_M;
    const round = this._getRoundNum(nm);
    this._updateScale(this._iScale, `${round} NM`, round / nm);
  },
});

// The aircraft symbol, nose up (24 x 24 px): fuselage, wings, tail.
const AIRCRAFT_PATH = "M12 1 L14 8 L23 13 L23 15 L14 13 L13.5 19 L17 22 L17 23.5 L12 22 L7 23.5 L7 22 L10.5 19 " +
  "L10 13 L1 15 L1 13 L10 8 Z";

function aircraftElement() {
  const root = document.createElement("div");
  root.className = "aircraft";
  const svg = document.createElementNS("http://www.w3.org/2000/svg", "svg");
  svg.setAttribute("viewBox", "0 0 24 24");
  svg.setAttribute("width", "24");
  svg.setAttribute("height", "24");
  const path = document.createElementNS("http://www.w3.org/2000/svg", "path");
  path.setAttribute("d", AIRCRAFT_PATH);
  svg.append(path);
  const label = document.createElement("span");
  label.className = "aircraft-label";
  root.append(svg, label);
  return root;
}

export class MapView {
  // container: the map's element. data: {state(), renderers(), draft(),
  // selectedLayer(), selectedRegion(), canEdit(), clockNow()}. on: {place, placed,
  // reshape, pick, cursor, view, basemap}.
  constructor(container, data, on) {
    this.container = container;
    this.data = data;
    this.on = on;
    this.mode = "pan";
    this.focus = { lat_deg: 0, lon_deg: 0 };
    this.zoom = MIN_ZOOM;
    const map = L.map(container, {
      zoomControl: false, worldCopyJump: true, minZoom: MIN_ZOOM, maxZoom: MAX_ZOOM, zoomSnap: ZOOM_SNAP,
      zoomDelta: ZOOM_DELTA, wheelPxPerZoomLevel: WHEEL_PX_PER_ZOOM, boxZoom: false,
      // Nothing outside the world's latitudes: Web Mercator ends at 85.05 degrees.
      maxBounds: [[-90, -1e6], [90, 1e6]], maxBoundsViscosity: 1,
    });
    this.map = map;
    map.attributionControl.setPrefix("Leaflet");
    map.attributionControl.addAttribution("Natural Earth");
    new NauticalScale({ metric: true, imperial: true, position: "bottomleft", maxWidth: 140 }).addTo(map);
    for (const [name, z] of PANES) map.createPane(name).style.zIndex = String(z);
    this.regionRenderer = L.svg({ pane: "regions", padding: SHAPES_MARGIN });
    this.base = new BaseMap(map, "basemap");
    this.base.load().then(() => this.on.basemap(null), (e) => this.on.basemap(String(e.message || e)));
    // The layer's own arrows give way to the wind field while it is shown:
    // one set of arrows on the map at a time.
    this.overlay = new WeatherOverlay({ ...data, layerWind: () => !this.windField.shown }, "coverage").addTo(map);
    this.windField = new WindFieldLayer("coverage").addTo(map);
    this.radar = new RadarLayer("coverage").addTo(map);
    this.lightning = new LightningLayer("flashes", data.clockNow).addTo(map);
    this.regionGroup = L.layerGroup().addTo(map);
    this.draftGroup = L.layerGroup().addTo(map);
    this.rendererGroup = L.layerGroup().addTo(map);
    this.stations = new StationLayer(map);
    this.aircraft = new Map();  // renderer id -> {marker, ring}
    this.handleMarkers = {};    // kind -> L.Marker
    this.regionKey = "";
    this.place = null;
    this.swallowClick = false;
    this.handleDrag = null;
    // The container's size follows the page's layout (panels filling in, a
    // narrower window): Leaflet must know, or its centre is not the middle.
    new ResizeObserver(() => map.invalidateSize({ animate: false })).observe(container);
    map.on("moveend", () => this.moved());
    map.on("mousedown", (e) => this.pressed(e));
    map.on("mousemove", (e) => this.pointerMoved(e));
    map.on("mouseup", (e) => this.released(e));
    map.on("click", (e) => this.clicked(e));
  }

  // Centre (degrees) and zoom; zoom kept when not given.
  setView(lat_deg, lon_deg, zoom = this.map.getZoom()) {
    const lat = Math.max(-MERCATOR_MAX_LAT_DEG, Math.min(MERCATOR_MAX_LAT_DEG, lat_deg));
    this.map.setView([lat, normalizeLon(lon_deg)], Math.max(MIN_ZOOM, Math.min(MAX_ZOOM, zoom)), { animate: false });
    this.moved();
  }

  zoomBy(delta) {
    this.map.setZoom(this.map.getZoom() + delta);
  }

  setMode(mode) {
    this.mode = mode;
    this.container.dataset.mode = mode;
    const placing = mode !== "pan";
    for (const h of [this.map.dragging, this.map.doubleClickZoom]) placing ? h.disable() : h.enable();
  }

  // The wind field: {shown, alt_m, units} (WindFieldLayer.set).
  setWindField(options) {
    this.windField.set(options);
    this.container.classList.toggle("wind-field-shown", this.windField.shown);
    this.overlay.redraw();
  }

  redraw() {
    this.overlay.redraw();
    this.drawRegions();
    this.drawDraft();
    this.drawRenderers(this.data.renderers() || []);
  }

  moved() {
    const c = this.map.getCenter();
    this.focus = { lat_deg: c.lat, lon_deg: normalizeLon(c.lng) };
    this.zoom = this.map.getZoom();
    // Zoomed out, the stations' and aircraft's names would cover the map.
    this.container.classList.toggle("zoomed-out", this.zoom < LABELS_FROM_ZOOM);
    this.on.view(this.focus, this.zoom);
    // Shapes follow the view round the world (see `near`).
    this.drawRegions();
    this.drawDraft();
    this.drawRenderers(this.data.renderers() || []);
    this.stations.follow(c.lng);
  }

  // The view's centre longitude, unwrapped as Leaflet holds it.
  ref() {
    return this.map.getCenter().lng;
  }

  // ---- the pointer ----

  pressed(e) {
    this.swallowClick = false;
    if (this.mode === "pan" || !this.data.canEdit() || this.handleDrag) return;
    this.place = { start: e.containerPoint, centre: e.latlng.wrap(), dragged: false };
  }

  pointerMoved(e) {
    const p = e.latlng.wrap();
    const arrow = this.windField.pick(e.containerPoint);
    this.on.cursor(`${fmt(p.lat, 4)}°, ${fmt(p.lng, 4)}°` + (arrow ? ` · wind ${this.windField.describe(arrow)}` : ""));
    const d = this.place;
    if (!d) return;
    if (!d.dragged && e.containerPoint.distanceTo(d.start) <= CLICK_SLOP_PX) return;
    d.dragged = true;
    const half_m = inverse(d.centre.lat, d.centre.lng, p.lat, p.lng).distance_m;
    this.on.place(this.mode, d.centre.lat, d.centre.lng, half_m);
  }

  released() {
    const d = this.place;
    this.place = null;
    if (!d) return;
    if (!d.dragged) this.on.place(this.mode, d.centre.lat, d.centre.lng, null);
    // The click the browser may fire after this release placed; it picks nothing.
    this.swallowClick = true;
    this.on.placed();
  }

  // A click in pan mode on a wind field's arrow shows its wind; elsewhere it
  // picks the region under it (innermost first).
  clicked(e) {
    if (this.swallowClick) {
      this.swallowClick = false;
      return;
    }
    if (this.mode !== "pan") return;
    const arrow = this.windField.pick(e.containerPoint);
    if (arrow) {
      this.windField.popup(arrow);
      return;
    }
    const s = e.latlng.wrap();
    const state = this.data.state();
    if (!state) return;
    const hit = state.regions
      .map((r) => ({ r, d: regionEdgeDistance_m(r, s.lat, s.lng) }))
      .filter((x) => x.d <= 0).sort((a, b) => a.d - b.d)[0];
    if (hit) this.on.pick(hit.r.id);
  }

  // ---- regions and the draft ----

  // The edge and, when it has one, the dashed transition perimeter of a
  // region, each one polygon (SVG path) with continuous longitudes.
  // kind: "region" (the state's) or "draft" (the region tool's), in the paths' classes.
  // faint: a METAR station's region (thin, half transparent).
  regionShapes(r, colour, selected, kind = "region", extra = {}, faint = false) {
    const c = near(r.center_lon_deg, this.ref());
    const opts = { renderer: this.regionRenderer, interactive: false, color: colour, fill: false, opacity: faint ? 0.45 : 1 };
    const shapes = [L.polygon(continuous(regionOutline(r, 0), c), { ...opts, weight: selected ? 2.5 : faint ? 1 : 1.5,
      className: `${kind}-edge ${kind}-${r.id}`, ...extra })];
    if (r.transition_m > 0) {
      shapes.push(L.polygon(continuous(regionOutline(r, r.transition_m), c), { ...opts, weight: 1, dashArray: "6 5",
        className: `${kind}-perimeter ${kind}-${r.id}` }));
    }
    return shapes;
  }

  drawRegions() {
    const state = this.data.state();
    const regions = state ? state.regions : [];
    const selected = this.data.selectedRegion();
    const key = JSON.stringify([regions, selected, Math.round(this.ref())]);
    if (key === this.regionKey) return;
    this.regionKey = key;
    this.regionGroup.clearLayers();
    for (const r of regions) {
      // A METAR station's region is drawn faint and unlabelled: its marker names it.
      const station = r.id >= METAR_REGION_IDS[0] && r.id <= METAR_REGION_IDS[1];
      const clearing = r.layers.length > 0 && r.layers.every((l) => l.coverage === 0);
      const colour = station ? "#c9a37a" : clearing ? "#7fd1ff" : "#ffb347";
      const shapes = this.regionShapes(r, colour, r.id === selected, "region", {}, station);
      for (const s of shapes) this.regionGroup.addLayer(s);
      if (station) continue;
      const label = document.createElement("span");
      label.textContent = `R${r.id}${r.drifts_with_wind ? " ↝" : ""}`;
      label.className = clearing ? "region-label clearing" : "region-label";
      this.regionGroup.addLayer(L.marker([r.center_lat_deg, near(r.center_lon_deg, this.ref())], {
        interactive: false, keyboard: false,
        icon: L.divIcon({ className: "region-label-icon", html: label, iconSize: null, iconAnchor: [-4, 16] }),
      }));
    }
  }

  drawDraft() {
    this.draftGroup.clearLayers();
    const d = this.data.draft();
    const valid = d && d.size_x_m > 0 && d.size_y_m > 0 && Number.isFinite(d.center_lat_deg) &&
      Number.isFinite(d.center_lon_deg);
    if (valid) {
      for (const s of this.regionShapes(d, "#ff7a3c", true, "draft", { fill: true, fillColor: "#ff783c", fillOpacity: 0.12 }))
        this.draftGroup.addLayer(s);
    }
    this.drawHandles(valid && this.data.canEdit() ? d : null);
  }

  // The draft's handles on its x axis (east at rotation 0): the edge (size)
  // and the perimeter's outer edge (transition). Kept while one is dragged.
  drawHandles(d) {
    for (const kind of ["size", "transition"]) {
      let m = this.handleMarkers[kind];
      if (!d) {
        if (m && !this.handleDrag) { this.map.removeLayer(m); delete this.handleMarkers[kind]; }
        continue;
      }
      const p = kind === "size" ? regionPoint(d, d.size_x_m / 2, 0)
        : regionPoint(d, d.size_x_m / 2 + Math.max(0, d.transition_m || 0), 0);
      const at = L.latLng(p.lat_deg, near(p.lon_deg, near(d.center_lon_deg, this.ref())));
      if (!m) {
        m = L.marker(at, { draggable: true, keyboard: false, zIndexOffset: 2000, title: kind === "size"
          ? "drag to resize" : "drag to set the transition perimeter",
        icon: L.divIcon({ className: `handle handle-${kind}`, iconSize: [12, 12] }) });
        m.on("dragstart", () => { this.handleDrag = { kind, region: this.data.draft() }; });
        m.on("drag", (e) => this.handleDragged(e.target.getLatLng()));
        m.on("dragend", () => { this.handleDrag = null; this.drawDraft(); });
        m.addTo(this.map);
        this.handleMarkers[kind] = m;
      } else if (!this.handleDrag) {
        m.setLatLng(at);
      }
    }
  }

  // A handle's distance from the region's centre sets its size or perimeter.
  handleDragged(latlng) {
    const { kind, region: r } = this.handleDrag;
    const dist_m = inverse(r.center_lat_deg, r.center_lon_deg, latlng.lat, normalizeLon(latlng.lng)).distance_m;
    if (kind === "size") {
      const half = Math.max(50, dist_m);
      const k = half / (r.size_x_m / 2);
      this.on.reshape({ size_x_m: r.size_x_m * k, size_y_m: r.size_y_m * k, corner_radius_m: (r.corner_radius_m || 0) * k });
    } else {
      this.on.reshape({ transition_m: Math.max(0, dist_m - r.size_x_m / 2) });
    }
  }

  // ---- renderers ----

  drawRenderers(renderers) {
    const seen = new Set();
    const ref = this.ref();
    for (const r of renderers) {
      const key = String(r.id);
      seen.add(key);
      let a = this.aircraft.get(key);
      if (!a) {
        const el = aircraftElement();
        a = { el, marker: L.marker([0, 0], { interactive: false, keyboard: false, zIndexOffset: 1000,
          icon: L.divIcon({ className: "aircraft-icon", html: el, iconSize: [24, 24], iconAnchor: [12, 12] }) }),
        ring: null, ringKey: "" };
        this.aircraft.set(key, a);
      }
      this.drawArea(a, r.area, ref);
      const placed = r.lat_deg !== null && r.lat_deg !== undefined && r.lon_deg !== null && r.lon_deg !== undefined;
      if (!placed) {
        if (this.rendererGroup.hasLayer(a.marker)) this.rendererGroup.removeLayer(a.marker);
        continue;
      }
      const stale = r.last_report_age_s !== null && r.last_report_age_s !== undefined && r.last_report_age_s > STALE_AFTER_S;
      a.marker.setLatLng([this.drawnLat(r.lat_deg), near(r.lon_deg, ref)]);
      if (!this.rendererGroup.hasLayer(a.marker)) this.rendererGroup.addLayer(a.marker);
      // Heading is true, clockwise from north; Mercator keeps north up.
      a.el.querySelector("svg").style.transform = `rotate(${r.heading_deg || 0}deg)`;
      a.el.classList.toggle("stale", stale);
      a.el.dataset.id = key;
      a.el.dataset.lat = String(r.lat_deg);
      a.el.dataset.lon = String(r.lon_deg);
      const beyond = Math.abs(r.lat_deg) > MERCATOR_MAX_LAT_DEG;
      const alt = r.alt_m === null || r.alt_m === undefined ? "" : ` ${fmt(ftFromM(r.alt_m))} ft`;
      a.el.querySelector(".aircraft-label").textContent = `${r.channel || r.id}${alt}${stale ? " (stale)" : ""}` +
        (beyond ? ` at ${fmt(Math.abs(r.lat_deg), 2)}°${r.lat_deg > 0 ? "N" : "S"}, beyond the map's edge` : "");
      a.el.classList.toggle("beyond-edge", beyond);
    }
    for (const [key, a] of this.aircraft) {
      if (seen.has(key)) continue;
      this.rendererGroup.removeLayer(a.marker);
      if (a.ring) this.rendererGroup.removeLayer(a.ring);
      this.aircraft.delete(key);
    }
  }

  // The latitude a symbol is drawn at: its own, or for one beyond Web
  // Mercator's edge (over a pole), just inside the edge, so it stays whole.
  drawnLat(lat_deg) {
    if (Math.abs(lat_deg) <= MERCATOR_MAX_LAT_DEG) return lat_deg;
    const zoom = this.map.getZoom(), sign = Math.sign(lat_deg);
    const edge = this.map.project([sign * MERCATOR_MAX_LAT_DEG, 0], zoom);
    return this.map.unproject(edge.add([0, sign * EDGE_INSET_PX]), zoom).lat;
  }

  // A renderer's area of interest (the spherical cap it subscribed), dashed.
  drawArea(a, area, ref) {
    const ok = area && area.radius_m > 0 && Number.isFinite(area.center_lat_deg) && Number.isFinite(area.center_lon_deg);
    const key = ok ? JSON.stringify([area, Math.round(ref)]) : "";
    if (key === a.ringKey) return;
    a.ringKey = key;
    if (a.ring) this.rendererGroup.removeLayer(a.ring);
    a.ring = null;
    if (!ok) return;
    const ring = [];
    for (let k = 0; k <= 72; ++k) ring.push(direct(area.center_lat_deg, area.center_lon_deg, k * 5, area.radius_m));
    a.ring = L.polyline(continuous(ring, near(area.center_lon_deg, ref)), { renderer: this.regionRenderer,
      interactive: false, color: "#ffe14d", opacity: 0.4, weight: 1, dashArray: "2 4", className: "renderer-area" });
    this.rendererGroup.addLayer(a.ring);
  }
}
