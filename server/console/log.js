// The event log (every accepted change: who, what, when) and the server's
// health (subscribers, changes applied, inputs rejected by reason), plus the
// list of connected renderers.
import { $, el } from "./dom.js";
import { clockText, fmt, ftFromM } from "./units.js";

// The log keeps this many events (the newest).
const MAX_EVENTS = 500;

export class EventLog {
  constructor(root) {
    this.root = root;
    this.events = [];
  }

  setAll(events) {
    this.events = [...events].sort((a, b) => a.sequence - b.sequence).slice(-MAX_EVENTS);
    this.render();
  }

  add(event) {
    if (this.events.some((e) => e.sequence === event.sequence)) return;
    this.events.push(event);
    this.events.sort((a, b) => a.sequence - b.sequence);
    if (this.events.length > MAX_EVENTS) this.events.shift();
    this.render();
  }

  render() {
    const tbody = $("tbody", this.root);
    tbody.replaceChildren(...[...this.events].reverse().map((e) => el("tr", {},
      el("td", { class: "num" }, String(e.sequence)),
      el("td", {}, new Date(e.wall_time_ms).toLocaleTimeString()),
      el("td", { class: "num" }, clockText(e.clock_s)),
      el("td", {}, e.author, e.source && e.source !== e.author ? el("span", { class: "muted" }, ` (${e.source})`) : ""),
      el("td", {}, e.summary))));
    if (!this.events.length) tbody.append(el("tr", {}, el("td", { colspan: 5, class: "muted" }, "no changes yet")));
  }
}

export function renderHealth(root, h) {
  const rejected = Object.entries(h.rejected || {});
  const dl = $("dl", root);
  const item = (k, v) => [el("dt", {}, k), el("dd", {}, v === null || v === undefined ? "–" : String(v))];
  dl.replaceChildren(
    ...item("subscribers", h.subscribers), ...item("changes applied", h.changes_applied),
    ...item("rejected", rejected.length ? rejected.map(([r, n]) => `${r}: ${n}`).join(", ") : "none"),
    ...item("console clients", h.ws_clients));
}

export function renderRenderers(root, renderers) {
  const tbody = $("tbody", root);
  if (renderers === null) {
    tbody.replaceChildren(el("tr", {}, el("td", { colspan: 6, class: "muted" },
      "this server does not list its renderers (no /api/renderers)")));
    return;
  }
  tbody.replaceChildren(...renderers.map((r) => el("tr", {},
    el("td", {}, String(r.channel || r.id)), el("td", {}, r.peer || ""),
    el("td", { class: "num" }, r.lat_deg === null || r.lat_deg === undefined ? "no pose" : `${fmt(r.lat_deg, 4)}, ${fmt(r.lon_deg, 4)}`),
    el("td", { class: "num" }, r.alt_m === null || r.alt_m === undefined ? "–" : `${fmt(r.alt_m)} m · ${fmt(ftFromM(r.alt_m))} ft`),
    el("td", { class: "num" }, r.heading_deg === null || r.heading_deg === undefined ? "–" : `${fmt(r.heading_deg)}°`),
    el("td", { class: "num" }, r.last_report_age_s === null || r.last_report_age_s === undefined ? "–" : `${fmt(r.last_report_age_s, 1)} s`))));
  if (!renderers.length) tbody.append(el("tr", {}, el("td", { colspan: 6, class: "muted" }, "no renderer connected")));
}
