// Lightning on the console: a flash asked for at the map's centre (POST
// /api/events, with the token), and the recent flashes on the map, read from
// GET /api/events (those asked for and those the server's storm process
// draws over cumulonimbus). Each flash is a marker that fades over its first
// minute of weather clock.
import { request } from "./api.js";
import { $, note } from "./dom.js";
import { normalizeLon } from "./geo.js";
import { clockText, fmt } from "./units.js";

const L = window.L;

// One request at a time, this long after the last answer: a flash shows
// within about two seconds of the server drawing it.
const POLL_MS = 2000;
// Flashes asked for per poll (the newest); the server keeps at most 1000.
const POLL_LIMIT = 50;
// A flash is drawn for this much weather clock after it struck, fading.
const SHOWN_FOR_S = 60;
// The faintest a flash gets before it goes, so the last seconds still show.
const MIN_OPACITY = 0.15;
// A flash this far ahead of the page's clock is still drawn (the page
// extrapolates the clock between states); one further ahead is from before
// a jump back and is not.
const AHEAD_SLACK_S = 5;
// Flashes held at most; the oldest go first.
const MAX_FLASHES = 200;

// The marker (16 x 16 px): a bolt for a cloud-to-ground flash, a ring for
// one inside the cloud (the usual lightning-map symbols).
const BOLT_PATH = "M10 0 L3 9 L7.5 9 L5 16 L13 6.5 L8.5 6.5 L11 0 Z";

function flashElement(kind) {
  const root = document.createElement("div");
  root.className = `flash flash-${kind}`;
  const svg = document.createElementNS("http://www.w3.org/2000/svg", "svg");
  svg.setAttribute("viewBox", "0 0 16 16");
  svg.setAttribute("width", "16");
  svg.setAttribute("height", "16");
  if (kind === "in-cloud") {
    const ring = document.createElementNS("http://www.w3.org/2000/svg", "circle");
    ring.setAttribute("cx", "8");
    ring.setAttribute("cy", "8");
    ring.setAttribute("r", "5.5");
    svg.append(ring);
  } else {
    const path = document.createElementNS("http://www.w3.org/2000/svg", "path");
    path.setAttribute("d", BOLT_PATH);
    svg.append(path);
  }
  root.append(svg);
  return root;
}

// The flashes on the map. clockNow(): the weather clock now (s).
export const LightningLayer = L.Layer.extend({
  initialize(pane, clockNow) {
    L.setOptions(this, { pane });
    this.clockNow = clockNow;
    this.flashes = new Map();  // seed -> {flash, marker, el}
    this.inFlight = false;
  },
  onAdd(map) {
    map.on("moveend", this.draw, this);
    this.poll();
  },
  onRemove(map) {
    map.off("moveend", this.draw, this);
    clearTimeout(this.pollTimer);
    for (const f of this.flashes.values()) f.marker.remove();
    this.flashes.clear();
  },

  async poll() {
    if (this.inFlight || !this._map) return;
    this.inFlight = true;
    const r = await request("GET", `/api/events?limit=${POLL_LIMIT}`);
    this.inFlight = false;
    if (!this._map) return;
    // A server without lightning answers without the list: nothing to draw.
    if (r.ok && r.body && Array.isArray(r.body.lightning)) this.add(r.body.lightning);
    this.pollTimer = setTimeout(() => this.poll(), POLL_MS);
  },

  // Flashes (the API's objects) to draw; ones already held are kept as they
  // are, and ones past their minute (still in the server's list) not taken.
  add(flashes) {
    const now_s = this.clockNow();
    for (const flash of flashes) {
      if (this.flashes.has(flash.seed) || now_s - flash.time_s > SHOWN_FOR_S) continue;
      const el = flashElement(flash.kind);
      const marker = L.marker([0, 0], { pane: this.options.pane, interactive: false, keyboard: false,
        icon: L.divIcon({ className: "flash-icon", html: el, iconSize: [16, 16], iconAnchor: [8, 8] }) });
      el.title = `${flash.kind} flash at ${clockText(flash.time_s)}, ${fmt(flash.lat_deg, 4)}°, ${fmt(flash.lon_deg, 4)}°`;
      Object.assign(el.dataset, { seed: flash.seed, kind: flash.kind, lat: String(flash.lat_deg),
        lon: String(flash.lon_deg), timeS: String(flash.time_s) });
      this.flashes.set(flash.seed, { flash, marker, el });
    }
    this.draw();
  },

  // Places and fades every held flash; forgets those past their minute and
  // the oldest beyond MAX_FLASHES.
  draw() {
    const map = this._map;
    if (!map) return;
    const now_s = this.clockNow(), ref_deg = map.getCenter().lng;
    const held = [...this.flashes.values()].sort((a, b) => a.flash.time_s - b.flash.time_s);
    let drawn = 0;
    held.forEach((f, i) => {
      const age_s = now_s - f.flash.time_s;
      if (age_s > SHOWN_FOR_S || held.length - i > MAX_FLASHES) {
        f.marker.remove();
        this.flashes.delete(f.flash.seed);
        return;
      }
      if (age_s < -AHEAD_SLACK_S) {
        f.marker.remove();
        return;
      }
      // Longitudes within 180 degrees of the view's centre, as map.js draws shapes.
      f.marker.setLatLng([f.flash.lat_deg, ref_deg + normalizeLon(f.flash.lon_deg - ref_deg)]);
      if (!map.hasLayer(f.marker)) f.marker.addTo(map);
      f.el.style.opacity = String(Math.max(MIN_OPACITY, 1 - Math.max(0, age_s) / SHOWN_FOR_S));
      f.el.dataset.ageS = fmt(age_s, 1);
      ++drawn;
    });
    map.getContainer().dataset.flashes = String(drawn);
  },
});

// The Lightning card: a kind and a button that asks for a flash at the map's
// centre. app: {canEdit(), tokenRefused()}; centre(): {lat_deg, lon_deg};
// flashed(flash): the server's flash, drawn at once.
export class LightningPanel {
  constructor(root, app, centre, flashed) {
    this.root = root;
    this.app = app;
    this.centre = centre;
    this.flashed = flashed;
    $("#lightning-form", root).addEventListener("submit", (e) => { e.preventDefault(); this.flash(); });
  }

  async flash() {
    const noteEl = $(".note", this.root);
    if (!this.app.canEdit()) return note(noteEl, "read-only: enter the token first", "bad");
    const { lat_deg, lon_deg } = this.centre();
    const kind = $("#lightning-kind", this.root).value;
    note(noteEl, "asking…", "busy");
    const r = await request("POST", "/api/events", { lightning: { lat_deg, lon_deg, kind } }, { auth: true });
    if (r.ok) {
      const f = r.body.lightning;
      note(noteEl, `${f.kind} flash at ${fmt(f.lat_deg, 4)}°, ${fmt(f.lon_deg, 4)}°, clock ${clockText(f.time_s)}` +
        ` (${fmt(f.bottom_m)}–${fmt(f.top_m)} m)`, "ok");
      this.flashed(f);
    } else if (r.status === 401) {
      this.app.tokenRefused();
      note(noteEl, "the server refused the token: read-only now; no flash", "bad");
    } else if (r.status === 404 || r.status === 405) {
      note(noteEl, "this server cannot make lightning (no POST /api/events)", "bad");
    } else {
      note(noteEl, `no flash: ${(r.body && r.body.error) || `HTTP ${r.status}`}`, "bad");
    }
  }
}
