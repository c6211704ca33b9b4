// The map's ground: Natural Earth 1:50m land, coastlines and country borders
// (world-atlas's countries-50m.json, a TopoJSON the build copies next to the
// page, decoded with topojson-client) drawn by Leaflet on one canvas, under
// everything else. The world repeats east and west: the copies a view
// across the antimeridian needs are added as it moves.
const L = window.L;
const topojson = window.topojson;

export const BASEMAP_URL = "/console/countries-50m.json";
// Colours of the dark instructor map: sea is the map container's background.
export const LAND_COLOUR = "#27362b";
export const COAST_COLOUR = "#8fb3cf";
const BORDER_COLOUR = "#9c8bb0";

export class BaseMap {
  // map: the Leaflet map; pane: the pane to draw in.
  constructor(map, pane) {
    this.map = map;
    this.renderer = L.canvas({ pane, padding: 0.2 });
    this.copies = new Map();  // longitude offset (deg) -> L.LayerGroup, built once each
    this.onMap = new Set();   // the offsets on the map now
    this.layers = null;       // {land, coast, borders} GeoJSON, once loaded
    this.shown = { land: true, borders: true };
    map.on("moveend", () => this.updateCopies());
  }

  // Fetches and decodes the TopoJSON; resolves when drawn, rejects (with a
  // message) when the file cannot be had.
  async load() {
    const r = await fetch(BASEMAP_URL);
    if (!r.ok) throw new Error(`${BASEMAP_URL}: HTTP ${r.status}`);
    const topo = await r.json();
    const land = topojson.feature(topo, topo.objects.land);
    // The land's outline is the coastline; arcs shared by two countries are borders.
    const coast = topojson.mesh(topo, topo.objects.land);
    const borders = topojson.mesh(topo, topo.objects.countries, (a, b) => a !== b);
    this.layers = { land, coast, borders };
    this.updateCopies();
  }

  show(kind, on) {
    this.shown[kind] = on;
    for (const g of this.copies.values()) this.applyShown(g);
  }

  applyShown(group) {
    for (const [kind, layer] of Object.entries(group.parts)) {
      const on = kind === "coast" ? this.shown.land : this.shown[kind];
      if (on && !group.hasLayer(layer)) group.addLayer(layer);
      if (!on && group.hasLayer(layer)) group.removeLayer(layer);
    }
  }

  copy(offset_deg) {
    const at = (c) => L.latLng(c[1], c[0] + offset_deg);
    const opts = (style) => ({ renderer: this.renderer, interactive: false, coordsToLatLng: at, style });
    const parts = {
      land: L.geoJSON(this.layers.land, opts({ stroke: false, fillColor: LAND_COLOUR, fillOpacity: 1 })),
      coast: L.geoJSON(this.layers.coast, opts({ color: COAST_COLOUR, weight: 1, opacity: 0.9, fill: false })),
      borders: L.geoJSON(this.layers.borders, opts({ color: BORDER_COLOUR, weight: 0.8, opacity: 0.7,
        dashArray: "4 3", fill: false })),
    };
    const group = L.layerGroup();
    group.parts = parts;
    this.applyShown(group);
    return group;
  }

  // The world's copies the view needs: 0, and the one east or west of it
  // when the view reaches past +-180 degrees.
  updateCopies() {
    if (!this.layers) return;
    const b = this.map.getBounds();
    const wanted = new Set([0]);
    for (let k = 1; k <= 2; ++k) {
      if (b.getWest() < -180 * (2 * k - 1)) wanted.add(-360 * k);
      if (b.getEast() > 180 * (2 * k - 1)) wanted.add(360 * k);
    }
    for (const offset of this.onMap) {
      if (wanted.has(offset)) continue;
      this.map.removeLayer(this.copies.get(offset));
      this.onMap.delete(offset);
    }
    for (const offset of wanted) {
      if (this.onMap.has(offset)) continue;
      if (!this.copies.has(offset)) this.copies.set(offset, this.copy(offset));
      this.copies.get(offset).addTo(this.map);
      this.onMap.add(offset);
    }
  }
}
