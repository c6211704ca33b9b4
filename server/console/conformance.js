// The conformance panel: GET /api/conformance on demand. Per METAR station
// what its report says against what the renderers draw there (oktas per
// layer, ceiling), and how many points of a loaded forecast's grid match
// their grid values; rows out of tolerance first, in the warning colour.
import { $, el, note } from "./dom.js";
import { request } from "./api.js";
import { fmt, ftFromM } from "./units.js";

const layersText = (layers) =>
  layers.length ? layers.map((l) => `${l.oktas}/8 at ${fmt(ftFromM(l.base_m))} ft`).join(", ") : "clear";
const ceilingText = (c) => (c === null || c === undefined ? "none" : `${fmt(ftFromM(c))} ft`);

export class ConformancePanel {
  constructor(root) {
    this.root = root;
    $("#conformance-check", root).addEventListener("click", () => this.check());
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
      `within ${c.tolerances.oktas} okta and ${fmt(ftFromM(c.tolerances.ceiling_m))} ft; ${forecast}; visibility: ${c.visibility}`,
      sum.stations_ok === sum.stations && sum.grid_ok === sum.grid_points ? "ok" : "bad");
    const rows = [...c.stations].sort((a, b) => Number(a.ok) - Number(b.ok));
    out.replaceChildren(
      el("thead", {}, el("tr", {}, el("th", {}, "station"), el("th", {}, "report"), el("th", {}, "drawn"),
        el("th", {}, "ceiling"), el("th", {}, "off"))),
      el("tbody", {}, rows.map((st) => el("tr", { class: st.ok ? "ok" : "bad", dataset: { region: String(st.region_id) } },
        el("td", {}, st.icao || `region ${st.region_id}`),
        el("td", {}, layersText(st.reported.layers)),
        el("td", {}, layersText(st.drawn.layers)),
        el("td", {}, `${ceilingText(st.reported.ceiling_m)} / ${ceilingText(st.drawn.ceiling_m)}`),
        el("td", {}, `${st.oktas_off}/8`)))));
  }
}
