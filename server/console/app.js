// The Skyshell operator console: wires the live feed (api.js) to the map and
// the panels, keeps the token for the tab's session, and turns the page
// read-only without it. Served by skyshell-weatherd at / (docs/operating.md, "The
// operator console").
import { LiveLink, postChanges, request, session } from "./api.js";
import { ClockPanel } from "./clock.js";
import { ClusterPanel } from "./cluster.js";
import { layerIds } from "./coverage.js";
import { $, $$, note, showErrors } from "./dom.js";
import { LayerPanel } from "./layers.js";
import { LightningPanel } from "./lightning.js";
import { EventLog, renderHealth, renderRenderers } from "./log.js";
import { MapView } from "./map.js";
import { MetarPanel } from "./metar.js";
import { ConformancePanel } from "./conformance.js";
import { RegionPanel } from "./regions.js";
import { fmt, ftFromM, keyOfServerError, mFromFt, num } from "./units.js";
import { WIND_ALT_LIMITS_M } from "./weather_overlay.js";

const VIEW_KEY = "skyshell.view";
// The wind field's units ("m": m and m/s, "ft": ft and kt), kept per browser.
const UNITS_KEY = "skyshell.units";
// The wind field's height until the operator (or the URL) says otherwise:
// 1500 m MSL, near the bundled scenario's cumulus base.
const DEFAULT_WIND_ALT_M = 1500;
// Where the map looks before anything says better: the bundled demo's area
// (north-east Italy), Leaflet zoom 8.75 (about 250 m per pixel there).
const DEFAULT_VIEW = { lat_deg: 46.0, lon_deg: 13.0, zoom: 8.75 };
// Web Mercator's metres per pixel at the equator at zoom 0 (2 pi 6378137 m /
// 256 px): turns an old "scale" (m per px at the focus) into a zoom.
const MERCATOR_MPP_AT_ZOOM0 = 156543.03392804097;

const app = {
  stateValue: null,
  stateAt_ms: 0,
  renderersValue: [],
  overlayLayer: null,
  selectedRegion: null,
  viewChosen: false,  // the operator (or the URL) chose the view: no auto focus

  state() { return this.stateValue || { layers: [], regions: [], pending: [], clock_s: 0, clock_rate: 0, sequence: 0 }; },
  // The weather clock now, from the last state and its rate.
  clockNow() {
    const s = this.stateValue;
    if (!s) return 0;
    return s.clock_s + (s.clock_rate * (performance.now() - this.stateAt_ms)) / 1000;
  },
  canEdit() { return session.token() !== ""; },
  allLayerIds() { return layerIds(this.state()); },
  redraw() { map.redraw(); },
  stationsChanged() { refreshStations(); },
  onSelect(id) { setOverlay(id); },
  tokenRefused() {
    session.setToken("");
    updateEditable();
  },
  changed() { link.refreshState(); refreshStations(); },

  // Sends one batch. The server applies all of it or none; a refusal lands
  // next to the field it names (keys: API key -> the form's field).
  async submit(changes, form, keys, noteEl) {
    if (!this.canEdit()) {
      note(noteEl, "read-only: enter the token first", "bad");
      return { ok: false };
    }
    note(noteEl, "applying…", "busy");
    const r = await postChanges(changes);
    if (r.ok) {
      showErrors(form, {});
      note(noteEl, `applied #${r.body.sequence} at clock ${fmt(r.body.clock_s)} s: ${r.body.summary}`, "ok");
      link.refreshState();
      return r;
    }
    if (r.status === 401) {
      this.tokenRefused();
      note(noteEl, "the server refused the token: read-only now; nothing applied", "bad");
      return r;
    }
    if (r.status === 0) {
      note(noteEl, `${r.body.error}: nothing applied`, "bad");
      return r;
    }
    const { key, layerIndex } = keyOfServerError(r.body);
    const field = layerIndex !== null && keys.layers ? "layers" : keys[key] || "form";
    showErrors(form, { [field]: r.body.error || `HTTP ${r.status}` });
    note(noteEl, "refused by the server: nothing applied", "bad");
    return r;
  },
};

