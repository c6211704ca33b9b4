// Small DOM helpers shared by the console's panels: building elements,
// paired inputs of two units, and errors shown next to their fields.
import { fmt, num } from "./units.js";

// el("div", {class: "x", onclick: f}, child, "text", ...)
export function el(tag, attrs = {}, ...children) {
  const e = document.createElement(tag);
  for (const [k, v] of Object.entries(attrs)) {
    if (v === undefined || v === null || v === false) continue;
    if (k.startsWith("on")) e.addEventListener(k.slice(2), v);
    else if (k === "class") e.className = v;
    else if (k === "dataset") Object.assign(e.dataset, v);
    // Through CSSOM: the page's CSP allows no inline style attributes.
    else if (k === "style") Object.assign(e.style, v);
    else e.setAttribute(k, v === true ? "" : v);
  }
  for (const c of children.flat()) if (c !== null && c !== undefined && c !== false) e.append(c);
  return e;
}

export const $ = (sel, root = document) => root.querySelector(sel);
export const $$ = (sel, root = document) => [...root.querySelectorAll(sel)];

// Two inputs showing one value in two units (metres and feet): typing in
// either updates the other. value() is in the first unit, taken from the
// input typed in last, so 5000 ft stays exactly 1524 m.
export class UnitPair {
  constructor(a, b, toB, toA, digitsA, digitsB) {
    Object.assign(this, { a, b, toB, toA, digitsA, digitsB, last: "a" });
    a.addEventListener("input", () => {
      this.last = "a";
      const v = num(a.value);
      b.value = Number.isFinite(v) ? fmt(toB(v), digitsB) : "";
    });
    b.addEventListener("input", () => {
      this.last = "b";
      const v = num(b.value);
      a.value = Number.isFinite(v) ? fmt(toA(v), digitsA) : "";
    });
  }
  value() {
    return this.last === "b" ? this.toA(num(this.b.value)) : num(this.a.value);
  }
  set(v) {
    this.last = "a";
    this.a.value = fmt(v, this.digitsA);
    this.b.value = fmt(this.toB(v), this.digitsB);
  }
}

// Shows {field: message} next to the fields of `root` (elements with
// data-err="field"); `general` (data-err="form") takes the rest. Clears the
// others. Marks the inputs of a refused field (aria-invalid).
export function showErrors(root, errors) {
  const known = new Set();
  for (const span of $$("[data-err]", root)) {
    const f = span.dataset.err;
    known.add(f);
    span.textContent = errors[f] || "";
  }
  const rest = Object.entries(errors).filter(([f]) => !known.has(f)).map(([, m]) => m);
  const general = $('[data-err="form"]', root);
  if (general && rest.length) general.textContent = rest.join("; ");
  for (const input of $$("[data-field]", root)) {
    if (errors[input.dataset.field]) input.setAttribute("aria-invalid", "true");
    else input.removeAttribute("aria-invalid");
  }
}

// A short-lived note under a form: what was applied, or why not.
export function note(target, text, kind = "ok") {
  target.textContent = text;
  target.className = `note ${kind}`;
}
