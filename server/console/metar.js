// The METAR box: raw reports pasted in, previewed (the layers each report
// would give, or why it does not parse), then applied as the server's station
// regions (POST /api/metar, see server/include/sky/server/metar_api.hpp).
// Apply sends exactly what was previewed; editing the reports asks for a new
// preview first.
import { $, el, showErrors } from "./dom.js";
import { request, session } from "./api.js";
import { checkTiming, fmt, ftFromM, keyOfServerError, num, OKTAS } from "./units.js";

const MAX_REPORTS = 1024;  // the server's limit per request (kMaxMetarReports)

const METAR_KEYS = { reports: "reports", radius_m: "radius", ramp_s: "ramp", stations: "stations", at_s: "ramp" };

// "icao,lat_deg,lon_deg,elevation_m" lines (a header and # comments
// skipped) to station objects; {error} naming the line when one is bad.
export function parseStations(text) {
  const stations = [];
  const lines = text.split("\n");
  for (let i = 0; i < lines.length; ++i) {
    const line = lines[i].trim();
    if (!line || line.startsWith("#") || /^icao\s*,/i.test(line)) continue;
    const [icao, lat, lon, elev, extra] = line.split(",").map((s) => s.trim());
    const v = [lat, lon, elev].map(num);
    if (extra !== undefined || !icao || icao.length !== 4 || v.some((x) => !Number.isFinite(x)))
      return { error: `stations line ${i + 1}: expected ICAO,lat_deg,lon_deg,elevation_m` };
    stations.push({ icao: icao.toUpperCase(), lat_deg: v[0], lon_deg: v[1], elevation_m: v[2] });
  }
  return { stations };
}

export class MetarPanel {
  // app: {canEdit(), clockNow(), changed(result)}
  constructor(root, app) {
    this.root = root;
    this.app = app;
    this.form = $("#metar-form", root);
    this.f = (name) => $(`[name="${name}"]`, this.form);
    this.previewed = null;  // the request body last previewed successfully
    this.form.addEventListener("submit", (e) => { e.preventDefault(); this.preview(); });
    $("#metar-apply", root).addEventListener("click", () => this.apply());
    this.form.addEventListener("input", () => {
      this.previewed = null;
      this.updateButtons();
    });
    this.updateButtons();
  }

  updateButtons() {
    $("#metar-apply", this.root).disabled = !(this.previewed && this.app.canEdit());
  }

  body() {
    const errors = {};
    const reports = this.f("reports").value.split("\n").map((s) => s.trim()).filter((s) => s);
    if (!reports.length) errors.reports = "paste at least one METAR report";
    else if (reports.length > MAX_REPORTS) errors.reports = `${reports.length} reports, at most ${MAX_REPORTS} at a time`;
    const radius_km = num(this.f("radius").value);
    if (!(radius_km > 0 && radius_km <= 2000)) errors.radius = "radius: more than 0 and at most 2000 km";
    const ramp_s = this.f("ramp").value.trim() === "" ? 0 : num(this.f("ramp").value);
    Object.assign(errors, checkTiming(ramp_s, null, this.app.clockNow()));
    const body = { reports, radius_m: radius_km * 1000 };
    if (ramp_s > 0) body.ramp_s = ramp_s;
    const stationsText = this.f("stations").value.trim();
    if (stationsText) {
      const parsed = parseStations(stationsText);
      if (parsed.error) errors.stations = parsed.error;
      else body.stations = parsed.stations;
    }
    return { body, errors };
  }

  async preview() {
    const { body, errors } = this.body();
    showErrors(this.form, errors);
    this.previewed = null;
    this.updateButtons();
    if (Object.keys(errors).length) return;
    const note = $(".note", this.root);
    note.textContent = "previewing…";
    const r = await request("POST", "/api/metar", { ...body, apply: false });
    if (!r.ok) return this.refused(r);
    this.show(r.body);
    const good = r.body.reports.filter((x) => x.ok && x.sky === "read").length;
    note.textContent = `${good} of ${r.body.reports.length} reports map to weather` +
      (good ? `: ${r.body.stations.set} station region(s) on apply` : "");
    note.className = `note ${good ? "ok" : "bad"}`;
    if (r.body.changes.length) this.previewed = body;
    this.updateButtons();
  }

  async apply() {
    if (!this.previewed || !this.app.canEdit()) return;
    const note = $(".note", this.root);
    const r = await request("POST", "/api/metar", { ...this.previewed, apply: true, author: session.author() },
      { auth: true });
    if (!r.ok) return this.refused(r);
    note.textContent = `applied #${r.body.applied.sequence}: ${r.body.applied.summary}`;
    note.className = "note ok";
    this.show(r.body);
    this.app.changed(r);
  }

  refused(r) {
    const note = $(".note", this.root);
    if (r.status === 401) {
      this.app.tokenRefused();
      note.textContent = "the server refused the token: read-only now; nothing applied";
    } else {
      const { key } = keyOfServerError(r.body);
      const field = METAR_KEYS[key] || (/^reports/.test(key) ? "reports" : "form");
      showErrors(this.form, { [field]: r.body.error || `HTTP ${r.status}` });
      note.textContent = r.status === 0 ? `${r.body.error}: nothing applied` : "refused: nothing applied";
    }
    note.className = "note bad";
  }

  show(reply) {
    const list = $("#metar-result", this.root);
    list.replaceChildren(...reply.reports.map((rep) => {
      if (!rep.ok) return el("li", { class: "bad" }, `${rep.index}: ${rep.error}`);
      const layers = rep.sky === "not_observed"
        ? "sky not observed: the weather there stays as it is"
        : rep.layers.length
          ? rep.layers.map((l) => `${l.type} ${fmt(l.coverage * OKTAS, 1)}/8 (${fmt(l.coverage * 100)} %) ` +
              `${fmt(ftFromM(l.base_m))}–${fmt(ftFromM(l.base_m + l.thickness_m))} ft MSL`).join("; ")
          : "clear (no layers)";
      // Groups the decoder skipped (not used) or read with the one before.
      const notes = [];
      for (const g of rep.skipped || []) notes.push(`skipped group ${g.group} '${g.text}': ${g.reason}`);
      if ((rep.skipped_count || 0) > (rep.skipped || []).length)
        notes.push(`and ${rep.skipped_count - rep.skipped.length} more skipped`);
      for (const g of rep.joined || []) notes.push(`group ${g.group} '${g.text}': ${g.reason}`);
      return el("li", { class: rep.sky === "not_observed" ? "warn" : "ok" }, el("b", {}, `${rep.index} ${rep.icao}`),
        `: ${layers}`, ...(notes.length ? [el("div", { class: "notes" }, notes.join("; "))] : []));
    }));
  }
}