const map = new MapView($("#map"), {
  state: () => app.stateValue,
  renderers: () => app.renderersValue,
  draft: () => regions.draft(),
  selectedLayer: () => app.overlayLayer,
  selectedRegion: () => regions.selectedId,
  canEdit: () => app.canEdit(),
  clockNow: () => app.clockNow(),
}, {
  place: (kind, lat, lon, half_m) => regions.place(kind, lat, lon, half_m),
  placed: () => setMode("pan"),
  reshape: (shape) => regions.reshape(shape),
  pick: (id) => regions.edit(id),
  cursor: (text) => { $("#map-cursor").textContent = text; },
  view: (focus, zoom) => {
    $('[name="focus_lat"]').value = fmt(focus.lat_deg, 4);
    $('[name="focus_lon"]').value = fmt(focus.lon_deg, 4);
    $("#map").dataset.focus = `${focus.lat_deg},${focus.lon_deg}`;
    $("#map").dataset.zoom = String(zoom);
    saveView();
  },
  // The Natural Earth ground loaded (null) or not (why).
  basemap: (error) => {
    $("#map").dataset.basemap = error ? "failed" : "loaded";
    if (error) $("#map-hint").textContent = `coastlines not loaded: ${error}`;
  },
});

const layers = new LayerPanel($("#layers"), app);
const regions = new RegionPanel($("#region"), app);
const metar = new MetarPanel($("#metar"), app);
new ConformancePanel($("#conformance"), (stations) => map.stations.conformance(stations));
new ClockPanel($("#clock"), app);
new LightningPanel($("#lightning"), app, () => map.focus, (flash) => map.lightning.add([flash]));
const log = new EventLog($("#events"));

// The view in this browser and in the address (a link shows the same place,
// and the wind field when it is shown: #focus=38,-97&zoom=6&wind_alt_m=6000).
function saveView() {
  clearTimeout(app.saveView);
  app.saveView = setTimeout(() => {
    const { focus, zoom } = map, wind = map.windField;
    localStorage.setItem(VIEW_KEY, JSON.stringify({ lat_deg: focus.lat_deg, lon_deg: focus.lon_deg, zoom,
      wind_alt_m: wind.alt_m, wind_shown: wind.shown }));
    history.replaceState(null, "", `#focus=${fmt(focus.lat_deg, 5)},${fmt(focus.lon_deg, 5)}&zoom=${zoom}` +
      (wind.shown ? `&wind_alt_m=${fmt(wind.alt_m, 1)}` : ""));
  }, 500);
}

// The wind field's controls: the height in the chosen units, checked
// against the server's range next to the field; the field follows a valid one.
function windHeightShown(alt_m, units) {
  $("#wind-height").value = fmt(units === "ft" ? ftFromM(alt_m) : alt_m, units === "ft" ? 0 : 1);
}
function windHeightChanged() {
  const input = $("#wind-height"), units = $("#wind-units").value;
  const v = num(input.value), alt_m = units === "ft" ? mFromFt(v) : v;
  const [lo, hi] = WIND_ALT_LIMITS_M;
  const bad = !Number.isFinite(alt_m) ? "enter a height" : alt_m < lo || alt_m > hi
    ? `the wind field is from ${units === "ft" ? `${fmt(ftFromM(lo))} to ${fmt(ftFromM(hi))} ft` : `${lo} to ${hi} m`} MSL` : "";
  input.title = bad;
  if (bad) {
    input.setAttribute("aria-invalid", "true");
    return;
  }
  input.removeAttribute("aria-invalid");
  map.setWindField({ alt_m });
  saveView();
}

function setOverlay(id) {
  app.overlayLayer = id;
  $("#overlay-layer").value = id === null ? "" : String(id);
  map.redraw();
}

function setMode(mode) {
  map.setMode(mode);
  for (const b of $$("[data-mode]")) b.classList.toggle("active", b.dataset.mode === mode);
  $("#map-hint").textContent = mode === "pan"
    ? "drag to pan, wheel to zoom, click a region to edit it"
    : `click to place a ${mode === "storm" ? "storm cell" : "clearing"}, or press and drag for its size`;
}

function updateOverlayChoices(state) {
  const select = $("#overlay-layer");
  const ids = layerIds(state);
  const key = ids.join(",");
  if (select.dataset.ids !== key) {
    select.dataset.ids = key;
    select.replaceChildren(...ids.map((id) => {
      const l = state.layers.find((x) => x.id === id) ||
        state.regions.flatMap((r) => r.layers).find((x) => x.id === id);
      const o = document.createElement("option");
      o.value = String(id);
      o.textContent = `layer ${id} (${l.type})${state.layers.some((x) => x.id === id) ? "" : ", regional"}`;
      return o;
    }));
  }
  if (app.overlayLayer === null || !ids.includes(app.overlayLayer)) app.overlayLayer = ids.length ? ids[0] : null;
  select.value = app.overlayLayer === null ? "" : String(app.overlayLayer);
}

