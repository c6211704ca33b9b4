// The conformance panel: GET /api/conformance on demand. Per METAR station
// what its report says against what the renderers draw there (oktas per
// layer, ceiling, visibility), and how many points of a loaded forecast's grid match
// their grid values; rows out of tolerance first, in the warning colour.
// And at a point: the weather there (GET /api/conditions: cloud, the air's
// temperature and humidity and whether a forecast gave them) and where each
// forecast layer's cover comes from (file, field, grid point).
import { $, el, note } from "./dom.js";
import { request } from "./api.js";
import { fmt, ftFromM } from "./units.js";

const layersText = (layers) =>
  layers.length ? layers.map((l) => `${l.oktas}/8 at ${fmt(ftFromM(l.base_m))} ft`).join(", ") : "clear";
const ceilingText = (c) => (c === null || c === undefined ? "none" : `${fmt(ftFromM(c))} ft`);
// A visibility under 10 km in metres, as METARs give it; none: 10 km or more.
const visibilityText = (v) => (v === null || v === undefined ? "10 km+" : `${fmt(v)} m`);

export class ConformancePanel {
  // onChecked(stations): the check's station rows, for the map's markers.
  constructor(root, onChecked = () => {}) {
    this.root = root;
    this.onChecked = onChecked;
    $("#conformance-check", root).addEventListener("click", () => this.check());
    $("#source-form", root).addEventListener("submit", (e) => { e.preventDefault(); this.source(); });
  }

  async source() {
    const f = (name) => Number($(`#source-form [name="${name}"]`, this.root).value);
    const out = $("#source-result", this.root);
    const lat = f("lat"), lon = f("lon"), alt = f("alt");
    if (![lat, lon, alt].every(Number.isFinite) || Math.abs(lat) > 90 || Math.abs(lon) > 180) {
      out.replaceChildren(el("li", { class: "bad" }, "latitude, longitude (degrees) and altitude (m MSL)"));
      return;
    }
    const r = await request("GET", `/api/conditions?lat_deg=${lat}&lon_deg=${lon}&alt_m=${alt}`);
    if (!r.ok) {
      out.replaceChildren(el("li", { class: "bad" }, (r.body && r.body.error) || `HTTP ${r.status}`));
      return;
    }
    const c = r.body, sources = Object.entries(c.forecast_sources || {});
    const humidity = c.humidity_pct === null || c.humidity_pct === undefined ? "" : `, humidity ${fmt(c.humidity_pct, 0)} %`;
    out.replaceChildren(
      el("li", {}, c.layer_id === null ? "clear air here"
        : `layer ${c.layer_id}, cloud density ${fmt(c.cloud_density, 2)}, visibility ${fmt(c.visibility_m)} m`),
      el("li", {}, `air ${fmt(c.air_temperature_c, 1)} C${humidity} (${c.air_from || "standard atmosphere"})`),
      ...(sources.length ? sources.map(([id, src]) => el("li", {}, `layer ${id}: ${src}`))
        : [el("li", {}, "no forecast cover here (hand-made layers, regions and stations only)")]));
  }

  async check() {
    const out = $("#conformance-result", this.root), msg = $(".note", this.root);
    note(msg, "checking ...", "ok");
    const [r, s] = await Promise.all([request("GET", "/api/conformance?grid_points=200"), request("GET", "/api/state")]);
    if (!r.ok) {
      note(msg, `not checked: ${(r.body && r.body.error) || `HTTP ${r.status}`}`, "bad");
      return;
    }
    const c = r.body, sum = c.summary;
    const forecast = s.ok && s.body.forecast ? `forecast ${s.body.forecast.name} (valid ${s.body.forecast.first_valid})` : "no forecast";
    note(msg, `${sum.stations_ok} of ${sum.stations} stations and ${sum.grid_ok} of ${sum.grid_points} grid points ` +
      `within ${c.tolerances.oktas} okta, ${fmt(ftFromM(c.tolerances.ceiling_m))} ft and visibility ${c.tolerances.visibility}; ${forecast}`,
      sum.stations_ok === sum.stations && sum.grid_ok === sum.grid_points ? "ok" : "bad");
    this.onChecked(c.stations);
    const rows = [...c.stations].sort((a, b) => Number(a.ok) - Number(b.ok));
    out.replaceChildren(
      el("thead", {}, el("tr", {}, el("th", {}, "station"), el("th", {}, "report"), el("th", {}, "drawn"),
        el("th", {}, "ceiling"), el("th", {}, "visibility"), el("th", {}, "off"))),
      el("tbody", {}, rows.map((st) => el("tr", { class: st.ok ? "ok" : "bad", dataset: { region: String(st.region_id) } },
        el("td", {}, st.icao || `region ${st.region_id}`),
        el("td", {}, layersText(st.reported.layers)),
        el("td", {}, layersText(st.drawn.layers)),
        el("td", {}, `${ceilingText(st.reported.ceiling_m)} / ${ceilingText(st.drawn.ceiling_m)}`),
        el("td", {}, `${visibilityText(st.reported.visibility_m)} / ${visibilityText(st.drawn.visibility_m)}`),
        el("td", {}, `${st.oktas_off}/8`)))));
  }
}
