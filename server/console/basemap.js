// The map's ground: Natural Earth 1:50m land, coastlines and country borders
// (world-atlas's countries-50m.json, a TopoJSON the build copies next to the
// page, decoded with topojson-client) drawn by Leaflet on one canvas, under
// everything else. The world repeats east and west: the copies a view
// across the antimeridian needs are added as it moves.
// window.L and window.topojson (globalThis: Node.js tests the pure functions
// below without them).
const L = globalThis.L;
const topojson = globalThis.topojson;

const BASEMAP_URL = "/console/countries-50m.json";
// Colours of the dark instructor map: sea is the map container's background.
const LAND_COLOUR = "#27362b";
const COAST_COLOUR = "#8fb3cf";
const BORDER_COLOUR = "#9c8bb0";
// How far beyond the view the ground is drawn (a fraction of the view each
// side, Leaflet's default is 0.1): a short pan shows drawn land at once.
const DRAWN_MARGIN = 0.2;

// Natural Earth cuts rings and lines at the antimeridian, and TopoJSON's
// quantisation joins the cut's two sides again: a ring of Chukotka or Fiji
// steps from 179.9 to -180 and back, which Leaflet would draw as a band round
// the whole world. A step of more than 180 degrees is such a cut.
const isCut = (a, b) => Math.abs(b[0] - a[0]) > 180;

// A ring made continuous across the cut (longitudes past +-180), unless it
// goes round a pole (Antarctica), which is right as it is within +-180.
export function unwrapRing(ring) {
  let winding = 0;
  for (let i = 1; i < ring.length; ++i) {
    const d = ring[i][0] - ring[i - 1][0];
    winding += d - 360 * Math.round(d / 360);
  }
  if (Math.abs(winding) > 180) return ring;
  let shift = 0;
  return ring.map((p, i) => {
    if (i > 0 && isCut(ring[i - 1], p)) shift -= 360 * Math.sign(p[0] - ring[i - 1][0]);
    return shift ? [p[0] + shift, p[1]] : p;
  });
}

// A line split where it steps across the cut (each piece stays on its side).
export function splitLine(line) {
  const pieces = [[line[0]]];
  for (let i = 1; i < line.length; ++i) {
    if (isCut(line[i - 1], line[i])) pieces.push([]);
    pieces[pieces.length - 1].push(line[i]);
  }
  return pieces.filter((p) => p.length > 1);
}

function unwrapPolygons(collection) {
  for (const f of collection.features) {
    const g = f.geometry;
    if (g.type === "Polygon") g.coordinates = g.coordinates.map(unwrapRing);
    if (g.type === "MultiPolygon") g.coordinates = g.coordinates.map((p) => p.map(unwrapRing));
  }
  return collection;
}

function splitLines(multiLine) {
  return { type: "MultiLineString", coordinates: multiLine.coordinates.flatMap(splitLine) };
}

export class BaseMap {
  // map: the Leaflet map; pane: the pane to draw in.
  constructor(map, pane) {
    this.map = map;
    this.renderer = L.canvas({ pane, padding: DRAWN_MARGIN });
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
    const land = unwrapPolygons(topojson.feature(topo, topo.objects.land));
    // The land's outline is the coastline; arcs shared by two countries are borders.
    const coast = splitLines(topojson.mesh(topo, topo.objects.land));
    const borders = splitLines(topojson.mesh(topo, topo.objects.countries, (a, b) => a !== b));
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
