// The console's link to skyshell-weatherd: JSON requests to the HTTP API, and
// the live feed. Live first: the WebSocket at /api/ws pushes hello, state,
// event, renderers and health messages. When the socket cannot be had (a
// server without it), the feed falls back to polling GET /api/state,
// /api/events, /api/renderers and /metrics, and keeps trying the socket.
// When the server is gone altogether it retries with a growing backoff and
// resynchronises by itself once it is back.

const TOKEN_KEY = "skyshell.token";
const AUTHOR_KEY = "skyshell.author";

// The token lives in sessionStorage: entered once per browser tab session,
// gone when the tab closes.
export const session = {
  token: () => sessionStorage.getItem(TOKEN_KEY) || "",
  setToken: (t) => (t ? sessionStorage.setItem(TOKEN_KEY, t) : sessionStorage.removeItem(TOKEN_KEY)),
  author: () => sessionStorage.getItem(AUTHOR_KEY) || "console",
  setAuthor: (a) => sessionStorage.setItem(AUTHOR_KEY, a),
};

// One request. Resolves to {ok, status, body} (body: parsed JSON, or text);
// status 0 when the server could not be reached. Never rejects.
export async function request(method, path, body, { auth = false, timeout_ms = 10000 } = {}) {
  const headers = {};
  if (body !== undefined) headers["Content-Type"] = "application/json";
  if (auth && session.token()) headers.Authorization = `Bearer ${session.token()}`;
  const abort = new AbortController();
  const timer = setTimeout(() => abort.abort(), timeout_ms);
  try {
    const r = await fetch(path, {
      method, headers, body: body === undefined ? undefined : JSON.stringify(body), signal: abort.signal,
      cache: "no-store",
    });
    const text = await r.text();
    let parsed = text;
    if ((r.headers.get("Content-Type") || "").startsWith("application/json")) {
      try { parsed = JSON.parse(text); } catch { parsed = { error: "reply is not JSON" }; }
    }
    return { ok: r.ok, status: r.status, body: parsed };
  } catch (e) {
    return { ok: false, status: 0, body: { error: `server not reachable (${e.name === "AbortError" ? "timeout" : "network"})` } };
  } finally {
    clearTimeout(timer);
  }
}

export const postChanges = (changes) =>
  request("POST", "/api/changes", { author: session.author(), changes }, { auth: true });

// Reads the counters the health panel shows out of /metrics (polling mode).
export function healthFromMetrics(text) {
  const value = (name) => {
    const m = new RegExp(`^${name}(?:\\{[^}]*\\})? (\\S+)$`, "m").exec(text);
    return m ? Number(m[1]) : null;
  };
  const rejected = {};
  const invalid = value("skyshell_changes_rejected_total");
  if (invalid) rejected.invalid = invalid;
  const unauthorized = value("skyshell_changes_unauthorized_total");
  if (unauthorized) rejected.unauthorized = unauthorized;
  const cigi = value("skyshell_cigi_rejected_total");
  if (cigi) rejected.cigi = cigi;
  const malformed = value("skyshell_cigi_malformed_total");
  if (malformed) rejected.cigi_malformed = malformed;
  return {
    subscribers: value("skyshell_subscribers"), changes_applied: value("skyshell_changes_applied_total"),
    rejected, ws_clients: null,
  };
}

// Backoff of reconnects after a failure: doubles from the first to the last.
const RETRY_FIRST_MS = 500, RETRY_MAX_MS = 10000;
// Polling periods when there is no socket: the state once a second keeps a
// change from another console within about a second; the rest change less.
const POLL_STATE_MS = 1000, POLL_RENDERERS_MS = 1000, POLL_EVENTS_MS = 2000, POLL_HEALTH_MS = 4000;
// How often, while polling, the socket is tried again.
const WS_RETRY_WHILE_POLLING_MS = 30000;
// The server sends state after every change only; while something evolves
// by itself (a ramp, a drifting region) the state is re-read this often.
const REFRESH_EVOLVING_MS = 2000;

// The live feed. handlers: hello(msg), state(STATE), event(EVENT),
// events([EVENT]) (a full list, after a (re)connect), renderers([..]) or
// renderers(null) when the server has none to give, health(H), mode(m, detail).
// Modes: "connecting", "live" (WebSocket), "polling", "offline".
export class LiveLink {
  constructor(handlers) {
    this.h = handlers;
    this.mode = "connecting";
    this.ws = null;
    this.retry_ms = RETRY_FIRST_MS;
    this.timers = new Map();
    this.lastSequence = -1;
    this.lastState = null;
    this.renderersAvailable = true;
  }

  start() {
    this.connectSocket();
  }

  setMode(mode, detail = "") {
    this.mode = mode;
    this.h.mode(mode, detail);
  }

  later(name, ms, fn) {
    clearTimeout(this.timers.get(name));
    this.timers.set(name, setTimeout(() => { this.timers.delete(name); fn(); }, ms));
  }

  stopPolling() {
    for (const name of ["state", "events", "renderers", "health"]) clearTimeout(this.timers.get(name));
  }