function autoFocus() {
  if (app.viewChosen) return;
  const r = app.state().regions[0];
  const plane = (app.renderersValue || []).find((x) => x.lat_deg !== null && x.lat_deg !== undefined);
  const target = plane ? { lat: plane.lat_deg, lon: plane.lon_deg } : r ? { lat: r.center_lat_deg, lon: r.center_lon_deg } : null;
  if (!target) return;
  app.viewChosen = true;
  map.setView(target.lat, target.lon);
}

// Read-only without the token: every edit control is disabled and says why.
function updateEditable() {
  const editable = app.canEdit();
  document.body.classList.toggle("read-only", !editable);
  for (const e of $$(".edit, .editor input, .editor select, .editor button")) {
    if (e.closest(".always")) continue;
    e.disabled = !editable;
  }
  $("#token-state").textContent = editable ? "changes enabled" : "read-only: enter the server's token to make changes";
  $("#token-forget").hidden = !editable;
  $("#token-form").classList.toggle("has-token", editable);
  if (!editable && map.mode !== "pan") setMode("pan");
  metar.updateButtons();
  regions.renderLayers();
}

const link = new LiveLink({
  hello: (m) => {
    // This page speaks version 1 of the feed; a newer server is named so an
    // odd display has an explanation.
    $("#server-id").textContent = m.server_id + (m.api_version > 1 ? ` (feed v${m.api_version}; this console reads v1)` : "");
  },
  state: (s) => {
    app.stateValue = s;
    app.stateAt_ms = performance.now();
    document.body.dataset.sequence = String(s.sequence);
    updateOverlayChoices(s);
    layers.render(s);
    if (stationRegionsOf(s) !== stationRegions) {
      stationRegions = stationRegionsOf(s);
      refreshStations();
    }
    autoFocus();
    map.redraw();
    map.windField.weatherChanged();
    map.radar.weatherChanged();
  },
  event: (e) => {
    log.add(e);
    metarApplied([e]);
  },
  events: (list) => {
    log.setAll(list);
    metarApplied(list);
  },
  renderers: (list) => {
    app.renderersValue = list;
    renderRenderers($("#renderers"), list);
    autoFocus();
    map.redraw();
  },
  health: (h) => renderHealth($("#health"), h),
  mode: (mode, detail) => {
    document.body.dataset.link = mode;
    const badge = $("#link");
    badge.className = `badge link-${mode}`;
    badge.textContent = { connecting: "connecting", live: "live", polling: "polling", offline: "offline" }[mode];
    $("#link-detail").textContent = mode === "live" ? "WebSocket" : detail;
  },
});

// ---- wiring of the page's own controls ----

$("#token-form").addEventListener("submit", (e) => {
  e.preventDefault();
  const token = $('[name="token"]').value.trim();
  if (!token) return;
  session.setToken(token);
  session.setAuthor($('[name="author"]').value.trim() || "console");
  $('[name="token"]').value = "";
  updateEditable();
});
$("#token-forget").addEventListener("click", () => { session.setToken(""); updateEditable(); });
$('[name="author"]').value = session.author();
$('[name="author"]').addEventListener("change", (e) => session.setAuthor(e.target.value.trim() || "console"));

$("#overlay-layer").addEventListener("change", (e) => setOverlay(e.target.value === "" ? null : Number(e.target.value)));
for (const b of $$("[data-mode]")) b.addEventListener("click", () => setMode(b.dataset.mode));
$("#focus-form").addEventListener("submit", (e) => {
  e.preventDefault();
  const lat = num($('[name="focus_lat"]').value), lon = num($('[name="focus_lon"]').value);
  if (!(Math.abs(lat) <= 90) || !Number.isFinite(lon)) return;
  app.viewChosen = true;
  map.setView(lat, lon);
});
$("#zoom-in").addEventListener("click", () => map.zoomBy(1));
$("#zoom-out").addEventListener("click", () => map.zoomBy(-1));
$("#show-land").addEventListener("change", (e) => map.base.show("land", e.target.checked));
$("#show-borders").addEventListener("change", (e) => map.base.show("borders", e.target.checked));
$("#show-stations").addEventListener("change", (e) => map.stations.show(e.target.checked));
$("#show-radar").addEventListener("change", (e) => map.radar.set(e.target.checked));
$("#show-wind-field").addEventListener("change", (e) => {
  map.setWindField({ shown: e.target.checked });
  saveView();
});
$("#wind-form").addEventListener("submit", (e) => { e.preventDefault(); windHeightChanged(); });
$("#wind-height").addEventListener("change", windHeightChanged);
$("#wind-units").addEventListener("change", (e) => {
  localStorage.setItem(UNITS_KEY, e.target.value);
  map.setWindField({ units: e.target.value });
  windHeightShown(map.windField.alt_m, e.target.value);
  $("#wind-height").removeAttribute("aria-invalid");
});

