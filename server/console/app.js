// The Skyshell operator console: wires the live feed (api.js) to the map and
// the panels, keeps the token for the tab's session, and turns the page
// read-only without it. Served by skyshell-weatherd at / (README, "The
// operator console").
import { LiveLink, postChanges, session } from "./api.js";
import { ClockPanel } from "./clock.js";
import { layerIds } from "./coverage.js";
import { $, $$, note, showErrors } from "./dom.js";
import { LayerPanel } from "./layers.js";
import { EventLog, renderHealth, renderRenderers } from "./log.js";
import { MapView } from "./map.js";
import { MetarPanel } from "./metar.js";
import { ConformancePanel } from "./conformance.js";
import { RegionPanel } from "./regions.js";
import { fmt, keyOfServerError, num } from "./units.js";

const VIEW_KEY = "skyshell.view";
// Where the map looks before anything says better: the bundled demo's area
// (north-east Italy), 250 m per pixel.
const DEFAULT_VIEW = { lat_deg: 46.0, lon_deg: 13.0, scale_mpp: 250 };

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
  onSelect(id) { setOverlay(id); },
  tokenRefused() {
    session.setToken("");
    updateEditable();
  },
  changed() { link.refreshState(); },

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
}, {
  place: (kind, lat, lon, half_m) => regions.place(kind, lat, lon, half_m),
  placed: () => setMode("pan"),
  reshape: (shape) => regions.reshape(shape),
  pick: (id) => regions.edit(id),
  cursor: (text) => { $("#map-cursor").textContent = text; },
  view: (focus, scale) => {
    $('[name="focus_lat"]').value = fmt(focus.lat_deg, 4);
    $('[name="focus_lon"]').value = fmt(focus.lon_deg, 4);
    $("#map").dataset.focus = `${focus.lat_deg},${focus.lon_deg}`;
    $("#map").dataset.scale = String(scale);
    clearTimeout(app.saveView);
    app.saveView = setTimeout(() => localStorage.setItem(VIEW_KEY,
      JSON.stringify({ lat_deg: focus.lat_deg, lon_deg: focus.lon_deg, scale_mpp: scale })), 500);
  },
});

const layers = new LayerPanel($("#layers"), app);
const regions = new RegionPanel($("#region"), app);
const metar = new MetarPanel($("#metar"), app);
new ConformancePanel($("#conformance"));
new ClockPanel($("#clock"), app);
const log = new EventLog($("#events"));

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
    autoFocus();
    map.redraw();
  },
  event: (e) => log.add(e),
  events: (list) => log.setAll(list),
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
$("#zoom-in").addEventListener("click", () => map.setView(map.focus.lat_deg, map.focus.lon_deg, map.scale_mpp / 1.6));
$("#zoom-out").addEventListener("click", () => map.setView(map.focus.lat_deg, map.focus.lon_deg, map.scale_mpp * 1.6));

// The view: from the URL (#focus=46.1,13.2&scale=200), else the last one
// this browser used, else the default until a region or renderer appears.
function initialView() {
  const hash = new URLSearchParams(location.hash.slice(1));
  const focus = (hash.get("focus") || "").split(",").map(Number);
  if (focus.length === 2 && focus.every(Number.isFinite)) {
    app.viewChosen = true;
    return { lat_deg: focus[0], lon_deg: focus[1], scale_mpp: Number(hash.get("scale")) || DEFAULT_VIEW.scale_mpp };
  }
  try {
    const saved = JSON.parse(localStorage.getItem(VIEW_KEY) || "null");
    if (saved && Number.isFinite(saved.lat_deg)) {
      app.viewChosen = true;
      return saved;
    }
  } catch { /* a damaged saved view: use the default */ }
  return DEFAULT_VIEW;
}

const view = initialView();
map.setView(view.lat_deg, view.lon_deg, view.scale_mpp);
setMode("pan");
updateEditable();
renderRenderers($("#renderers"), []);
log.render();
link.start();
