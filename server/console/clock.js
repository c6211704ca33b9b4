// The weather clock and the timeline: the clock now (extrapolated between
// states at its rate), pause and rates x1/x10/x60, a jump to a time, and what
// is scheduled or ramping next (the state's pending changes) on a bar
// timeline and as a list.
import { $, el, showErrors } from "./dom.js";
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
      el("span", { class: "when" }, this.when(p, now)), ` #${p.sequence} ${p.summary}`))
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
