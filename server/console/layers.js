// The layer table and editor: every global layer with its values in both
// units, and a form that adds or changes one (at once or as a ramp) or
// removes it. A draft is checked here first (units.js); what the server
// still refuses comes back next to the field it names.
import { $, el, showErrors, UnitPair } from "./dom.js";
import {
  checkLayer, checkTiming, CLOUD_TYPES, fmt, ftFromM, ktFromMps, mFromFt, mpsFromKt, num, OKTAS, parseClock,
} from "./units.js";

// API keys (as the server names them) to the editor's fields.
export const LAYER_KEYS = {
  id: "id", type: "type", coverage: "coverage", base_m: "base", thickness_m: "top", transition_band_m: "transition",
  density: "density", "wind.speed_mps": "windSpeed", speed_mps: "windSpeed", "wind.from_deg": "windFrom",
  from_deg: "windFrom", "wind.vertical_mps": "windVertical", vertical_mps: "windVertical", ramp_s: "ramp",
  at_s: "at", wind: "windSpeed",
};

export const DEFAULT_LAYER = {
  type: "cumulus", base_m: 1500, thickness_m: 1500, transition_band_m: 100, coverage: 0.5, density: 1,
  wind: { speed_mps: 10, from_deg: 270, vertical_mps: 0 },
};

export class LayerPanel {
  // app: {clockNow(), submit(changes, form, keys, noteEl), onSelect(id)}
  constructor(root, app) {
    this.root = root;
    this.app = app;
    this.form = $("#layer-form", root);
    this.tbody = $("#layer-table tbody", root);
    this.selectedId = null;
    this.state = null;
    const f = (name) => $(`[name="${name}"]`, this.form);
    this.f = f;
    const type = f("type");
    for (const t of CLOUD_TYPES) type.append(el("option", { value: t }, t));
    this.coverage = new UnitPair(f("coverage_pct"), f("coverage_oktas"), (p) => (p / 100) * OKTAS,
      (o) => (o / OKTAS) * 100, 1, 2);
    this.base = new UnitPair(f("base_m"), f("base_ft"), ftFromM, mFromFt, 1, 0);
    this.top = new UnitPair(f("top_m"), f("top_ft"), ftFromM, mFromFt, 1, 0);
    this.wind = new UnitPair(f("wind_mps"), f("wind_kt"), ktFromMps, mpsFromKt, 2, 1);
    this.form.addEventListener("submit", (e) => { e.preventDefault(); this.apply(); });
    $("#layer-remove", root).addEventListener("click", () => this.remove());
    $("#layer-new", root).addEventListener("click", () => this.newLayer());
    $("#layer-revert", root).addEventListener("click", () => this.select(this.selectedId));
    // Each keystroke re-checks the draft, so a bad value is named at once.
    this.form.addEventListener("input", () => this.check());
  }

  render(state) {
    this.state = state;
    const ramping = new Set();
    for (const p of state.pending) {
      const m = /^layer (\d+)/.exec(p.summary);
      if (m) ramping.add(Number(m[1]));
    }
    // Each value in both units, one above the other.
    const two = (a, b) => el("td", { class: "num" }, el("div", {}, a), el("div", { class: "muted" }, b));
    this.tbody.replaceChildren(...state.layers.map((l) => el("tr", {
      class: l.id === this.selectedId ? "selected" : "", dataset: { id: String(l.id) },
      onclick: () => this.select(l.id),
    },
    el("td", {}, String(l.id), ramping.has(l.id) ? el("span", { class: "badge", title: "a change is ramping or scheduled" }, "ramp") : ""),
    el("td", {}, l.type),
    two(`${fmt(l.coverage * 100)} %`, `${fmt(l.coverage * OKTAS, 1)} oktas`),
    two(`${fmt(l.base_m)} m`, `${fmt(ftFromM(l.base_m))} ft`),
    two(`${fmt(l.base_m + l.thickness_m)} m`, `${fmt(ftFromM(l.base_m + l.thickness_m))} ft`),
    el("td", { class: "num" }, fmt(l.density, 2)),
    two(`${fmt(l.wind.speed_mps, 1)} m/s · ${fmt(ktFromMps(l.wind.speed_mps))} kt`,
      `from ${fmt(l.wind.from_deg)}°${l.wind.vertical_mps ? `, ${l.wind.vertical_mps > 0 ? "+" : ""}${fmt(l.wind.vertical_mps, 1)} m/s` : ""}`))));
    if (!state.layers.length) this.tbody.append(el("tr", {}, el("td", { colspan: 7, class: "muted" }, "no global layers: clear sky")));
    if (!this.initialized) {
      this.initialized = true;
      if (state.layers.length) this.select(state.layers[0].id);
      else this.newLayer();
    } else if (!this.dirty && this.selectedId !== null) {
      // An untouched form follows the server (another console's change).
      const l = state.layers.find((x) => x.id === this.selectedId);
      if (l) this.fill(l);
    }
  }

