// The weather clock and the timeline: the clock now (extrapolated between
// states at its rate), pause and rates x1/x10/x60, a jump to a time, loading a
// scenario file (POST /api/scenario: its start replaces the weather, its
// timeline is scheduled), and what is scheduled or ramping next (the state's
// pending changes) on a bar timeline and as a list.
import { request, session } from "./api.js";
import { $, el, note, showErrors } from "./dom.js";
import { clockText, parseClock } from "./units.js";

const RATES = [0, 1, 10, 60];
// The timeline shows at least this much clock ahead (s), more when a
// pending change ends later.
const TIMELINE_MIN_S = 3600;

export class ClockPanel {
  // app: {clockNow(), state(), submit(changes, form, keys, note), canEdit()}
  constructor(root, app) {
    this.root = root;
    this.app = app;
    for (const rate of RATES) {
      const b = $(`[data-rate="${rate}"]`, root);
      b.addEventListener("click", () => this.setRate(rate));
    }
    $("#clock-jump-form", root).addEventListener("submit", (e) => { e.preventDefault(); this.jump(); });
    $("#scenario-form", root).addEventListener("submit", (e) => { e.preventDefault(); this.loadScenario(); });
    setInterval(() => this.tick(), 250);
  }

  async setRate(rate) {
    await this.app.submit([{ op: "set_clock", rate }], $("#clock-jump-form", this.root), { rate: "jump" },
      $(".note", this.root));
  }

  async jump() {
    const form = $("#clock-jump-form", this.root);
    const t = parseClock($('[name="jump"]', form).value);
    if (!Number.isFinite(t)) {
      showErrors(form, { jump: "a clock time (12:30, 12:30:00, 1d 06:00) or seconds" });
      return;
    }
    showErrors(form, {});
    await this.app.submit([{ op: "set_clock", jump_to_s: t }], form, { jump_to_s: "jump" }, $(".note", this.root));
  }

  // Reads the chosen TOML file in the browser (no upload of anything but its
  // text) and asks the server to load it; its refusal names file and line.
  async loadScenario() {
    const form = $("#scenario-form", this.root);
    const errors = $("#scenario-error", this.root);
    const noteEl = $(".note", this.root);
    const file = $('[name="scenario"]', form).files[0];
    const refuse = (text) => {
      errors.textContent = text;
      $('[name="scenario"]', form).setAttribute("aria-invalid", "true");
      note(noteEl, "scenario not loaded: nothing changed", "bad");
    };
    errors.textContent = "";
    $('[name="scenario"]', form).removeAttribute("aria-invalid");
    if (!file) return refuse("choose a scenario file (.toml) first");
    if (file.size > 1 << 20) return refuse(`${file.name}: ${file.size} bytes, at most 1 MiB`);
    if (!this.app.canEdit()) return note(noteEl, "read-only: enter the token first", "bad");
    note(noteEl, `loading ${file.name}…`, "busy");
    const r = await request("POST", "/api/scenario", { toml: await file.text(), name: file.name, author: session.author() },
      { auth: true });
    if (r.ok) {
      note(noteEl, `loaded ${file.name} (#${r.body.sequence}): ${r.body.layers} layer(s), ` +
        `${r.body.timeline} timeline entr${r.body.timeline === 1 ? "y" : "ies"}`, "ok");
      this.app.changed(r);
    } else if (r.status === 401) {
      this.app.tokenRefused();
      note(noteEl, "the server refused the token: read-only now; nothing applied", "bad");
    } else if (r.status === 404) {
      refuse("this server cannot load scenarios (no POST /api/scenario)");
    } else {
      refuse(r.body.error || `HTTP ${r.status}`);
    }
  }

  tick() {
    const s = this.app.state();
    if (!s) return;
    $("#clock-now", this.root).textContent = clockText(this.app.clockNow());
    $("#clock-rate", this.root).textContent = s.clock_rate === 0 ? "paused" : `×${s.clock_rate}`;
    for (const rate of RATES) $(`[data-rate="${rate}"]`, this.root).classList.toggle("active", s.clock_rate === rate);
    this.renderTimeline(s);
  }

  renderTimeline(s) {
    const now = this.app.clockNow();
    const pending = [...s.pending].sort((a, b) => a.start_s - b.start_s);
    const end = Math.max(now + TIMELINE_MIN_S, ...pending.map((p) => p.end_s));
    const span = end - now;
    const bars = $("#timeline-bars", this.root);
    const pct = (t) => `${(100 * Math.max(0, Math.min(1, (t - now) / span))).toFixed(2)}%`;
    bars.replaceChildren(
      ...pending.map((p, i) => el("div", {
        class: `bar${p.start_s <= now ? " running" : ""}`, title: p.summary,
        style: { left: pct(p.start_s), width: `max(3px, calc(${pct(p.end_s)} - ${pct(p.start_s)}))`, top: `${(i % 4) * 9 + 2}px` },
      })),
      el("span", { class: "tick", style: { left: "0" } }, "now"),
      el("span", { class: "tick mid", style: { left: "50%" } }, clockText(now + span / 2)),
      el("span", { class: "tick end" }, clockText(end)));
    const list = $("#timeline-list", this.root);
    const key = JSON.stringify(pending.map((p) => [p.sequence, p.start_s <= now]));
    if (key === this.listKey && list.children.length) {
      // Only the countdowns change between states.
      [...list.children].forEach((li, i) => { if (pending[i]) li.firstChild.textContent = this.when(pending[i], now); });
      return;
    }
    this.listKey = key;
    list.replaceChildren(...(pending.length ? pending.map((p) => el("li", {},
      el("span", { class: "when" }, this.when(p, now)), p.kind === "timeline" ? el("span", { class: "badge" }, "scenario") : "",
      ` #${p.sequence} ${p.summary}`))
      : [el("li", { class: "muted" }, "nothing scheduled")]));
  }

  when(p, now) {
    const rate = this.app.state().clock_rate;
    if (p.start_s > now) {
      const wall = rate > 0 ? ` (${Math.round((p.start_s - now) / rate)} s wall)` : " (clock paused)";
      return `at ${clockText(p.start_s)}, in ${clockText(p.start_s - now)}${wall}`;
    }
    return `ramping until ${clockText(p.end_s)}`;
  }
}