// The METAR stations and their latest reports: asked again after an apply
// and whenever the set of station regions (ids 40000-65535) changes.
let stationRegions = null;
async function refreshStations() {
  const r = await request("GET", "/api/metar/stations");
  if (r.ok) map.stations.update(r.body.stations);
}
function stationRegionsOf(state) {
  return state.regions.filter((x) => x.id >= 40000).map((x) => x.id).join(",");
}
// A newer report replaces its station's region in place (same id), so the
// set of station regions need not change: the stations are asked again after
// every METAR change too, whoever applied it (events of source "metar").
let lastMetarSequence = null;
function metarApplied(events) {
  const sequences = events.filter((e) => e.source === "metar").map((e) => e.sequence);
  if (sequences.length === 0) return;
  const newest = Math.max(...sequences);
  if (newest === lastMetarSequence) return;
  lastMetarSequence = newest;
  refreshStations();
}

// A zoom from a view that names one, or from an older console's scale (m
// per CSS px at the focus); NaN when it names neither.
function zoomOf(v, lat_deg) {
  if (Number.isFinite(v.zoom)) return v.zoom;
  if (v.scale_mpp > 0) return Math.log2((MERCATOR_MPP_AT_ZOOM0 * Math.cos((lat_deg * Math.PI) / 180)) / v.scale_mpp);
  return NaN;
}

// A wind field height from a URL or a saved view: metres within the
// server's range, else null.
function windAltOf(v) {
  const alt_m = Number(v);
  return v !== null && v !== undefined && v !== "" && alt_m >= WIND_ALT_LIMITS_M[0] && alt_m <= WIND_ALT_LIMITS_M[1]
    ? alt_m : null;
}

// The view: from the URL (#focus=46.1,13.2&zoom=9, with &wind_alt_m=6000
// when the wind field is shown), else the last one this browser used, else
// the default until a region or renderer appears.
function initialView() {
  const hash = new URLSearchParams(location.hash.slice(1));
  const focus = (hash.get("focus") || "").split(",").map(Number);
  if (focus.length === 2 && focus.every(Number.isFinite)) {
    app.viewChosen = true;
    const zoom = zoomOf({ zoom: hash.has("zoom") ? Number(hash.get("zoom")) : NaN,
      scale_mpp: Number(hash.get("scale")) }, focus[0]);
    const wind_alt_m = windAltOf(hash.get("wind_alt_m"));
    return { lat_deg: focus[0], lon_deg: focus[1], zoom: Number.isFinite(zoom) ? zoom : DEFAULT_VIEW.zoom,
      wind_alt_m: wind_alt_m ?? DEFAULT_WIND_ALT_M, wind_shown: wind_alt_m !== null };
  }
  try {
    const saved = JSON.parse(localStorage.getItem(VIEW_KEY) || "null");
    if (saved && Number.isFinite(saved.lat_deg) && Number.isFinite(zoomOf(saved, saved.lat_deg))) {
      app.viewChosen = true;
      return { ...saved, zoom: zoomOf(saved, saved.lat_deg), wind_alt_m: windAltOf(saved.wind_alt_m) ?? DEFAULT_WIND_ALT_M,
        wind_shown: saved.wind_shown === true };
    }
  } catch { /* a damaged saved view: use the default */ }
  return { ...DEFAULT_VIEW, wind_alt_m: DEFAULT_WIND_ALT_M, wind_shown: false };
}

const view = initialView();
map.setView(view.lat_deg, view.lon_deg, view.zoom);
const units = localStorage.getItem(UNITS_KEY) === "ft" ? "ft" : "m";
$("#wind-units").value = units;
$("#show-wind-field").checked = view.wind_shown;
windHeightShown(view.wind_alt_m, units);
map.setWindField({ shown: view.wind_shown, alt_m: view.wind_alt_m, units });
setMode("pan");
updateEditable();
renderRenderers($("#renderers"), []);
log.render();
link.start();
new ClusterPanel($("#cluster"), request).start();
