// The region tool's form: a storm cell or a clearing placed on the map (or an
// existing region picked there), its shape (CIGI Environmental Region
// Control: centre, size, corner radius, rotation, transition perimeter), its
// layers, and apply / remove, at once or as a ramp. The map draws the draft
// from this form and drags its size and transition handles into it.
import { $, el, showErrors } from "./dom.js";
import { checkRegion, checkTiming, CLOUD_TYPES, fmt, num, parseClock } from "./units.js";

export const REGION_KEYS = {
  id: "id", center_lat_deg: "lat", center_lon_deg: "lon", size_x_m: "sizeX", size_y_m: "sizeY",
  corner_radius_m: "corner", rotation_deg: "rotation", transition_m: "transition", drifts_with_wind: "drifts",
  layers: "layers", ramp_s: "ramp", at_s: "at", region: "form",
};

// Defaults for a click without a drag: a storm cell is a round 10 km cell
// with a 4 km perimeter; a clearing a round 30 km hole with a 10 km one.
const STORM = { size_m: 10000, transition_m: 4000 };
const CLEARING = { size_m: 30000, transition_m: 10000 };
// A storm cell's cloud: cumulonimbus from 900 m to 9900 m, nearly overcast,
// in a 12 m/s south-westerly (docs/operating.md's example storm cell).
const STORM_LAYER = { type: "cumulonimbus", base_m: 900, thickness_m: 9000, transition_band_m: 200, coverage: 0.9,
  density: 1, wind: { speed_mps: 12, from_deg: 250, vertical_mps: 0 } };

export class RegionPanel {
  // app: {state(), allLayerIds(), clockNow(), submit(...), canEdit(), redraw()}
  constructor(root, app) {
    this.root = root;
    this.app = app;
    this.form = $("#region-form", root);
    this.f = (name) => $(`[name="${name}"]`, this.form);
    this.layers = [];        // the draft's layers (API units)
    this.selectedId = null;  // an existing region being edited, or null for a new one
    this.active = false;     // whether there is a draft at all
    this.form.addEventListener("submit", (e) => { e.preventDefault(); this.apply(); });
    this.form.addEventListener("input", () => { this.readLayers(); this.check(); this.app.redraw(); });
    $("#region-remove", root).addEventListener("click", () => this.remove());
    $("#region-cancel", root).addEventListener("click", () => this.cancel());
    $("#region-add-layer", root).addEventListener("click", () => {
      this.readLayers();
      this.layers.push({ ...STORM_LAYER, wind: { ...STORM_LAYER.wind }, id: this.freeLayerId() });
      this.renderLayers();
      this.check();
    });
    this.showActive();
  }

  freeLayerId() {
    const used = new Set([...this.app.allLayerIds(), ...this.layers.map((l) => l.id)]);
    let id = 1;
    while (used.has(id)) ++id;
    return id;
  }

  freeRegionId() {
    const used = new Set(this.app.state().regions.map((r) => r.id));
    let id = 1;
    while (used.has(id)) ++id;
    return id;
  }

  // A new draft at (lat, lon); half_m: half its size, or null for the default.
  place(kind, lat_deg, lon_deg, half_m = null) {
    const d = kind === "clearing" ? CLEARING : STORM;
    const size_m = half_m ? 2 * half_m : d.size_m;
    this.selectedId = null;
    this.kind = kind;
    this.layers = kind === "clearing"
      // A clearing: every global layer at coverage 0 inside (same ids replace them).
      ? this.app.state().layers.map((l) => ({ ...l, wind: { ...l.wind }, coverage: 0 }))
      : [{ ...STORM_LAYER, wind: { ...STORM_LAYER.wind }, id: this.freeLayerId() }];
    this.fill({
      id: this.freeRegionId(), center_lat_deg: lat_deg, center_lon_deg: lon_deg, size_x_m: size_m, size_y_m: size_m,
      corner_radius_m: size_m / 2, rotation_deg: 0, transition_m: half_m ? half_m * (d.transition_m / d.size_m) * 2 : d.transition_m,
      drifts_with_wind: false,
    });
    $("#region-title", this.root).textContent = kind === "clearing" ? "New clearing" : "New storm cell";
  }

  // Edit an existing region (picked on the map).
  edit(id) {
    const r = this.app.state().regions.find((x) => x.id === id);
    if (!r) return;
    this.selectedId = id;
    this.kind = r.layers.length && r.layers.every((l) => l.coverage === 0) ? "clearing" : "region";
    this.layers = r.layers.map((l) => ({ ...l, wind: { ...l.wind } }));
    this.fill(r);
    $("#region-title", this.root).textContent = `Region ${id}`;
  }

  fill(r) {
    this.active = true;
    this.f("id").value = String(r.id);
    this.f("lat").value = fmt(r.center_lat_deg, 5);
    this.f("lon").value = fmt(r.center_lon_deg, 5);
    this.setShape(r);
    this.f("rotation").value = fmt(r.rotation_deg || 0, 1);
    this.f("drifts").checked = !!r.drifts_with_wind;
    this.renderLayers();
    showErrors(this.form, {});
    $(".note", this.root).textContent = "";
    this.showActive();
    this.check();
    this.app.redraw();
  }