  connectSocket() {
    const url = `${location.protocol === "https:" ? "wss" : "ws"}://${location.host}/api/ws`;
    let opened = false;
    let ws;
    try {
      ws = new WebSocket(url);
    } catch {
      this.socketFailed(false);
      return;
    }
    this.ws = ws;
    ws.onopen = () => {
      opened = true;
      this.retry_ms = RETRY_FIRST_MS;
      this.stopPolling();
      this.setMode("live");
      this.loadEvents();  // the socket pushes new events; the history comes once
    };
    ws.onmessage = (m) => this.onMessage(m.data);
    ws.onclose = () => {
      if (this.ws !== ws) return;
      this.ws = null;
      this.socketFailed(opened);
    };
  }

  // The socket closed (after working) or never opened: find out whether the
  // server is there at all, and poll or wait accordingly.
  async socketFailed(wasOpen) {
    const alive = await request("GET", "/healthz", undefined, { timeout_ms: 3000 });
    if (alive.status === 200) {
      // The server answers but the socket does not: poll, and try the socket
      // again now and then (at once if it had been working: a hiccup).
      if (this.mode !== "polling") this.setMode("polling", "no WebSocket: polling the API");
      this.pollAll();
      this.later("ws", wasOpen ? RETRY_FIRST_MS : WS_RETRY_WHILE_POLLING_MS, () => this.connectSocket());
      return;
    }
    this.stopPolling();
    this.renderersAvailable = true;  // the server that comes back may list them
    this.setMode("offline", `server not reachable; retrying in ${(this.retry_ms / 1000).toFixed(1)} s`);
    this.later("ws", this.retry_ms, () => this.connectSocket());
    this.retry_ms = Math.min(this.retry_ms * 2, RETRY_MAX_MS);
  }

  onMessage(data) {
    let m;
    try { m = JSON.parse(data); } catch { return; }
    switch (m.type) {
      case "hello": this.h.hello(m); break;
      case "state": this.acceptState(m.state); break;
      case "event": this.h.event(m.event); break;
      case "renderers": this.h.renderers(m.renderers); break;
      case "health": this.h.health(m); break;
      default: break;  // a newer server's message: not ours to read
    }
  }

  acceptState(state) {
    this.lastState = state;
    this.h.state(state);
    // Ramps and drift change the weather between changes: re-read it while
    // they last (the socket only speaks when something is accepted).
    const evolving = state.pending.length > 0 || state.regions.some((r) => r.drifts_with_wind);
    if (evolving && this.mode === "live") this.later("evolving", REFRESH_EVOLVING_MS, () => this.refreshState());
  }

  async refreshState() {
    const r = await request("GET", "/api/state");
    if (r.ok) this.acceptState(r.body);
  }

  async loadEvents() {
    const r = await request("GET", "/api/events?limit=200");
    if (r.ok) this.h.events(r.body.events);
  }

  // Polling: each kind on its own period; a failure hands over to
  // socketFailed, which decides between polling on and offline.
  pollAll() {
    this.pollState();
    this.pollEvents();
    this.pollRenderers();
    this.pollHealth();
  }

  async pollState() {
    if (this.mode !== "polling") return;
    const r = await request("GET", "/api/state");
    if (this.mode !== "polling") return;
    if (!r.ok) return this.pollFailed();
    this.lastState = r.body;
    this.h.state(r.body);
    this.later("state", POLL_STATE_MS, () => this.pollState());
  }

  async pollEvents() {
    if (this.mode !== "polling") return;
    const seq = this.lastState ? this.lastState.sequence : null;
    if (seq !== this.lastSequence) {
      const r = await request("GET", "/api/events?limit=200");
      if (this.mode !== "polling") return;
      if (!r.ok) return this.pollFailed();
      this.lastSequence = seq;
      this.h.events(r.body.events);
    }
    this.later("events", POLL_EVENTS_MS, () => this.pollEvents());
  }

  async pollRenderers() {
    if (this.mode !== "polling" || !this.renderersAvailable) return;
    const r = await request("GET", "/api/renderers");
    if (this.mode !== "polling") return;
    if (r.status === 404) {
      // A server without the renderer list: say so once, do not ask again.
      this.renderersAvailable = false;
      this.h.renderers(null);
      return;
    }
    if (!r.ok) return this.pollFailed();
    this.h.renderers(Array.isArray(r.body) ? r.body : r.body.renderers || []);
    this.later("renderers", POLL_RENDERERS_MS, () => this.pollRenderers());
  }

  async pollHealth() {
    if (this.mode !== "polling") return;
    const r = await request("GET", "/metrics");
    if (this.mode !== "polling") return;
    if (!r.ok) return this.pollFailed();
    this.h.health(healthFromMetrics(String(r.body)));
    this.later("health", POLL_HEALTH_MS, () => this.pollHealth());
  }

  pollFailed() {
    if (this.mode !== "polling") return;
    this.stopPolling();
    clearTimeout(this.timers.get("ws"));
    this.socketFailed(false);
  }
}
