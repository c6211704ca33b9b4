// The METAR stations on the map (GET /api/metar/stations): a dot per station
// of the server's table (and any a request brought), coloured by the flight
// category of its latest applied report (flight_category.js), grey without
// one; a click opens the report and the layers it became.
import { el } from "./dom.js";
import { categoryFromLayers, flightCategory } from "./flight_category.js";
import { normalizeLon } from "./geo.js";
import { fmt, ftFromM, OKTAS } from "./units.js";

const L = window.L;

// What a category means, for the popup and the legend.
const CATEGORY_TEXT = {
  VFR: "VFR: ceiling above 3000 ft and visibility above 5 SM",
  MVFR: "MVFR: ceiling 1000-3000 ft or visibility 3-5 SM",
  IFR: "IFR: ceiling 500-999 ft or visibility 1-3 SM",
  LIFR: "LIFR: ceiling below 500 ft or visibility below 1 SM",
};

function layerText(l) {
  return `${l.type} ${fmt(l.coverage * OKTAS, 1)}/8 ${fmt(ftFromM(l.base_m))}–${fmt(ftFromM(l.base_m + l.thickness_m))} ft MSL`;
}

// The popup of a station: its report and the layers it became (the ones
// with cloud: the zero-coverage copies of the global layers only clear the
// sky round the station and are summed up in one line).
function popupContent(s, category) {
  const head = el("div", { class: "station-head" }, el("b", {}, s.icao),
    ` ${fmt(s.lat_deg, 4)}°, ${fmt(s.lon_deg, 4)}°, ${fmt(s.elevation_m)} m`);
  if (!s.report) return el("div", { class: "station-popup" }, head, el("div", { class: "muted" }, "no report applied"));
  const r = s.report;
  const cloudy = r.layers.filter((l) => l.coverage > 0);
  const cleared = r.layers.length - cloudy.length;
  return el("div", { class: "station-popup" }, head,
    el("div", { class: `station-category cat-${category || "none"}` }, category ? CATEGORY_TEXT[category] : "category unknown"),
    r.text !== null ? el("code", { class: "station-report" }, r.text)
      : el("div", { class: "muted" }, "the report's text is gone (the server restarted since); category from its layers' ceiling"),
    el("div", { class: "muted" }, r.sequence !== null ? `applied #${r.sequence} as region ${r.region_id}` : `region ${r.region_id}`),
    r.sky === "not_observed" ? el("div", {}, "sky not observed: the weather there stays as it was")
      : el("ul", { class: "station-layers" }, ...(cloudy.length ? cloudy.map((l) => el("li", {}, `layer ${l.id}: ${layerText(l)}`))
        : [el("li", {}, "clear sky")]),
      cleared ? el("li", { class: "muted" }, `${cleared} other layer(s) at 0/8 round the station`) : null));
}

export class StationLayer {
  constructor(map) {
    this.map = map;
    this.group = L.layerGroup().addTo(map);
    this.markers = new Map();  // ICAO -> {marker, el, key}
    this.ref_deg = 0;
    this.list = [];
    this.checked = new Map();  // ICAO -> the last conformance check's row for it
  }

  // The conformance check's rows (GET /api/conformance's stations): each
  // checked station's marker says whether what the renderers draw there is
  // within tolerance of its report (a yellow ring when it is not).
  conformance(rows) {
    this.checked = new Map(rows.filter((r) => r.icao).map((r) => [r.icao, r]));
    for (const [icao, m] of this.markers) this.markConformance(icao, m);
  }

  markConformance(icao, m) {
    const row = this.checked.get(icao);
    m.el.dataset.conformance = row ? (row.ok ? "ok" : "off") : "";
    m.el.title = m.el.dataset.titleBase + (!row ? ""
      : row.ok ? "; drawn as reported" : `; drawn ${row.oktas_off}/8 off its report`);
  }

  show(on) {
    if (on) this.group.addTo(this.map);
    else this.group.remove();
  }

  // The stations as GET /api/metar/stations lists them.
  update(list) {
    this.list = list;
    const seen = new Set();
    for (const s of list) {
      seen.add(s.icao);
      // From the report, or from its region's layers when the server no
      // longer has the text (it restarted since).
      const category = !s.report ? null
        : s.report.text !== null ? flightCategory(s.report.text) : categoryFromLayers(s.report.layers, s.elevation_m);
      const key = JSON.stringify([s, category]);
      let m = this.markers.get(s.icao);
      if (!m) {
        const dot = el("span", { class: "station-dot" });
        const label = el("span", { class: "station-label" }, s.icao);
        const root = el("div", { class: "station", dataset: { icao: s.icao } }, dot, label);
        m = { el: root, key: "", marker: L.marker([s.lat_deg, s.lon_deg], { keyboard: false, riseOnHover: true,
          icon: L.divIcon({ className: "station-icon", html: root, iconSize: [14, 14], iconAnchor: [7, 7] }) }) };
        m.marker.bindPopup("", { className: "station-popup-wrap", maxWidth: 360 });
        this.markers.set(s.icao, m);
        this.group.addLayer(m.marker);
      }
      if (m.key === key) continue;
      m.key = key;
      m.el.className = `station cat-${category || "none"}`;
      m.el.dataset.category = category || "";
      m.el.dataset.titleBase = `${s.icao}: ${category || (s.report ? "category unknown" : "no report applied")}`;
      this.markConformance(s.icao, m);
      m.marker.setLatLng([s.lat_deg, this.ref_deg + normalizeLon(s.lon_deg - this.ref_deg)]);
      m.marker.setPopupContent(popupContent(s, category));
    }
    for (const [icao, m] of this.markers) {
      if (seen.has(icao)) continue;
      this.group.removeLayer(m.marker);
      this.markers.delete(icao);
    }
  }

  // Keeps every marker within 180 degrees of the view's centre longitude.
  follow(ref_deg) {
    this.ref_deg = ref_deg;
    for (const s of this.list) {
      const m = this.markers.get(s.icao);
      if (m) m.marker.setLatLng([s.lat_deg, ref_deg + normalizeLon(s.lon_deg - ref_deg)]);
    }
  }
}