  // Size, corner and perimeter from the map's handles (metres).
  setShape(s) {
    if (s.size_x_m !== undefined) this.f("size_x").value = fmt(s.size_x_m / 1000, 2);
    if (s.size_y_m !== undefined) this.f("size_y").value = fmt(s.size_y_m / 1000, 2);
    if (s.corner_radius_m !== undefined) this.f("corner").value = fmt(s.corner_radius_m / 1000, 2);
    if (s.transition_m !== undefined) this.f("transition").value = fmt(s.transition_m / 1000, 2);
  }

  reshape(s) {
    this.setShape(s);
    this.check();
    this.app.redraw();
  }

  showActive() {
    $("#region-empty", this.root).hidden = this.active;
    this.form.hidden = !this.active;
    $("#region-remove", this.root).hidden = this.selectedId === null;
  }

  cancel() {
    this.active = false;
    this.selectedId = null;
    this.showActive();
    this.app.redraw();
  }

  renderLayers() {
    const tbody = $("#region-layers tbody", this.root);
    const row = (l, i) => {
      const input = (key, value, attrs = {}) => el("input", { dataset: { k: key, i: String(i) }, value: String(value), inputmode: "decimal", ...attrs });
      const type = el("select", { dataset: { k: "type", i: String(i) } }, ...CLOUD_TYPES.map((t) => el("option", { value: t, selected: t === l.type }, t)));
      return el("tr", {},
        el("td", {}, input("id", l.id, { size: 3 })), el("td", {}, type),
        el("td", {}, input("coverage", fmt(l.coverage * 100, 1), { size: 4 })),
        el("td", {}, input("base_m", fmt(l.base_m), { size: 5 })),
        el("td", {}, input("top_m", fmt(l.base_m + l.thickness_m), { size: 5 })),
        el("td", {}, input("speed", fmt(l.wind.speed_mps, 1), { size: 3 })),
        el("td", {}, input("from", fmt(l.wind.from_deg), { size: 3 })),
        el("td", {}, el("button", { type: "button", class: "small edit", title: "remove this layer from the region",
          onclick: () => { this.readLayers(); this.layers.splice(i, 1); this.renderLayers(); this.check(); } }, "×")));
    };
    tbody.replaceChildren(...this.layers.map(row));
    for (const b of tbody.querySelectorAll("input, select, button")) b.disabled = !this.app.canEdit();
  }

  // The layer rows back into this.layers (API units; other values kept).
  readLayers() {
    for (const input of this.root.querySelectorAll("#region-layers [data-k]")) {
      const l = this.layers[Number(input.dataset.i)];
      if (!l) continue;
      const v = input.dataset.k === "type" ? input.value : num(input.value);
      switch (input.dataset.k) {
        case "id": l.id = v; break;
        case "type": l.type = v; break;
        case "coverage": l.coverage = v / 100; break;
        case "base_m": { const top = l.base_m + l.thickness_m; l.base_m = v; l.thickness_m = top - v; break; }
        case "top_m": l.thickness_m = v - l.base_m; break;
        case "speed": l.wind.speed_mps = v; break;
        case "from": l.wind.from_deg = v; break;
        default: break;
      }
    }
  }

  // The draft as an API region, or null when there is none.
  draft() {
    if (!this.active) return null;
    return {
      id: num(this.f("id").value), center_lat_deg: num(this.f("lat").value), center_lon_deg: num(this.f("lon").value),
      size_x_m: num(this.f("size_x").value) * 1000, size_y_m: num(this.f("size_y").value) * 1000,
      corner_radius_m: num(this.f("corner").value) * 1000, rotation_deg: num(this.f("rotation").value),
      transition_m: num(this.f("transition").value) * 1000, drifts_with_wind: this.f("drifts").checked,
      layers: this.layers.map((l) => ({ ...l, wind: { ...l.wind } })),
    };
  }

  timing() {
    const ramp_s = this.f("ramp").value.trim() === "" ? 0 : num(this.f("ramp").value);
    const atText = this.f("at").value.trim();
    return { ramp_s, at_s: atText === "" ? null : parseClock(atText) };
  }

  check() {
    const d = this.draft();
    if (!d) return false;
    const t = this.timing();
    const errors = { ...checkRegion(d), ...checkTiming(t.ramp_s, t.at_s, this.app.clockNow()) };
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
    this.readLayers();
    if (!this.check()) return;
    const region = this.draft();
    const r = await this.app.submit([this.withTiming({ op: "set_region", region })], this.form, REGION_KEYS,
      $(".note", this.root));
    if (r.ok) {
      this.selectedId = region.id;
      $("#region-title", this.root).textContent = `Region ${region.id}`;
      this.showActive();
    }
  }

  async remove() {
    if (this.selectedId === null) return;
    const t = this.timing();
    const r = await this.app.submit([this.withTiming({ op: "remove_region", id: this.selectedId })], this.form,
      REGION_KEYS, $(".note", this.root));
    if (r.ok) this.cancel();
  }
}
