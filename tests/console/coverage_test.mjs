// The console's own geometry against closed forms, without a browser: the
// sphere's distances, the projection, the region shape and the coverage blend
// the map draws (server/console/geo.js, coverage.js), which must agree with
// the server's (sky/weather/region.hpp: smoothstep across the perimeter;
// snapshot_builder.cpp: the weighted blend into the global layer).
import fs from "node:fs";
import { createRequire } from "node:module";
import { assert, near, run, skip } from "./harness.mjs";


const smoothstep = (t) => t * t * (3 - 2 * t);

run("coverage", async () => {
  // The console's files are ES modules in a folder without a package.json:
  // Node.js reads them as such from 20 on (syntax detection).
  if (Number(process.versions.node.split(".")[0]) < 20) skip(`Node.js 20 or newer needed, this is ${process.version}`);
  const { coverageAt, regionEdgeDistance_m, regionOutline, regionWeight } = await import("../../server/console/coverage.js");
  const { direct, EARTH_RADIUS_M, inverse, Projection } = await import("../../server/console/geo.js");
  // A degree of the equator, due east.
  const eq = inverse(0, 0, 0, 1);
  near(eq.distance_m, (EARTH_RADIUS_M * Math.PI) / 180, 1e-6, "one degree of the equator");
  near(eq.azimuth_deg, 90, 1e-9, "due east");
  // A quarter meridian, due north.
  near(inverse(0, 10, 90, 10).distance_m, (EARTH_RADIUS_M * Math.PI) / 2, 1e-6, "equator to pole");
  // direct() undoes inverse(), and the projection round-trips, across the antimeridian too.
  for (const [lat, lon, az, s] of [[46, 13, 37, 12345], [-33, 179.9, 95, 40000], [80, -120, 200, 250000]]) {
    const p = direct(lat, lon, az, s);
    const back = inverse(lat, lon, p.lat_deg, p.lon_deg);
    near(back.distance_m, s, 1e-6, "direct/inverse distance");
    near(((back.azimuth_deg - az + 540) % 360) - 180, 0, 1e-7, "direct/inverse azimuth");
    const proj = new Projection(lat, lon);
    const xy = proj.forward(p.lat_deg, p.lon_deg);
    near(Math.hypot(xy.x_m, xy.y_m), s, 1e-6, "projected distance is true from the focus");
    const q = proj.inverse(xy.x_m, xy.y_m);
    near(q.lat_deg, p.lat_deg, 1e-9, "projection round trip lat");
    near(((q.lon_deg - p.lon_deg + 540) % 360) - 180, 0, 1e-9, "projection round trip lon");
  }

  // A round cell (corner radius = half its size): the edge is a circle, so
  // the edge distance is the distance from the centre less the radius.
  const cell = { id: 1, center_lat_deg: 46, center_lon_deg: 13, size_x_m: 10000, size_y_m: 10000,
    corner_radius_m: 5000, rotation_deg: 0, transition_m: 4000, layers: [] };
  for (const [s, weight] of [[0, 1], [4999, 1], [5000 + 1000, smoothstep(0.75)], [5000 + 2000, 0.5],
    [5000 + 3000, smoothstep(0.25)], [9001, 0], [50000, 0]]) {
    const p = direct(46, 13, 37, s);
    near(regionEdgeDistance_m(cell, p.lat_deg, p.lon_deg), s - 5000, 1e-6, `edge distance at ${s} m`);
    near(regionWeight(cell, p.lat_deg, p.lon_deg), weight, 1e-9, `weight at ${s} m`);
  }
  // A rotated rectangle: x runs at rotation + 90 degrees, y at rotation.
  const rect = { id: 2, center_lat_deg: 46, center_lon_deg: 13, size_x_m: 8000, size_y_m: 4000,
    corner_radius_m: 0, rotation_deg: 30, transition_m: 2000, layers: [] };
  const along = (az, s) => { const p = direct(46, 13, az, s); return regionEdgeDistance_m(rect, p.lat_deg, p.lon_deg); };
  near(along(120, 5000), 1000, 1e-6, "beyond the x edge");
  near(along(30, 3000), 1000, 1e-6, "beyond the y edge");
  near(along(210, 1000), -1000, 1e-6, "inside, nearest the y edge");
  near(along(30 + (Math.atan2(5000, 3000) * 180) / Math.PI, Math.hypot(5000, 3000)), Math.hypot(1000, 1000), 1e-6,
    "beyond the corner");
  // Outlines lie on the edge and on the perimeter's outer edge.
  for (const [r, grow] of [[cell, 0], [cell, 4000], [rect, 0], [rect, 2000]]) {
    for (const p of regionOutline(r, grow)) near(regionEdgeDistance_m(r, p.lat_deg, p.lon_deg), grow, 0.01, "outline on its edge");
  }

  // The blend: a clearing (coverage 0) in a 0.6 layer is 0.6 - w * 0.6.
  const clearing = { ...cell, layers: [{ id: 1, coverage: 0 }] };
  const state = { layers: [{ id: 1, coverage: 0.6 }], regions: [clearing] };
  for (const [s, w] of [[0, 1], [7000, 0.5], [6000, smoothstep(0.75)], [9500, 0]]) {
    const p = direct(46, 13, 300, s);
    near(coverageAt(state, 1, p.lat_deg, p.lon_deg), 0.6 * (1 - w), 1e-9, `clearing coverage at ${s} m`);
  }
  // A layer only a region has is 0 outside it.
  const storm = { ...cell, layers: [{ id: 6, coverage: 0.9 }] };
  const stormState = { layers: [{ id: 1, coverage: 0.6 }], regions: [storm] };
  near(coverageAt(stormState, 6, 46, 13), 0.9, 1e-12, "storm layer inside");
  const far = direct(46, 13, 0, 20000);
  near(coverageAt(stormState, 6, far.lat_deg, far.lon_deg), 0, 1e-12, "storm layer outside");
  near(coverageAt(stormState, 1, 46, 13), 0.6, 1e-12, "the global layer is untouched by another id");
  // Two overlapping regions: weights summed and capped at 1, values averaged by weight.
  const a = { ...cell, layers: [{ id: 1, coverage: 0.2 }] };
  const b = { ...cell, center_lon_deg: 13.01, layers: [{ id: 1, coverage: 1.0 }] };
  const both = { layers: [{ id: 1, coverage: 0.6 }], regions: [a, b] };
  const mid = direct(46, 13, 90, 0.005 * 111195 * Math.cos((46 * Math.PI) / 180));
  const wa = regionWeight(a, mid.lat_deg, mid.lon_deg), wb = regionWeight(b, mid.lat_deg, mid.lon_deg);
  assert(wa === 1 && wb === 1, "the midpoint is inside both");
  near(coverageAt(both, 1, mid.lat_deg, mid.lon_deg), 0.6, 1e-12, "two full weights: the mean of 0.2 and 1.0");

  // Flight categories (FAA AIM 7-1-7; the station markers' colours) at and
  // across each bound of ceiling and visibility, in metres and statute miles.
  const { flightCategory, readReport } = await import("../../server/console/flight_category.js");
  const cat = (groups) => flightCategory(`METAR LJLJ 221150Z 24008KT ${groups} 12/06 Q1018`);
  for (const [groups, want] of [
    ["9999 FEW025 SCT045 BKN090", "VFR"], ["CAVOK", "VFR"], ["9999 NSC", "VFR"], ["10SM SKC", "VFR"],
    ["9999 BKN031", "VFR"], ["9999 BKN030", "MVFR"], ["9999 OVC010", "MVFR"], ["9999 OVC009", "IFR"],
    ["9999 BKN005", "IFR"], ["9999 BKN004", "LIFR"], ["0800 FG VV002", "LIFR"], ["9999 VV///", "LIFR"],
    ["P6SM SCT010", "VFR"], ["5SM BKN040", "MVFR"], ["6SM BKN040", "VFR"], ["3SM SCT040", "MVFR"],
    ["2 1/2SM BR", "IFR"], ["1SM BR", "IFR"], ["M1SM FG", "LIFR"], ["1/2SM FG OVC002", "LIFR"],
    ["9000 SCT020", "VFR"], ["8000 SCT020", "MVFR"], ["6000 FEW020", "MVFR"], ["4000 BR", "IFR"], ["1700 BR", "IFR"], ["1500 BR", "LIFR"],
    // A ceiling of few/scattered clouds is none; the trend after NOSIG/TEMPO is not the observation.
    ["9999 SCT003", "VFR"], ["9999 FEW030 TEMPO 0500 FG", "VFR"], ["9999 BKN040 RMK OVC002", "VFR"],
    ["4000NE BKN050", "IFR"], ["9999NDV OVC035", "VFR"],
  ]) assert(cat(groups) === want, `'${groups}' is ${cat(groups)}, expected ${want}`);
  assert(flightCategory("METAR LJLJ 221150Z 24008KT ////// 12/06 Q1018") === null, "no sky, no visibility: no category");
  // From a station region's layers alone (after a server restart): the
  // lowest cloud base of 5 oktas or more above the station, the visibility
  // its fog layer's (3.912 / (0.05 x coverage x density) m).
  const { categoryFromLayers } = await import("../../server/console/flight_category.js");
  const layer = (coverage, base_m) => ({ type: "stratus", coverage, base_m, density: 1 });
  const fog = (visibility_m, coverage = 1) => ({ type: "fog", coverage, base_m: 388, density: 3.912 / (0.05 * visibility_m * coverage) });
  assert(categoryFromLayers([layer(1, 388 + 60)], 388) === "LIFR", "stratus 200 ft above the station");
  assert(categoryFromLayers([fog(800)], 388) === "LIFR", "fog of 800 m: under 1 SM");
  assert(categoryFromLayers([fog(4000), layer(0.75, 388 + 365.76)], 388) === "IFR", "mist of 2.5 SM under BKN012");
  assert(categoryFromLayers([fog(7000, 0.5)], 388) === "MVFR", "haze patches: 4.3 SM, fog not a ceiling");
  assert(categoryFromLayers([layer(0.75, 388 + 300), layer(0.19, 388 + 100)], 388) === "IFR", "BKN at 984 ft; FEW below it no ceiling");
  assert(categoryFromLayers([layer(0, 300), layer(0.44, 1000)], 388) === "VFR", "no ceiling: VFR by ceiling");
  assert(categoryFromLayers([layer(1, 388 + 914.4)], 388) === "MVFR", "OVC at 3000 ft");
  const read = readReport("METAR KJFK 221151Z 18012KT 1 3/4SM BR BKN008 OVC015 12/11 A2992");
  near(read.visibility_sm, 1.75, 1e-12, "1 3/4SM");
  assert(read.ceiling_ft === 800, `the lowest broken layer: ${read.ceiling_ft}`);

  // The Natural Earth ground across the antimeridian (basemap.js), on the
  // data the console serves: after unwrapping, no ring steps across the
  // cut but those round the South Pole, and no coast or border line does.
  const { splitLine, unwrapRing } = await import("../../server/console/basemap.js");
  near(unwrapRing([[179, -16], [-179, -16], [-179, -17], [179, -17], [179, -16]])[1][0], 181, 1e-12, "a ring across 180 goes on east");
  assert(splitLine([[170, 65], [179.9, 66], [-180, 66], [-175, 65]]).length === 2, "a line across 180 is split");
  const vendor = new URL("../../server/console/vendor/node_modules/", import.meta.url);
  if (!fs.existsSync(vendor)) skip("the console's map packages are not installed (deploy/setup)");
  const require = createRequire(vendor);
  const topojson = require("topojson-client");
  const topo = JSON.parse(fs.readFileSync(new URL("world-atlas/countries-50m.json", vendor), "utf8"));
  const steps = (points) => points.some((p, i) => i > 0 && Math.abs(p[0] - points[i - 1][0]) > 180);
  let rings = 0, acrossBefore = 0, acrossAfter = 0, polar = 0;
  for (const f of topojson.feature(topo, topo.objects.land).features) {
    const polys = f.geometry.type === "Polygon" ? [f.geometry.coordinates] : f.geometry.coordinates;
    for (const ring of polys.flat()) {
      ++rings;
      if (!steps(ring)) continue;
      ++acrossBefore;
      const u = unwrapRing(ring);
      if (!steps(u)) continue;
      ++acrossAfter;
      if (ring.every((p) => p[1] < -60)) ++polar;
    }
  }
  console.log(`  land: ${rings} rings, ${acrossBefore} across 180, ${acrossAfter} still after unwrapping (${polar} round the pole)`);
  assert(acrossBefore >= 3, "Chukotka, Wrangel Island and Fiji cross 180 in the data");
  assert(acrossAfter === polar, "only rings round the South Pole keep their step");
  const coast = topojson.mesh(topo, topo.objects.land).coordinates.flatMap(splitLine);
  assert(!coast.some(steps), "no coastline steps across 180 after splitting");
});