  fill(l) {
    this.f("id").value = String(l.id);
    this.f("type").value = l.type;
    this.coverage.set(l.coverage * 100);
    this.base.set(l.base_m);
    this.top.set(l.base_m + l.thickness_m);
    this.f("transition").value = fmt(l.transition_band_m, 1);
    this.f("density").value = fmt(l.density, 3);
    this.wind.set(l.wind.speed_mps);
    this.f("wind_from").value = fmt(l.wind.from_deg, 1);
    this.f("wind_vertical").value = fmt(l.wind.vertical_mps, 2);
    showErrors(this.form, {});
    this.dirty = false;
  }

  select(id) {
    const l = this.state && this.state.layers.find((x) => x.id === id);
    if (!l) return this.newLayer();
    this.selectedId = id;
    this.fill(l);
    $(".note", this.root).textContent = "";
    $("#layer-editor-title", this.root).textContent = `Layer ${id}`;
    $("#layer-remove", this.root).disabled = !this.app.canEdit();
    for (const tr of this.tbody.children) tr.classList.toggle("selected", tr.dataset.id === String(id));
    this.app.onSelect(id);
  }

  newLayer() {
    const ids = this.state ? this.app.allLayerIds() : [];
    const id = ids.length ? Math.max(...ids) + 1 : 1;
    this.selectedId = null;
    this.fill({ id, ...DEFAULT_LAYER });
    $("#layer-editor-title", this.root).textContent = `New layer ${id}`;
    $("#layer-remove", this.root).disabled = true;
    for (const tr of this.tbody.children) tr.classList.remove("selected");
  }

  // The form as an API layer.
  draft() {
    const base_m = this.base.value();
    return {
      id: num(this.f("id").value), type: this.f("type").value, base_m, thickness_m: this.top.value() - base_m,
      transition_band_m: num(this.f("transition").value), coverage: this.coverage.value() / 100,
      density: num(this.f("density").value),
      wind: { speed_mps: this.wind.value(), from_deg: num(this.f("wind_from").value), vertical_mps: num(this.f("wind_vertical").value) },
    };
  }

  timing() {
    const ramp_s = this.f("ramp").value.trim() === "" ? 0 : num(this.f("ramp").value);
    const atText = this.f("at").value.trim();
    return { ramp_s, at_s: atText === "" ? null : parseClock(atText) };
  }

  check() {
    this.dirty = true;
    const t = this.timing();
    const errors = { ...checkLayer(this.draft()), ...checkTiming(t.ramp_s, t.at_s, this.app.clockNow()) };
    showErrors(this.form, errors);
    return Object.keys(errors).length === 0;
  }

  withTiming(change) {
    const t = this.timing();
    if (t.ramp_s > 0) change.ramp_s = t.ramp_s;
    if (t.at_s !== null) change.at_s = t.at_s;
    return change;
  }

  async apply() {
    if (!this.check()) return;
    const layer = this.draft();
    const r = await this.app.submit([this.withTiming({ op: "set_layer", layer })], this.form, LAYER_KEYS,
      $(".note", this.root));
    if (r.ok) {
      this.selectedId = layer.id;
      this.dirty = false;
      $("#layer-editor-title", this.root).textContent = `Layer ${layer.id}`;
    }
  }

  async remove() {
    if (this.selectedId === null) return;
    const t = this.timing();
    const e = checkTiming(t.ramp_s, t.at_s, this.app.clockNow());
    showErrors(this.form, e);
    if (Object.keys(e).length) return;
    const r = await this.app.submit([this.withTiming({ op: "remove_layer", id: this.selectedId })], this.form,
      LAYER_KEYS, $(".note", this.root));
    if (r.ok && !(t.ramp_s > 0) && t.at_s === null) this.selectedId = null;
  }
}
