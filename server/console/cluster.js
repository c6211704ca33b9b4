// The cluster panel: the weather servers and relays of a NATS cluster
// (skyshell-weatherd --nats, skyshell-relay) with their role, their
// renderers and whether their weather is the leader's, from GET
// /api/cluster (server/API.md). Hidden on a server without --nats.
import { $, el } from "./dom.js";
import { fmt } from "./units.js";

// How often the panel asks: each member puts its record and reads the
// others' every second, so 2 s shows a change within about 3 s.
const POLL_MS = 2000;
// A record older than this is marked stale: its member missed at least
// three of its one-second puts (it expires from the registry at 5 s).
const STALE_MS = 3000;

export class ClusterPanel {
  // request: api.js's request(method, path).
  constructor(root, request) {
    this.root = root;
    this.request = request;
    this.timer = null;
  }

  start() {
    const tick = async () => {
      const r = await this.request("GET", "/api/cluster");
      // Unreachable (status 0) or refused: the last list stays, as the other
      // panels keep their last state while the link is down.
      if (r.ok) this.render(r.body);
      this.timer = setTimeout(tick, POLL_MS);
    };
    tick();
  }

  render(cluster) {
    const members = cluster && Array.isArray(cluster.members) ? cluster.members : [];
    this.root.hidden = !(cluster && cluster.nats === true);
    if (this.root.hidden) return;
    const leader = members.find((m) => m.role === "leader");
    const now_ms = Date.now();
    const tbody = $("tbody", this.root);
    tbody.replaceChildren(...members.map((m) => {
      const stale = now_ms - Number(m.updated_unix_ms) > STALE_MS;
      const sameWeather = leader && m.state_hash === leader.state_hash;
      return el("tr", { "data-role": String(m.role), class: stale ? "muted" : "" },
        el("td", {}, String(m.role), m.id === cluster.self ? el("span", { class: "muted" }, " (this)") : ""),
        el("td", {}, String(m.id)),
        el("td", {}, String(m.stream || "")),
        el("td", { class: "num" }, String(m.subscribers)),
        el("td", { class: "num" }, String(m.applied_sequence)),
        el("td", {}, !leader ? "–" : sameWeather ? "as leader" : el("span", { class: "bad" }, "differs")));
    }));
    if (!members.length) tbody.append(el("tr", {}, el("td", { colspan: 6, class: "muted" }, "no member listed yet")));
    const relays = members.filter((m) => m.role === "relay");
    const age = cluster.read_age_ms === null || cluster.read_age_ms === undefined ? "not read yet"
      : `read ${fmt(cluster.read_age_ms / 1000, 1)} s ago`;
    $(".note", this.root).textContent =
      `${members.length - relays.length} server(s), ${relays.length} relay(s) with ` +
      `${relays.reduce((n, m) => n + Number(m.subscribers || 0), 0)} renderer(s); ${age}` +
      (cluster.malformed_records ? `; ${cluster.malformed_records} malformed record(s) left out` : "");
  }
}
