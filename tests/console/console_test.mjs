// Browser tests of the operator console (server/console/) against a real
// skyshell-weatherd: node console_test.mjs <case>. ctest runs each case as
// its own test (label console); a case that cannot run here (no Chromium, no
// playwright-core) exits 77 and is reported skipped, unless SKY_REQUIRE_DEPS=1
// (deploy/test, which installed both) makes that a failure.
import { execFileSync } from "node:child_process";
import dgram from "node:dgram";
import fs from "node:fs";
import path from "node:path";
import {
  assert, child, config, launch, near, openConsole, run, TOKEN, until, Weatherd,
} from "./harness.mjs";

const R = 6371008.8;  // the console's sphere (mean Earth radius)
const D2R = Math.PI / 180;

// Web Mercator as the tests compute it, independently of the page and of
// Leaflet: the world is 256 * 2^zoom CSS px round the equator, north up.
const worldPx = (zoom) => 256 * 2 ** zoom;
const mercatorY = (lat) => Math.log(Math.tan(Math.PI / 4 + (lat * D2R) / 2));
// Pixel offset (x east, y south) of (lat, lon) from the view's centre.
function offsetPx(lat0, lon0, zoom, lat, lon) {
  const dLon = ((((lon - lon0 + 180) % 360) + 360) % 360) - 180;  // the short way round
  return { x: (dLon / 360) * worldPx(zoom), y: ((mercatorY(lat0) - mercatorY(lat)) / (2 * Math.PI)) * worldPx(zoom) };
}
// The surface point at a pixel offset from the view's centre.
function pointAt(lat0, lon0, zoom, dx, dy) {
  const y = mercatorY(lat0) - (dy * 2 * Math.PI) / worldPx(zoom);
  return { lat: (2 * Math.atan(Math.exp(y)) - Math.PI / 2) / D2R, lon: lon0 + (dx * 360) / worldPx(zoom) };
}
// Metres per CSS px along a parallel at `lat` on the console's sphere.
const metresPerPx = (lat, zoom) => (2 * Math.PI * R * Math.cos(lat * D2R)) / worldPx(zoom);

// Presses at (x0, y0), moves to (x1, y1) in steps, releases.
async function drag(page, x0, y0, x1, y1) {
  await page.mouse.move(x0, y0);
  await page.mouse.down();
  await page.mouse.move((x0 + x1) / 2, (y0 + y1) / 2, { steps: 4 });
  await page.mouse.move(x1, y1, { steps: 4 });
  await page.mouse.up();
}

// The map's centre on the page (CSS px).
async function mapCentre(page) {
  const box = await page.locator("#map").boundingBox();
  return { box, cx: box.x + box.width / 2, cy: box.y + box.height / 2 };
}

// Where (lat, lon) is on the page now (CSS px), from the map's box and the
// view the page reports (#map data-focus, data-zoom): the layout round the
// map moves as panels fill in, so each press is placed afresh.
async function screenOf(page, lat, lon) {
  const { cx, cy } = await mapCentre(page);
  const [lat0, lon0] = (await page.getAttribute("#map", "data-focus")).split(",").map(Number);
  const zoom = Number(await page.getAttribute("#map", "data-zoom"));
  const o = offsetPx(lat0, lon0, zoom, lat, lon);
  return { x: cx + o.x, y: cy + o.y };
}

// Waits until the page shows the server's latest state: the panels round
// the map (the overlay list, the event log) change with it and can move the
// map on the page, so a press is placed only after.
async function settled(page, w) {
  const sequence = String((await w.state()).sequence);
  await until("the page at the server's state", async () => (await page.getAttribute("body", "data-sequence")) === sequence);
  await page.waitForTimeout(100);  // Leaflet's resize handling runs on the next frame
}

// The point `east_m` metres east of (lat, lon) along its parallel (near enough
// for a few tens of km: the tests drag handles along the region's x axis).
function east(lat, lon, east_m) {
  return { lat, lon: lon + east_m / (R * D2R * Math.cos(lat * D2R)) };
}

// Drags from the point (lat, lon) + e0 metres east to + e1 metres east.
async function dragEast(page, lat, lon, e0, e1) {
  const a = east(lat, lon, e0), b = east(lat, lon, e1);
  const p0 = await screenOf(page, a.lat, a.lon), p1 = await screenOf(page, b.lat, b.lon);
  await drag(page, p0.x, p0.y, p1.x, p1.y);
}

// Text of the layer table's row for a layer id.
const rowText = (page, id) => page.textContent(`#layer-table tbody tr[data-id="${id}"]`).catch(() => "");

async function setup(name, cleanup, options = {}) {
  await import("./harness.mjs").then((h) => h.loadPlaywright());
  const w = await new Weatherd(name, options).start();
  cleanup(() => w.stop());
  // Every case needs the console's WebSocket: a server without it fails the
  // case instead of skipping it.
  assert(await w.hasWebSocket(), "GET /api/ws does not upgrade to a WebSocket");
  const browser = await launch();
  cleanup(() => browser.close());
  return { w, browser };
}

function noProblems(...lists) {
  const all = lists.flat();
  assert(all.length === 0, `the pages reported:\n  ${all.join("\n  ")}`);
}

const cases = {
  // A layer edited in one console appears in another and in GET /api/state;
  // a change made through the API appears in both consoles.
  async two_pages(cleanup) {
    const { w, browser } = await setup("two_pages", cleanup);
    const allowed = [];
    const a = await openConsole(browser, w, { token: TOKEN, allowed, name: "A" });
    const b = await openConsole(browser, w, { allowed, name: "B" });
    console.log(`  link: A ${await a.page.getAttribute("body", "data-link")}, B ${await b.page.getAttribute("body", "data-link")}`);
    await a.page.click('#layer-table tbody tr[data-id="1"]');
    await a.page.fill('[name="coverage_pct"]', "85");
    // 85 % is 6.8 oktas: the pair follows.
    assert((await a.page.inputValue('[name="coverage_oktas"]')) === "6.8", "oktas follow the percentage");
    await a.page.fill('[name="base_ft"]', "5000");
    await a.page.click("#layer-apply");
    await until("A's note to say applied", async () => /applied #/.test(await a.page.textContent("#layers .note")));
    const s = await w.state();
    const l1 = s.layers.find((l) => l.id === 1);
    near(l1.coverage, 0.85, 1e-9, "layer 1 coverage in the API");
    near(l1.base_m, 5000 * 0.3048, 1e-6, "5000 ft base in metres in the API");
    await until("B to show 85 %", async () => /85 %/.test(await rowText(b.page, 1)));
    assert(/1524 m/.test(await rowText(b.page, 1)), "B shows the base in metres");
    // The other way: a change through the API reaches both pages.
    const r = await w.api("POST", "/api/changes", { author: "api-test", changes: [{ op: "set_layer", layer: {
      id: 5, type: "stratus", base_m: 300, thickness_m: 200, transition_band_m: 20, coverage: 0.4, density: 0.8,
      wind: { speed_mps: 5, from_deg: 180, vertical_mps: 0 } } }] });
    assert(r.status === 200, `API change: ${r.text}`);
    for (const p of [a.page, b.page]) await until("layer 5 in a console", async () => /stratus/.test(await rowText(p, 5)));
    await until("B's event log to name the API author", async () => /api-test/.test(await b.page.textContent("#events")));
    assert(/console/.test(await b.page.textContent("#events")), "B's log names the console's author");
    noProblems(a.problems, b.problems);
  },

  // The live path: the console is on the WebSocket (not polling), a change
  // reaches it by push, and it does not poll the state meanwhile.
  async live_ws(cleanup) {
    const { w, browser } = await setup("live_ws", cleanup);
    const a = await openConsole(browser, w, { name: "A" });
    await until("the console to be live", async () => (await a.page.getAttribute("body", "data-link")) === "live");
    let statePolls = 0;
    a.page.on("request", (req) => { if (new URL(req.url()).pathname === "/api/state") ++statePolls; });
    const r = await w.api("POST", "/api/changes", { author: "ws-test", changes: [{ op: "set_clock", rate: 10 }] });
    assert(r.status === 200, r.text);
    await until("the pushed rate", async () => /×10/.test(await a.page.textContent("#clock-rate")));
    await until("the pushed event", async () => /ws-test/.test(await a.page.textContent("#events")));
    await new Promise((res) => setTimeout(res, 3000));
    assert(statePolls === 0, `the live console polled GET /api/state ${statePolls} times`);
    await until("health from the socket", async () => /console clients\s*[1-9]/.test(await a.page.textContent("#health")));
    noProblems(a.problems);
  },

  // A host's CIGI Weather Control (a real UDP datagram: IG Control, then
  // Weather Control for cloud layer 1, big-endian, laid out as in
  // reference/cigi.md sections 3 and 6.4) appears in two open consoles, by
  // push, and in their event logs as coming from CIGI. The issue asks for
  // within a second; the bound is wider for a loaded 2-core machine and the
  // measured time is printed.
  async cigi(cleanup) {
    const { w, browser } = await setup("cigi", cleanup);
    const a = await openConsole(browser, w, { name: "A" });
    const b = await openConsole(browser, w, { name: "B" });
    for (const c of [a, b])
      await until("the console to be live", async () => (await c.page.getAttribute("body", "data-link")) === "live");
    const datagram = Buffer.alloc(24 + 56);
    const v = new DataView(datagram.buffer, datagram.byteOffset, datagram.length);
    // IG Control: id 1, size 24, version 3, db 0, Operate + minor version 3, magic 0x8000, host frame 1.
    v.setUint8(0, 1); v.setUint8(1, 24); v.setUint8(2, 3); v.setUint8(4, 0x01 | (3 << 4));
    v.setUint16(6, 0x8000); v.setUint32(8, 1);
    // Weather Control: id 12, size 56, global scope, layer 1, enabled, cumulus (7).
    const wc = 24;
    v.setUint8(wc, 12); v.setUint8(wc + 1, 56); v.setUint16(wc + 2, 0); v.setUint8(wc + 4, 1);
    v.setUint8(wc + 5, 70); v.setUint8(wc + 6, 0x01 | (7 << 4)); v.setUint8(wc + 7, 0);
    v.setFloat32(wc + 8, 10); v.setFloat32(wc + 12, 30000); v.setFloat32(wc + 16, 0);
    v.setFloat32(wc + 20, 87.5);   // coverage, %
    v.setFloat32(wc + 24, 1800);   // base, m MSL
    v.setFloat32(wc + 28, 1400);   // thickness, m
    v.setFloat32(wc + 32, 100);    // transition band, m
    v.setFloat32(wc + 36, 9);      // wind, m/s
    v.setFloat32(wc + 40, 0);
    v.setFloat32(wc + 44, 240);    // from, deg
    v.setFloat32(wc + 48, 1013.25); v.setFloat32(wc + 52, 0);
    const socket = dgram.createSocket("udp4");
    cleanup(() => new Promise((res) => socket.close(res)));
    const sent = Date.now();
    await new Promise((res, rej) => socket.send(datagram, w.cigiPort, "127.0.0.1", (e) => (e ? rej(e) : res())));
    const seen = await Promise.all([a, b].map((c) => until("the CIGI layer in the console", async () =>
      /88 %|87\.5 %/.test(await rowText(c.page, 1)) && /1800 m/.test(await rowText(c.page, 1)) ? Date.now() : 0,
    10000, 20)));
    const latency_ms = Math.max(...seen) - sent;
    console.log(`  CIGI Weather Control to both consoles: ${latency_ms} ms`);
    assert(latency_ms < 3000, `the CIGI change took ${latency_ms} ms to reach both consoles`);
    const s = await w.state();
    const l1 = s.layers.find((l) => l.id === 1);
    near(l1.coverage, 0.875, 1e-6, "layer 1 coverage from CIGI in the API");
    near(l1.base_m, 1800, 1e-3, "layer 1 base from CIGI in the API");
    for (const c of [a, b])
      await until("the CIGI event in the log", async () => /cigi/i.test(await c.page.textContent("#events")));
    noProblems(a.problems, b.problems);
  },

  // METAR: a preview lists each report's layers (or why it does not parse)
  // and changes nothing; apply puts the station's weather in the state.
  async metar(cleanup) {
    const { w, browser } = await setup("metar", cleanup);
    const a = await openConsole(browser, w, { token: TOKEN, name: "A" });
    const before = await w.state();
    // LJLJ (Ljubljana, 388 m in deploy/metar/stations.csv): broken at 3000 ft
    // above the station; the second report's only cloud group is malformed:
    // skipped and named, its sky not observed.
    await a.page.fill('[name="reports"]',
      "METAR LJLJ 221150Z 24008KT 9999 BKN030 12/06 Q1018\nMETAR LIPQ 221150Z 24008KT 9999 BKN0x5 12/06 Q1018");
    await a.page.click("#metar-preview");
    await until("the preview", async () => (await a.page.$$("#metar-result li")).length === 2);
    const items = await a.page.$$eval("#metar-result li", (lis) => lis.map((li) => [li.className, li.textContent]));
    assert(items[0][0] === "ok" && /LJLJ/.test(items[0][1]) && /\/8/.test(items[0][1]), `report 1 previewed: ${items[0][1]}`);
    assert(items[1][0] === "warn" && /skipped group 6 'BKN0x5'/.test(items[1][1]) && /not observed/.test(items[1][1]),
      `report 2's bad group skipped and named: ${items[1][1]}`);
    assert((await w.state()).sequence === before.sequence, "a preview changes nothing");
    await a.page.click("#metar-apply");
    await until("applied", async () => /applied #/.test(await a.page.textContent("#metar .note")));
    const s = await w.state();
    const region = s.regions.find((r) => Math.abs(r.center_lat_deg - 46.2237) < 0.01);
    assert(region, `a region at LJLJ: ${JSON.stringify(s.regions)}`);
    const layer = region.layers.find((l) => l.coverage > 0);
    // BKN is 5 to 7 oktas (WMO code table 2700); 3000 ft above a 388 m station.
    assert(layer.coverage >= 5 / 8 && layer.coverage <= 7 / 8, `BKN coverage ${layer.coverage}`);
    near(layer.base_m, 3000 * 0.3048 + 388, 15, "BKN030 base in metres MSL");
    await until("the METAR event", async () => /metar/.test(await a.page.textContent("#events")));
    // The conformance check: LJLJ's report is what the renderers draw there.
    await a.page.click("#conformance-check");
    await until("the conformance table", async () => (await a.page.$$("#conformance-result tbody tr")).length === 1);
    const row = await a.page.textContent("#conformance-result tbody tr");
    assert(/LJLJ/.test(row) && /at 427\d ft/.test(row) && /0\/8$/.test(row.trim()), `LJLJ's conformance row: ${row}`);
    assert(await a.page.getAttribute("#conformance-result tbody tr", "class") === "ok", "LJLJ within tolerance");
    assert(/1 of 1 stations/.test(await a.page.textContent("#conformance .note")), "the summary");
    // The map's marker of LJLJ says so too.
    await until("LJLJ's marker checked", async () =>
      await a.page.getAttribute('.station[data-icao="LJLJ"]', "data-conformance") === "ok");
    assert(/drawn as reported/.test(await a.page.getAttribute('.station[data-icao="LJLJ"]', "title")), "LJLJ's title");
    // At a point: the weather there; no forecast is loaded, so no source.
    await a.page.fill('#source-form [name="lat"]', "46.2237");
    await a.page.fill('#source-form [name="lon"]', "14.4576");
    await a.page.fill('#source-form [name="alt"]', "1400");
    await a.page.click("#source-ask");
    await until("the point's answer", async () => (await a.page.$$("#source-result li")).length === 3);
    const answer = await a.page.textContent("#source-result");
    assert(/layer \d+, cloud density/.test(answer) && /no forecast cover here/.test(answer), `the point's answer: ${answer}`);
    // No forecast: the standard atmosphere's 5.9 C at 1400 m, no humidity.
    assert(/air 5\.9 C \(standard atmosphere\)/.test(answer), `the point's air: ${answer}`);
    noProblems(a.problems);
  },

  // A storm cell placed by clicking on the map, resized by its handle,
  // appears in the API where it was clicked.
  async region_click(cleanup) {
    const { w, browser } = await setup("region_click", cleanup);
    const lat0 = 46, lon0 = 13, zoom = 10;  // about 106 m per CSS px here
    const a = await openConsole(browser, w, { token: TOKEN, name: "A",
      hash: `#focus=${lat0},${lon0}&zoom=${zoom}` });
    const { cx, cy } = await mapCentre(a.page);
    const dx = 120, dy = -80;  // px: east and north of the focus
    await a.page.click("#mode-storm");
    await a.page.mouse.click(cx + dx, cy + dy);
    await until("the region form", async () => a.page.isVisible("#region-form"));
    const centre = pointAt(lat0, lon0, zoom, dx, dy);
    // The size handle sits on the east edge, 5 km from the centre of the
    // default 10 km cell; dragged to 8 km it makes the cell 16 km.
    await dragEast(a.page, centre.lat, centre.lon, 5000, 8000);
    await a.page.click("#region-apply");
    await until("applied", async () => /applied #/.test(await a.page.textContent("#region .note")));
    const s = await w.state();
    assert(s.regions.length === 1, `one region: ${JSON.stringify(s.regions)}`);
    const r = s.regions[0];
    // Within 1.5 px: Leaflet puts the view's origin on a whole pixel.
    const tolerance_m = 1.5 * metresPerPx(centre.lat, zoom);
    near(r.center_lat_deg, centre.lat, tolerance_m / (R * D2R), "centre latitude");
    near(r.center_lon_deg, centre.lon, tolerance_m / (R * D2R * Math.cos(centre.lat * D2R)), "centre longitude");
    near(r.size_x_m, 16000, 300, "width after dragging the handle");
    assert(r.layers.length === 1 && r.layers[0].type === "cumulonimbus", "a storm cell's layer");
    await settled(a.page, w);
    // The transition handle: the default 4 km perimeter ends 12 km from the
    // centre; dragged out to 15 km it becomes 7 km.
    await dragEast(a.page, r.center_lat_deg, r.center_lon_deg, 12000, 15000);
    await a.page.click("#region-apply");
    await until("the perimeter applied", async () => {
      const g = (await w.state()).regions[0];
      return g && Math.abs(g.transition_m - 7000) < 300;
    });
    await settled(a.page, w);
    // The region and its perimeter on the map: one SVG path each.
    assert(await a.page.locator(`path.region-edge.region-${r.id}`).count() === 1, "the region's edge drawn");
    assert(await a.page.locator(`path.region-perimeter.region-${r.id}`).count() === 1, "its perimeter drawn");
    // Its layer as the overlay: the coverage field is white at the cell's
    // centre (0.95 of the overlay's full alpha) and empty 30 km away. The
    // least alpha of 3 x 3 pixels: a graticule line or an arrow on the same
    // canvas only adds to it.
    await a.page.selectOption("#overlay-layer", String(r.layers[0].id));
    const alphaAt = async (lat, lon) => {
      const p = await screenOf(a.page, lat, lon);
      return a.page.evaluate(([x, y]) => {
        const c = document.querySelector("canvas.sky-overlay"), rect = c.getBoundingClientRect();
        const k = c.width / rect.width;
        const d = c.getContext("2d").getImageData(Math.round((x - rect.left) * k) - 1, Math.round((y - rect.top) * k) - 1, 3, 3).data;
        let least = 255;
        for (let i = 3; i < d.length; i += 4) least = Math.min(least, d[i]);
        return least;
      }, [p.x, p.y]);
    };
    await until("the cell's coverage on the overlay", async () => (await alphaAt(r.center_lat_deg, r.center_lon_deg)) > 140);
    const far = east(r.center_lat_deg, r.center_lon_deg, -30000);
    assert((await alphaAt(far.lat, far.lon)) === 0, "no coverage of the cell's layer outside it");
    // A clearing placed by press and drag: 6 km from its centre is a 12 km
    // hole, every global layer at coverage 0 inside.
    await a.page.click("#mode-clearing");
    const clearingAt = pointAt(lat0, lon0, zoom, -150, 100);
    await dragEast(a.page, clearingAt.lat, clearingAt.lon, 0, 6000);
    await a.page.click("#region-apply");
    const clearing = await until("the clearing in the API", async () => (await w.state()).regions.find((g) => g.id !== r.id));
    near(clearing.size_x_m, 12000, 300, "clearing size from the drag");
    assert(clearing.layers.length === 1 && clearing.layers[0].id === 1 && clearing.layers[0].coverage === 0,
      `a clearing of layer 1: ${JSON.stringify(clearing.layers)}`);
    // A click on the storm cell (in pan mode) opens it in the region tool.
    await a.page.click("#region-cancel");
    await settled(a.page, w);
    const cell = await screenOf(a.page, r.center_lat_deg, r.center_lon_deg);
    await a.page.mouse.click(cell.x, cell.y);
    await until("the storm cell picked", async () => (await a.page.isVisible("#region-form")) &&
      (await a.page.textContent("#region-title")) === `Region ${r.id}`).catch(async (e) => {
      throw new Error(`${e.message}: the region tool says "${await a.page.textContent("#region-title")}" ${JSON.stringify(await a.page.evaluate(([x, y]) => document.elementsFromPoint(x, y).map((q) => q.tagName + "." + q.className.baseVal + q.className), [cell.x, cell.y]))}`);
    });
    noProblems(a.problems);
  },

  // The weather clock: pause, a jump, a rate; a layer change scheduled as a
  // ramp shows on the timeline and in the API's pending changes.
  async clock(cleanup) {
    const { w, browser } = await setup("clock", cleanup);
    const a = await openConsole(browser, w, { token: TOKEN, name: "A" });
    await a.page.click('[data-rate="0"]');
    await until("paused", async () => (await w.state()).clock_rate === 0);
    await until("the page says paused", async () => /paused/.test(await a.page.textContent("#clock-rate")));
    await a.page.fill('[name="jump"]', "12:00");
    await a.page.click("#clock-jump-form button");
    await until("the jump", async () => Math.abs((await w.state()).clock_s - 43200) < 1e-6);
    await until("the page's clock", async () => (await a.page.textContent("#clock-now")) === "12:00:00");
    // Coverage 0.6 -> 0.9 from 12:10 over 10 minutes.
    await a.page.click('#layer-table tbody tr[data-id="1"]');
    await a.page.fill('[name="coverage_oktas"]', "7.2");
    assert((await a.page.inputValue('[name="coverage_pct"]')) === "90", "7.2 oktas is 90 %");
    await a.page.fill('[name="ramp"]', "600");
    await a.page.fill('[name="at"]', "12:10:00");
    await a.page.click("#layer-apply");
    await until("applied", async () => /applied #/.test(await a.page.textContent("#layers .note")));
    const s = await w.state();
    assert(s.pending.length === 1 && s.pending[0].start_s === 43800 && s.pending[0].end_s === 44400,
      `pending: ${JSON.stringify(s.pending)}`);
    near(s.layers[0].coverage, 0.6, 1e-12, "not yet started");
    await until("the timeline entry", async () => /at 12:10:00, in 00:10:00/.test(await a.page.textContent("#timeline-list")));
    await a.page.click('[data-rate="60"]');
    await until("x60", async () => (await w.state()).clock_rate === 60);
    noProblems(a.problems);
  },

  // Invalid input is refused next to its field, before anything is sent;
  // a refusal from the server (the layer was removed meanwhile by someone
  // else) lands next to the field it names; the state stays as it was.
  async invalid(cleanup) {
    const { w, browser } = await setup("invalid", cleanup);
    const allowed = [
      { text: /status of 400/, url: /\/api\/changes$/, why: "the server's refusal this test provokes" }];
    const a = await openConsole(browser, w, { token: TOKEN, allowed, name: "A" });
    const before = await w.state();
    await a.page.click('#layer-table tbody tr[data-id="1"]');
    const err = (f) => a.page.textContent(`#layer-form [data-err="${f}"]`);
    await a.page.fill('[name="coverage_pct"]', "140");
    assert(/outside 0–100 %/.test(await err("coverage")), `coverage message: ${await err("coverage")}`);
    await a.page.fill('[name="coverage_pct"]', "50");
    await a.page.fill('[name="base_m"]', "-600");
    assert(/below the ground/.test(await err("base")), `base message: ${await err("base")}`);
    await a.page.fill('[name="base_m"]', "2000");
    await a.page.fill('[name="top_m"]', "1500");
    assert(/must be above the base/.test(await err("top")), `top message: ${await err("top")}`);
    let posts = 0;
    a.page.on("request", (req) => { if (req.method() === "POST") ++posts; });
    await a.page.click("#layer-apply");
    await new Promise((res) => setTimeout(res, 500));
    assert(posts === 0, "an invalid draft is not sent");
    assert(await a.page.getAttribute('[name="top_m"]', "aria-invalid") === "true", "the top field is marked");
    const after = await w.state();
    assert(after.sequence === before.sequence && JSON.stringify(after.layers) === JSON.stringify(before.layers), "state unchanged");
    // The server's refusal: layer 1 removed through the API; this console
    // still has it open and asks to remove it.
    await a.page.click("#layer-revert");
    const r = await w.api("POST", "/api/changes", { changes: [{ op: "remove_layer", id: 1 }] });
    assert(r.status === 200, r.text);
    const seq = (await w.state()).sequence;
    await a.page.click("#layer-remove");
    await until("the server's reason next to the id", async () => /no layer 1/.test(await err("id")));
    assert(/nothing applied/.test(await a.page.textContent("#layers .note")), "the note says nothing was applied");
    assert((await w.state()).sequence === seq, "the refused change left the state as it was");
    noProblems(a.problems);
  },

  // Without the token the page is read-only; the token is asked once per
  // tab session and kept across a reload; a wrong one is refused.
  async readonly(cleanup) {
    const { w, browser } = await setup("readonly", cleanup);
    const allowed = [
      { text: /status of 401/, url: /\/api\/changes$/, why: "the wrong token this test tries" }];
    const a = await openConsole(browser, w, { allowed, name: "A" });
    for (const sel of ["#layer-apply", "#mode-storm", "#metar-apply", '[data-rate="60"]', '#layer-form [name="coverage_pct"]'])
      assert(await a.page.isDisabled(sel), `${sel} disabled without the token`);
    assert(/read-only/.test(await a.page.textContent("#token-state")), "the page says read-only");
    assert(await a.page.isEnabled("#metar-preview"), "a METAR preview needs no token");
    // A wrong token: the first change is refused and the page is read-only again.
    await a.page.fill('[name="token"]', "not-the-token");
    await a.page.click("#token-use");
    await a.page.click('[data-rate="60"]');
    await until("the refusal", async () => /refused the token/.test(await a.page.textContent("#clock .note")));
    assert(await a.page.isDisabled('[data-rate="60"]'), "read-only again after a refused token");
    // The right token, then a reload: still allowed (sessionStorage).
    await a.page.fill('[name="token"]', TOKEN);
    await a.page.click("#token-use");
    await a.page.reload();
    await until("reloaded", async () => (await a.page.getAttribute("body", "data-sequence")) !== null);
    assert(await a.page.isEnabled('[data-rate="60"]'), "the token survives a reload");
    await a.page.click('[data-rate="60"]');
    try {
      await until("rate x60 applied", async () => (await w.state()).clock_rate === 60);
    } catch (e) {
      // What the page made of the click (a refusal, still applying, nothing).
      throw new Error(`${e.message}; the clock card's note: "${await a.page.textContent("#clock .note")}"`);
    }
    // A server alone has no cluster panel.
    assert(await a.page.isHidden("#cluster"), "no cluster panel without --nats");
    // Another tab session (a new context) starts without it. Its GET
    // /api/cluster answers a fixture: a leader, a follower and two relays,
    // one of them behind (another state hash).
    const now = Date.now();
    const member = (id, role, subscribers, hash) => ({ id, role, stream: `10.0.0.${subscribers}:7700`, api: "",
      subscribers, applied_sequence: 42, term: role === "leader" ? 7 : 0, state_hash: hash, updated_unix_ms: now });
    const cluster = { nats: true, self: "weatherd-a", read_age_ms: 300, malformed_records: 0, members: [
      member("weatherd-a", "leader", 0, "00000000000000aa"), member("weatherd-b", "follower", 0, "00000000000000aa"),
      member("relay-site-1", "relay", 12, "00000000000000aa"), member("relay-site-2", "relay", 3, "00000000000000bb")] };
    const b = await openConsole(browser, w, { allowed, name: "B", routes: { "/api/cluster": cluster } });
    assert(await b.page.isDisabled("#layer-apply"), "a new session is read-only");
    await until("the cluster panel", async () => await b.page.isVisible("#cluster"));
    const rows = await b.page.$$eval("#cluster tbody tr", (trs) => trs.map((tr) =>
      [...tr.querySelectorAll("td")].map((td) => td.textContent)));
    assert(rows.length === 4, `4 members, got ${JSON.stringify(rows)}`);
    assert(rows[0][0] === "leader (this)" && rows[2][3] === "12" && rows[2][5] === "as leader" && rows[3][5] === "differs",
      `the cluster rows: ${JSON.stringify(rows)}`);
    const note = await b.page.textContent("#cluster .note");
    assert(/2 server\(s\), 2 relay\(s\) with 15 renderer\(s\)/.test(note), `the cluster note: ${note}`);
    noProblems(a.problems, b.problems);
  },

  // The server goes away and comes back on the same port with the same
  // database: the page says offline, then recovers by itself and works.
  async restart(cleanup) {
    const { w, browser } = await setup("restart", cleanup, { db: true });
    const allowed = [
      { text: /ERR_CONNECTION_REFUSED|ERR_EMPTY_RESPONSE|ERR_CONNECTION_RESET|WebSocket connection to .* failed/,
        why: "the server is stopped on purpose" }];
    const a = await openConsole(browser, w, { token: TOKEN, allowed, name: "A" });
    await w.stop();
    await until("offline", async () => (await a.page.getAttribute("body", "data-link")) === "offline", 30000);
    await w.start();
    await until("back", async () => ["live", "polling"].includes(await a.page.getAttribute("body", "data-link")), 30000);
    await a.page.click('[data-rate="10"]');
    await until("a change after the restart", async () => (await w.state()).clock_rate === 10);
    await until("the page to show it", async () => /×10/.test(await a.page.textContent("#clock-rate")));
    noProblems(a.problems);
  },

  // Every control can be clicked where it is drawn: at the usual instructor
  // station sizes no card spills over another (a wide row under the next
  // card takes its clicks: the scenario Load button once sat under the
  // renderer list). Hit-tests the centre of each visible control.
  async layout(cleanup) {
    const { w, browser } = await setup("layout", cleanup);
    for (const viewport of [{ width: 1920, height: 1080 }, { width: 1600, height: 1000 }, { width: 1366, height: 768 },
      { width: 1280, height: 800 }, { width: 1024, height: 768 }]) {
      const a = await openConsole(browser, w, { token: TOKEN,
        name: `${viewport.width}x${viewport.height}`, viewport });
      const controls = await a.page.$$("button, input, select, textarea");
      let checked = 0;
      const covered = [];
      for (const c of controls) {
        if (!(await c.isVisible())) continue;
        await c.scrollIntoViewIfNeeded();
        const hit = await c.evaluate((el) => {
          const r = el.getBoundingClientRect();
          const x = r.left + r.width / 2, y = r.top + r.height / 2;
          const top = document.elementFromPoint(x, y);
          const label = el.closest("label");
          const ok = top !== null && (el === top || el.contains(top) || (label !== null && label.contains(top)));
          return { ok, what: el.id || el.name || el.textContent.trim().slice(0, 20) || el.tagName,
            over: top ? (top.closest("section") || top).id || top.tagName : "nothing" };
        });
        checked += 1;
        if (!hit.ok) covered.push(`${hit.what} (under ${hit.over})`);
      }
      assert(checked > 20, `${viewport.width}x${viewport.height}: only ${checked} visible controls`);
      assert(covered.length === 0, `${viewport.width}x${viewport.height}: covered controls: ${covered.join(", ")}`);
      console.log(`  ${viewport.width}x${viewport.height}: ${checked} controls, all clickable`);
      noProblems(a.problems);
      await a.context.close();
    }
  },

  // A screenshot of a busy console: the artefact in the build tree (and
  // docs/images/console.png when SKY_CONSOLE_DOCS_SCREENSHOT names it).
  async screenshot(cleanup) {
    const { w, browser } = await setup("screenshot", cleanup);
    const layer = (id, type, base_m, thickness_m, coverage, speed, from) => ({ op: "set_layer", layer: {
      id, type, base_m, thickness_m, transition_band_m: 100, coverage, density: 1,
      wind: { speed_mps: speed, from_deg: from, vertical_mps: 0 } } });
    const region = (id, lat, lon, size, transition, layers, extra = {}) => ({ op: "set_region", region: {
      id, center_lat_deg: lat, center_lon_deg: lon, size_x_m: size, size_y_m: size * (extra.aspect || 1),
      corner_radius_m: size / 2 * Math.min(1, extra.aspect || 1), rotation_deg: extra.rotation || 0, transition_m: transition, layers } });
    const now = (await w.state()).clock_s;
    const r = await w.api("POST", "/api/changes", { author: "instructor", changes: [
      layer(1, "cumulus", 1500, 1500, 0.45, 10, 270), layer(2, "altostratus", 4500, 1200, 0.3, 18, 250),
      region(1, 46.05, 13.25, 14000, 9000, [{ ...layer(6, "cumulonimbus", 900, 9000, 0.95, 12, 250).layer }]),
      region(2, 45.9, 12.75, 22000, 12000, [{ ...layer(1, "cumulus", 1500, 1500, 0, 10, 270).layer }], { aspect: 0.6, rotation: 30 }),
    ] });
    assert(r.status === 200, r.text);
    const later = await w.api("POST", "/api/changes", { author: "instructor", changes: [
      { ...layer(1, "cumulus", 1500, 1800, 0.8, 12, 280), at_s: now + 600, ramp_s: 900 },
      { op: "remove_layer", id: 2, at_s: now + 1800, ramp_s: 600 }] });
    assert(later.status === 200, later.text);
    // METAR at the stations round the cell, one of each flight category.
    const metar = await w.api("POST", "/api/metar", { apply: true, author: "instructor", radius_m: 30000, reports: [
      "METAR LJLJ 221150Z 24008KT 9999 FEW025 SCT045 BKN090 12/06 Q1018",
      "METAR LIPZ 221150Z 18006KT 4000 BR BKN012 14/12 Q1016",
      "METAR LIPH 221150Z 17005KT 2500 BR OVC007 13/12 Q1016",
      "METAR LIPQ 221150Z 22004KT 0800 FG VV002 11/11 Q1017",
      "METAR LOWK 221150Z 31005KT 9999 SCT050 09/02 Q1020"] });
    assert(metar.status === 200, metar.text);
    const a = await openConsole(browser, w, { token: TOKEN, name: "A", viewport: { width: 1600, height: 1100 },
      hash: "#focus=46.0,13.2&zoom=8.25" });
    await until("the coastline", async () => (await a.page.getAttribute("#map", "data-basemap")) === "loaded");
    await until("the stations", async () => (await a.page.$$('.station[data-category="LIFR"]')).length === 1);
    await a.page.fill('[name="reports"]', "METAR LJLJ 221150Z 24008KT 9999 FEW025 SCT045 BKN090 12/06 Q1018");
    await a.page.click("#metar-preview");
    await until("the preview", async () => (await a.page.$$("#metar-result li")).length === 1);
    await a.page.click('#layer-table tbody tr[data-id="1"]');
    await until("the timeline", async () => /scheduled|ramping|at /.test(await a.page.textContent("#timeline-list")));
    // The storm cell in the region tool, and one station's report open.
    const { cx, cy } = await mapCentre(a.page);
    const cell = offsetPx(46.0, 13.2, 8.25, 46.05, 13.25);
    await a.page.mouse.click(cx + cell.x, cy + cell.y);
    await until("the storm cell picked", async () => (await a.page.textContent("#region-title")) === "Region 1");
    // The overlay shows the storm cell's own layer (cumulonimbus, id 6).
    await a.page.selectOption("#overlay-layer", "6");
    await a.page.click('.station[data-icao="LIPZ"] .station-dot');
    await until("LIPZ's popup", async () => /LIPZ/.test(await a.page.textContent(".leaflet-popup-content")));
    await a.page.waitForTimeout(500);
    fs.mkdirSync(config.out, { recursive: true });
    const shot = path.join(config.out, "console.png");
    await a.page.screenshot({ path: shot });
    console.log(`  screenshot: ${shot}`);
    if (process.env.SKY_CONSOLE_DOCS_SCREENSHOT) {
      fs.copyFileSync(shot, process.env.SKY_CONSOLE_DOCS_SCREENSHOT);
      console.log(`  copied to ${process.env.SKY_CONSOLE_DOCS_SCREENSHOT}`);
    }
    assert(fs.statSync(shot).size > 50000, "a screenshot with something in it");
    noProblems(a.problems);
  },
};

// The Natural Earth ground is drawn where it belongs: along the parallel
// through Trieste (45.65 N) the Gulf of Trieste is sea and the first land
// east of it is the city's waterfront, Piazza Unita d'Italia at 13.767 E
// (1:50m data is generalised by a km or two: 0.03 deg, 2.3 km, allowed).
// The basemap's canvas is read at points projected here, not by the page.
cases.coastline = async (cleanup) => {
  const { w, browser } = await setup("coastline", cleanup);
  // No cloud overlay over the ground: the one global layer removed.
  const r = await w.api("POST", "/api/changes", { changes: [{ op: "remove_layer", id: 1 }] });
  assert(r.status === 200, r.text);
  const lat0 = 45.65, lon0 = 13.7, zoom = 11;
  const a = await openConsole(browser, w, { name: "A", hash: `#focus=${lat0},${lon0}&zoom=${zoom}` });
  await until("the coastline", async () => (await a.page.getAttribute("#map", "data-basemap")) === "loaded");
  await a.page.waitForTimeout(300);  // the canvas renderer draws on the next frame
  const { box } = await mapCentre(a.page);
  // Points along the parallel, 0.005 deg apart, from 13.60 E to 13.85 E, as
  // offsets from the map's centre in CSS px.
  const lons = [];
  for (let lon = 13.6; lon <= 13.85 + 1e-9; lon += 0.005) lons.push(lon);
  const points = lons.map((lon) => offsetPx(lat0, lon0, zoom, lat0, lon));
  const pixels = await a.page.evaluate(([pts, mapW, mapH]) => {
    const c = document.querySelector(".leaflet-basemap-pane canvas");
    const rect = c.getBoundingClientRect(), map = document.querySelector("#map").getBoundingClientRect();
    const k = c.width / rect.width, g = c.getContext("2d");
    return pts.map((p) => {
      const x = (map.left + mapW / 2 + p.x - rect.left) * k, y = (map.top + mapH / 2 + p.y - rect.top) * k;
      return [...g.getImageData(Math.round(x), Math.round(y), 1, 1).data];
    });
  }, [points, box.width, box.height]);
  // Land is filled (#27362b), the sea is the container showing through (alpha 0).
  const isLand = (px) => px[3] > 200 && px[0] < 80 && px[1] > 40 && px[1] < 80;
  const isSea = (px) => px[3] === 0;
  const firstLand = pixels.findIndex(isLand);
  console.log(`  along 45.65 N: ${pixels.map((p) => (isLand(p) ? "#" : isSea(p) ? "." : "+")).join("")}`);
  assert(firstLand > 0, "sea west of Trieste, land east of it");
  assert(pixels.slice(0, firstLand - 2).every(isSea), "the Gulf of Trieste is sea");
  assert(pixels.slice(firstLand + 2).every(isLand), "the Karst east of the city is land");
  near(lons[firstLand], 13.767, 0.03, "the coast at Trieste (deg E)");
  // The coastline itself is stroked there (light blue, #8fb3cf).
  const coastPx = offsetPx(lat0, lon0, zoom, lat0, lons[firstLand]);
  const stroke = await a.page.evaluate(([p, mapW, mapH]) => {
    const c = document.querySelector(".leaflet-basemap-pane canvas");
    const rect = c.getBoundingClientRect(), map = document.querySelector("#map").getBoundingClientRect();
    const k = c.width / rect.width, g = c.getContext("2d");
    const x = (map.left + mapW / 2 + p.x - rect.left) * k, y = (map.top + mapH / 2 + p.y - rect.top) * k;
    const d = g.getImageData(Math.round(x - 8 * k), Math.round(y - 2 * k), Math.round(16 * k), Math.round(4 * k)).data;
    let blue = 0;
    for (let i = 0; i < d.length; i += 4) if (d[i + 2] > 150 && d[i + 1] > 120 && d[i] > 90 && d[i] < 200) ++blue;
    return blue;
  }, [coastPx, box.width, box.height]);
  assert(stroke > 0, "the coastline's stroke at the coast");
  noProblems(a.problems);
};

// METAR stations on the map: every station of the server's table is a
// marker, coloured by the flight category of its latest applied report;
// a newer report changes the colour live, and a click shows the report and
// the layers it became.
cases.stations = async (cleanup) => {
  const { w, browser } = await setup("stations", cleanup, { db: true });
  const table = fs.readFileSync(config.stations, "utf8").split("\n").filter((l) => /^[A-Z0-9]{4},/.test(l))
    .map((l) => l.split(",")[0]);
  const allowed = [
    { text: /ERR_CONNECTION_REFUSED|ERR_EMPTY_RESPONSE|ERR_CONNECTION_RESET|WebSocket connection to .* failed/,
      why: "the server is restarted on purpose" }];
  const a = await openConsole(browser, w, { name: "A", hash: "#focus=46.0,13.2&zoom=8", allowed });
  await until("a marker per station", async () => (await a.page.$$(".station")).length === new Set(table).size);
  const category = (icao) => a.page.getAttribute(`.station[data-icao="${icao}"]`, "data-category");
  const colour = (icao) => a.page.$eval(`.station[data-icao="${icao}"] .station-dot`, (e) => getComputedStyle(e).backgroundColor);
  assert((await category("LJLJ")) === "", "no report yet: no category");
  // The colours pilots know (aviationweather.gov): VFR green, MVFR blue, IFR red, LIFR magenta.
  const expected = { VFR: "rgb(46, 204, 64)", MVFR: "rgb(58, 123, 255)", IFR: "rgb(255, 59, 48)", LIFR: "rgb(224, 64, 251)" };
  // [report, its category by ceiling and visibility (FAA AIM 7-1-7)]
  const reports = {
    LJLJ: ["METAR LJLJ 221150Z 24008KT 9999 FEW025 SCT045 BKN090 12/06 Q1018", "VFR"],  // ceiling 9000 ft, 10 km
    LOWK: ["METAR LOWK 221150Z 31005KT 6000 BKN025 09/02 Q1020", "MVFR"],               // 2500 ft, 3.7 SM
    LIPZ: ["METAR LIPZ 221150Z 18006KT 4000 BR BKN012 14/12 Q1016", "IFR"],             // 1200 ft but 2.5 SM
    LIPH: ["METAR LIPH 221150Z 17005KT 9999 OVC007 13/12 Q1016", "IFR"],                // ceiling 700 ft
    LIPQ: ["METAR LIPQ 221150Z 22004KT 0800 FG VV002 11/11 Q1017", "LIFR"],             // 200 ft, 0.5 SM
  };
  const applied = await w.api("POST", "/api/metar", { apply: true, author: "test", reports: Object.values(reports).map((x) => x[0]) });
  assert(applied.status === 200, applied.text);
  const listed = (await w.api("GET", "/api/metar/stations")).json.stations;
  for (const icao of Object.keys(reports))
    assert(listed.find((x) => x.icao === icao).report.text === reports[icao][0], `${icao}'s report in GET /api/metar/stations`);
  for (const [icao, [, cat]] of Object.entries(reports)) {
    await until(`${icao} ${cat}`, async () => (await category(icao)) === cat);
    assert((await colour(icao)) === expected[cat], `${icao}'s colour for ${cat}: ${await colour(icao)}`);
  }
  // A newer report: LJLJ goes down to LIFR, and its marker follows. (Bug:
  // the console asked for the stations again only when the set of station
  // regions changed; since a newer report replaces its station's region in
  // place, the marker kept its old category. It now asks after every METAR event.)
  const worse = "METAR LJLJ 221220Z 24004KT 0600 FG OVC002 10/10 Q1018";
  assert((await w.api("POST", "/api/metar", { apply: true, reports: [worse] })).status === 200, "the newer report");
  await until("LJLJ turns LIFR", async () => (await category("LJLJ")) === "LIFR");
  assert((await colour("LJLJ")) === expected.LIFR, "LJLJ magenta");
  // The report and its layers on click.
  await a.page.click('.station[data-icao="LJLJ"] .station-dot');
  const popup = await until("LJLJ's popup", async () => {
    const t = await a.page.textContent(".leaflet-popup-content").catch(() => "");
    return /LJLJ/.test(t) && t;
  });
  assert(popup.includes(worse), `the report in the popup: ${popup}`);
  assert(/LIFR/.test(popup) && /layer \d+: stratus 8\/8/.test(popup), `the category and the layer it became: ${popup}`);
  // A restart keeps the stations' regions (the store) but not the reports'
  // texts: the markers keep their category, from the regions' ceilings
  // (LIPZ's IFR came from its visibility, which the weather does not keep;
  // LJLJ's newer report replaced its region, OVC002 a LIFR ceiling).
  await w.stop();
  await until("offline", async () => (await a.page.getAttribute("body", "data-link")) === "offline", 30000);
  await w.start();
  await until("back", async () => (await a.page.getAttribute("body", "data-link")) === "live", 30000);
  const after = (await w.api("GET", "/api/metar/stations")).json.stations.find((x) => x.icao === "LIPQ");
  assert(after.report && after.report.text === null && after.report.layers.length > 0, `LIPQ after the restart: ${JSON.stringify(after)}`);
  await a.page.reload();
  await until("LIPQ still LIFR", async () => (await category("LIPQ")) === "LIFR");
  for (const [icao, cat] of [["LOWK", "MVFR"], ["LIPH", "IFR"], ["LJLJ", "LIFR"]])
    assert((await category(icao)) === cat, `${icao} by its ceiling alone: ${await category(icao)}`);
  noProblems(a.problems);
};

// Across the antimeridian and over the pole: a storm cell placed at 180
// degrees with the region tool is one shape (one SVG path the size of the
// cell, not a band round the world), seen from either side; a renderer over
// the North Pole (fed into the page's WebSocket) is drawn at the map's top
// edge and says so.
cases.antimeridian = async (cleanup) => {
  const { w, browser } = await setup("antimeridian", cleanup);
  const lat0 = -17, zoom = 9;
  const context = await browser.newContext({ viewport: { width: 1600, height: 1000 } });
  cleanup(() => context.close());
  // The live feed through the test: every renderers message gains one over the pole.
  const pole = { id: 99, channel: "pole", peer: "test", lat_deg: 89.9, lon_deg: 30, alt_m: 3000, heading_deg: 180,
    last_report_age_s: 0, area: { center_lat_deg: 89.9, center_lon_deg: 30, radius_m: 50000 } };
  await context.routeWebSocket(/\/api\/ws$/, (ws) => {
    const server = ws.connectToServer();
    ws.onMessage((m) => server.send(m));
    server.onMessage((m) => {
      const msg = JSON.parse(m);
      if (msg.type === "renderers") msg.renderers = [...(msg.renderers || []), pole];
      ws.send(JSON.stringify(msg));
    });
  });
  const page = await context.newPage();
  const { watch } = await import("./harness.mjs");
  const problems = watch(page, "A");
  await page.goto(`${w.base}/#focus=${lat0},180&zoom=${zoom}`);
  await until("live", async () => (await page.getAttribute("body", "data-link")) === "live");
  await page.fill('[name="token"]', TOKEN);
  await page.click("#token-use");
  const { cx, cy, box } = await mapCentre(page);
  await page.click("#mode-storm");
  await page.mouse.click(cx, cy);
  await until("the region form", async () => page.isVisible("#region-form"));
  await page.click("#region-apply");
  const region = await until("the cell in the API", async () => (await w.state()).regions[0]);
  near(Math.abs(region.center_lon_deg), 180, 0.01, "the cell's centre at the antimeridian");
  const cellPx = 10000 / metresPerPx(lat0, zoom);
  for (const lon0 of [180, 179.8, -179.8]) {
    await page.fill('[name="focus_lat"]', String(lat0));
    await page.fill('[name="focus_lon"]', String(lon0));
    await page.click('#focus-form button[type="submit"]');
    const edge = page.locator(`path.region-edge.region-${region.id}`);
    await until("the edge redrawn", async () => (await edge.count()) === 1);
    const d = await edge.getAttribute("d");
    const b = await edge.boundingBox();
    const want = offsetPx(lat0, lon0, zoom, lat0, 180);
    assert((d.match(/M/g) || []).length === 1, `one shape seen from ${lon0}: ${d.slice(0, 80)}`);
    near(b.width, cellPx, 4, `the cell's width in px seen from ${lon0}`);
    near(b.x + b.width / 2 - cx, want.x, 3, `the cell where 180 degrees is, seen from ${lon0}`);
  }
  // Over the pole: the view as far north as it goes shows Web Mercator's
  // top edge (85.05 N) at the map's top; the aircraft is drawn whole just
  // inside it (its centre 12 px down), and labelled.
  await page.fill('[name="focus_lat"]', "89.9");
  await page.fill('[name="focus_lon"]', "30");
  await page.click('#focus-form button[type="submit"]');
  const plane = page.locator('.aircraft[data-id="99"]');
  await until("the aircraft over the pole", async () => (await plane.count()) === 1);
  const mb = (await mapCentre(page)).box;
  // The map pans back inside the world after the jump (animated): wait for it.
  await until("the map's top at the world's edge", async () => {
    const [focusLat] = (await page.getAttribute("#map", "data-focus")).split(",").map(Number);
    return Math.abs(offsetPx(focusLat, 30, zoom, 85.0511287798, 30).y + mb.height / 2) < 2;
  }, 5000);
  const pb = await plane.locator("svg").boundingBox();
  assert(pb.x > mb.x && pb.x + pb.width < mb.x + mb.width, "the aircraft within the map's width");
  near(pb.y - mb.y, 0, 2, "the whole aircraft at the map's top");
  assert(/89\.9\d*°N, beyond the map's edge/.test(await plane.textContent()), `labelled: ${await plane.textContent()}`);
  noProblems(problems);
};

// A real renderer channel (skyshell-render, headless) flown by
// skyshell-replay over CIGI appears in the renderer list and as an aircraft
// on the map where the flight is.
cases.renderers = async (cleanup) => {
  const { w, browser } = await setup("renderers", cleanup);
  const list = await w.api("GET", "/api/renderers");
  assert(list.status === 200, `GET /api/renderers: ${list.status} ${list.text}`);
  if (!config.render || !config.replay || !config.flight) throw new Error("SKY_RENDER, SKY_REPLAY, SKY_TEST_FLIGHT must be set");
  // lavapipe's JIT leaves allocations no suppression can name: no leak
  // check for the renderer process (as in tests/integration).
  const render = child(w.dir, "render", config.render, ["--headless", "--server", `127.0.0.1:${w.streamPort}`,
    "--cigi-port", "0", "--port-file", path.join(w.dir, "render.port"), "--out", path.join(w.dir, "frames"),
    "--width", "32", "--height", "18", "--weather-timeout", "60"], { ASAN_OPTIONS: "detect_leaks=0:abort_on_error=1" });
  cleanup(() => render.stop());
  const cigiPort = await until("the renderer's CIGI port", async () => {
    const f = path.join(w.dir, "render.port");
    return fs.existsSync(f) ? Number(fs.readFileSync(f, "utf8")) : 0;
  }, 60000);
  const replay = child(w.dir, "replay", config.replay, [config.flight, "--port", String(cigiPort), "--loop", "--quiet"]);
  cleanup(() => replay.stop());
  // The flight: level, heading east at 900 m near 46.2 N 12.8 E.
  const listed = await until("the renderer in GET /api/renderers", async () => {
    const list = (await w.api("GET", "/api/renderers")).json;
    const arr = Array.isArray(list) ? list : list && list.renderers;
    return arr && arr.find((r) => r.lat_deg !== null && Math.abs(r.lat_deg - 46.2) < 0.01);
  }, 90000, 500);
  near(listed.lon_deg, 12.8, 0.02, "renderer longitude");
  near(listed.heading_deg, 90, 2, "renderer heading");
  const lat0 = 46.2, lon0 = 12.8, zoom = 12.5;  // about 20 m per CSS px
  const a = await openConsole(browser, w, { name: "A",
    hash: `#focus=${lat0},${lon0}&zoom=${zoom}` });
  await until("the renderer row", async () => /46\.2/.test(await a.page.textContent("#renderers tbody")), 30000);
  // The aircraft is drawn where the flight is (Web Mercator computed here),
  // nose to its heading (east); the replay moves ~55 m/s east, so the pose
  // is read just before the symbol and allowed 20 px.
  const { cx, cy } = await mapCentre(a.page);
  const found = await until("the aircraft on the map where the flight is", async () => {
    const r = (await w.api("GET", "/api/renderers")).json;
    const pose = (Array.isArray(r) ? r : r.renderers).find((x) => x.lat_deg !== null);
    const want = offsetPx(lat0, lon0, zoom, pose.lat_deg, pose.lon_deg);
    const plane = a.page.locator(".aircraft").first();
    const box = await plane.locator("svg").boundingBox();
    if (!box) return false;
    const x = box.x + box.width / 2 - cx, y = box.y + box.height / 2 - cy;
    const transform = await plane.locator("svg").evaluate((e) => e.style.transform);
    console.log(`  aircraft at (${x.toFixed(1)}, ${y.toFixed(1)}) px, flight at (${want.x.toFixed(1)}, ${want.y.toFixed(1)}), ${transform}`);
    const angle = Number((/rotate\(([-\d.]+)deg\)/.exec(transform) || [])[1]);
    return Math.hypot(x - want.x, y - want.y) < 20 && Math.abs(angle - 90) < 3;
  }, 30000, 500);
  assert(found, "the aircraft is drawn");
  noProblems(a.problems);
};

// A scenario file chosen in the page is loaded (its start replaces the
// weather, its timeline is pending); a bad one is refused naming its line.
cases.scenario = async (cleanup) => {
  const { w, browser } = await setup("scenario", cleanup);
  const probe = await w.api("POST", "/api/scenario", "not toml = ");
  assert(probe.status === 400, `POST /api/scenario with a bad body: ${probe.status} ${probe.text}`);
  const start = "[clock]\nstart_s = 1000.0\nrate = 1.0\n\n[[layer]]\nid = 3\ntype = \"stratus\"\nbase_m = 300.0\n" +
    "thickness_m = 400.0\ntransition_band_m = 50.0\ncoverage = 0.7\ndensity = 1.0\n" +
    "wind = { speed_mps = 4.0, from_deg = 90.0, vertical_mps = 0.0 }\n";
  const good = path.join(w.dir, "fog-lifts.toml");
  fs.writeFileSync(good, start + "\n[[timeline]]\nat_s = 1600\nop = \"remove_layer\"\nid = 3\nramp_s = 300\n");
  const bad = path.join(w.dir, "bad.toml");
  const badText = start.replace("coverage = 0.7", "coverage = 1.7");
  fs.writeFileSync(bad, badText);
  const badLine = badText.split("\n").findIndex((l) => l.startsWith("coverage")) + 1;
  const allowed = [
    { text: /status of 400/, url: /\/api\/scenario$/, why: "the bad scenario this test loads" }];
  const a = await openConsole(browser, w, { token: TOKEN, allowed, name: "A" });
  await a.page.setInputFiles('#scenario-form [name="scenario"]', good);
  await a.page.click("#scenario-load");
  await until("loaded", async () => /loaded fog-lifts\.toml/.test(await a.page.textContent("#clock .note")));
  const s = await w.state();
  assert(s.layers.length === 1 && s.layers[0].id === 3 && s.layers[0].coverage === 0.7, `the start: ${JSON.stringify(s.layers)}`);
  assert(s.pending.some((p) => p.start_s === 1600 && p.end_s === 1900), `the timeline pending: ${JSON.stringify(s.pending)}`);
  await until("the timeline entry in the page", async () => /at 00:26:40/.test(await a.page.textContent("#timeline-list")));
  await a.page.setInputFiles('#scenario-form [name="scenario"]', bad);
  await a.page.click("#scenario-load");
  await until("the refusal naming the line", async () =>
    new RegExp(`bad\\.toml:${badLine}\\b`).test(await a.page.textContent("#scenario-error")));
  assert((await w.state()).sequence === s.sequence, "a refused scenario changes nothing");
  noProblems(a.problems);
};

// Installed (cmake --install into a fresh prefix), skyshell-weatherd finds
// its console under <prefix>/share/skyshell/console without being told, and
// serves it at / and /console/*. No browser needed.
cases.installed = async (cleanup) => {
  const build = process.env.SKY_BUILD_DIR;
  if (!build) throw new Error("SKY_BUILD_DIR must be set");
  const prefix = path.join(config.out, "prefix");
  fs.rmSync(prefix, { recursive: true, force: true });
  execFileSync(process.env.SKY_CMAKE || "cmake", ["--install", build, "--prefix", prefix], { stdio: "pipe" });
  const installed = path.join(prefix, "bin", "skyshell-weatherd");
  assert(fs.existsSync(path.join(prefix, "share", "skyshell", "console", "index.html")), "index.html installed");
  const w = new Weatherd("installed");
  config.weatherd = installed;
  await w.start();
  cleanup(() => w.stop());
  const root = await fetch(`${w.base}/`);
  assert(root.status === 200 && /text\/html/.test(root.headers.get("content-type")), `GET / ${root.status}`);
  assert(/Skyshell weather console/.test(await root.text()), "the console's page");
  const js = await fetch(`${w.base}/console/app.js`);
  assert(js.status === 200 && /text\/javascript/.test(js.headers.get("content-type")), "app.js as JavaScript");
  const logged = w.log();
  assert(logged.includes(path.join(prefix, "share", "skyshell", "console")), `served from the prefix: ${logged}`);
  // The map library and the Natural Earth data are installed and served
  // with the page, each with its licence.
  for (const [file, type] of [["leaflet.js", /text\/javascript/], ["leaflet.css", /text\/css/],
    ["topojson-client.min.js", /text\/javascript/], ["countries-50m.json", /application\/json/],
    ["leaflet-LICENSE.txt", /text\/plain/], ["topojson-client-LICENSE.txt", /text\/plain/],
    ["world-atlas-LICENSE.txt", /text\/plain/]]) {
    const r = await fetch(`${w.base}/console/${file}`);
    assert(r.status === 200 && type.test(r.headers.get("content-type")), `${file}: ${r.status} ${r.headers.get("content-type")}`);
  }
  const topo = await (await fetch(`${w.base}/console/countries-50m.json`)).json();
  assert(topo.type === "Topology" && topo.objects.land && topo.objects.countries, "Natural Earth's land and countries");
};

// The wind field at a height (GET /api/wind) over a NAM forecast of the
// central US at 6000 m: the map draws an arrow per answered point, the field
// varies (arrows differ in direction), and the arrow nearest the centre is
// drawn where the server's answer puts it, pointing downwind as the answer
// says (the page's own query asked again by this test; the arrow's place
// and direction measured from the drawn SVG against Web Mercator computed
// here). A click on it shows its wind; the address keeps the height.
cases.wind_field = async (cleanup) => {
  if (!config.namGrib) throw new Error("SKY_NAM_GRIB must be set");
  const { w, browser } = await setup("wind_field", cleanup, { args: ["--grib", config.namGrib] });
  await until("the forecast's wind tiles", async () => {
    const r = await w.api("GET", "/api/wind?lat_deg=38&lon_deg=-97&alt_m=6000&radius_m=300000");
    return r.status === 200 && r.json.varying_layers.length > 0;
  }, 30000);
  const a = await openConsole(browser, w, { name: "A", hash: "#focus=38,-97&zoom=6" });
  const asked = [];
  a.page.on("request", (r) => { if (/\/api\/wind\?/.test(r.url())) asked.push(r.url()); });
  await a.page.selectOption("#wind-units", "m");
  await a.page.fill("#wind-height", "6000");
  await a.page.press("#wind-height", "Enter");
  await a.page.check("#show-wind-field");
  await settled(a.page, w);
  const deg = (r) => ((r * 180) / Math.PI + 360) % 360;
  const angleBetween = (x, y) => Math.abs(((x - y + 540) % 360) - 180);
  let drawn = [];
  // The page's last query, answered again for this test, against what is
  // drawn (a refresh may be on its way: tried until the two are of one answer).
  const checked = await until("the arrow at the centre drawn as GET /api/wind answers", async () => {
    if ((await a.page.getAttribute("svg.wind-field", "data-alt-m")) !== "6000") return false;
    drawn = (await a.page.evaluate(() => {
      const svg = document.querySelector("svg.wind-field").getBoundingClientRect();
      return [...document.querySelectorAll("svg.wind-field path.wind-arrow:not(.wind-calm)")].map((p) => {
        const [x0, y0, x1, y1] = p.getAttribute("d").match(/-?\d+(\.\d+)?/g).map(Number);
        return { x0: svg.left + x0, y0: svg.top + y0, x1: svg.left + x1, y1: svg.top + y1 };
      });
    })).map((d) => ({ x: (d.x0 + d.x1) / 2, y: (d.y0 + d.y1) / 2, toward_deg: deg(Math.atan2(d.x1 - d.x0, d.y0 - d.y1)) }));
    if (drawn.length <= 50 || asked.length === 0) return false;
    const url = new URL(asked[asked.length - 1]);
    assert(url.searchParams.get("alt_m") === "6000", `the page asks at 6000 m: ${url}`);
    const answer = (await w.api("GET", url.pathname + url.search)).json;
    const { cx, cy } = await mapCentre(a.page);
    const [lat0, lon0] = (await a.page.getAttribute("#map", "data-focus")).split(",").map(Number);
    const zoom = Number(await a.page.getAttribute("#map", "data-zoom"));
    let best = null;
    for (const arrow of answer.arrows) {
      const o = offsetPx(lat0, lon0, zoom, arrow.lat_deg, arrow.lon_deg);
      const at = { x: cx + o.x, y: cy + o.y };
      const d = Math.hypot(o.x, o.y);
      if (!best || d < best.d) best = { arrow, at, d };
    }
    const mark = drawn.find((m) => Math.hypot(m.x - best.at.x, m.y - best.at.y) < 2);
    if (!mark) return false;
    const want = (best.arrow.from_deg + 180) % 360;
    if (angleBetween(mark.toward_deg, want) > 3) return false;
    return { ...best, mark, want, url: String(url), count: answer.arrows.length };
  }, 30000, 500);
  let spread = 0;
  for (const m of drawn) for (const n of drawn) spread = Math.max(spread, angleBetween(m.toward_deg, n.toward_deg));
  console.log(`  ${drawn.length} arrows drawn (${checked.count} answered) for ${checked.url}; directions span ${spread.toFixed(1)}°`);
  console.log(`  at ${checked.arrow.lat_deg.toFixed(3)}, ${checked.arrow.lon_deg.toFixed(3)}: ` +
    `${checked.arrow.speed_mps.toFixed(1)} m/s from ${checked.arrow.from_deg.toFixed(1)}°, drawn toward ` +
    `${checked.mark.toward_deg.toFixed(1)}° (want ${checked.want.toFixed(1)}°)`);
  assert(drawn.length > 50, `more than 50 arrows: ${drawn.length}`);
  assert(spread > 10, `the field varies: directions span ${spread.toFixed(1)}°`);
  // A click on the arrow tells its wind.
  await a.page.mouse.click(checked.mark.x, checked.mark.y);
  const popup = await until("the arrow's popup", async () => {
    const t = await a.page.textContent(".wind-popup").catch(() => "");
    return /Wind at 6000 m/.test(t) && t;
  });
  assert(popup.includes(`from ${Number(checked.arrow.from_deg.toFixed(0))}°`) &&
    popup.includes(`${Number(checked.arrow.speed_mps.toFixed(1))} m/s`), `the popup tells the wind: ${popup}`);
  await until("the height in the address", async () => /wind_alt_m=6000\b/.test(await a.page.evaluate(() => location.hash)));
  noProblems(a.problems);
};

// The weather radar on the map (GET /api/radar): with rain of 10 mm/h
// everywhere up to 2 km, the checkbox draws the picture round the view's
// centre; what the page drew is the server's answer to the page's own query
// (asked again here), Marshall-Palmer's 39.0 dBZ (10 log10(200 x 10^1.6),
// the 8-bit tiles within 0.2 dB), and its centre has the 35-40 dBZ colour.
cases.radar = async (cleanup) => {
  const { w, browser } = await setup("radar", cleanup);
  const r = await w.api("POST", "/api/changes", { author: "radar-test", changes: [{ op: "set_layer", layer: {
    id: 9, type: "rain", base_m: 0, thickness_m: 2000, transition_band_m: 0, coverage: 1, density: 0.1067,
    wind: { speed_mps: 5, from_deg: 270, vertical_mps: 0 } } }] });
  assert(r.status === 200, `API change: ${r.text}`);
  const a = await openConsole(browser, w, { name: "A", hash: "#focus=46.2,14.5&zoom=8" });
  await a.page.check("#show-radar");
  const drawn = await until("the radar picture", async () => {
    const d = await a.page.evaluate(() => ({ ...document.querySelector("#map").dataset }));
    return d.radarQuery && Number(d.radarEchoes) > 0 && d;
  }, 30000);
  const answer = (await w.api("GET", drawn.radarQuery)).json;
  console.log(`  ${drawn.radarQuery}: ${drawn.radarEchoes} cells echo, max ${drawn.radarMaxDbz} dBZ`);
  assert(Number(drawn.radarMaxDbz) === answer.max_dbz, `the page drew the server's answer: ${drawn.radarMaxDbz} vs ${answer.max_dbz}`);
  assert(Math.abs(answer.max_dbz - 39.0) < 0.2, `Marshall-Palmer of 10 mm/h: ${answer.max_dbz}`);
  const centre = await a.page.evaluate(async () => {
    const img = document.querySelector("img.radar-image");
    if (!img.complete) await new Promise((res) => img.addEventListener("load", res, { once: true }));
    const c = document.createElement("canvas");
    c.width = img.naturalWidth;
    c.height = img.naturalHeight;
    const g = c.getContext("2d");
    g.drawImage(img, 0, 0);
    return [...g.getImageData(c.width / 2, c.height / 2, 1, 1).data];
  });
  assert(centre[0] === 253 && centre[1] === 248 && centre[2] === 2, `the 35-40 dBZ colour at the centre: ${centre}`);
  // Unchecked: gone.
  await a.page.uncheck("#show-radar");
  await until("the picture removed", async () => (await a.page.$("img.radar-image")) === null);
  noProblems(a.problems);
};

// A precipitation layer's type edited as an operator does it: rain of
// density 0.2 (an extinction of 2 /km, exact in the stream's 8 bits) up to
// 2 km, its row picked in the layer table, its type set to snow, applied
// with the token. GET /api/state then has layer 9 as snow with every other
// value as it was, and GET /api/conditions 500 m up under it answers snow at
// the rate the snow law gives for that extinction (3.5 R^0.7 /km = 2: 0.449
// mm/h; it answered rain at 0.25 R^0.63 /km = 2: 27.1 mm/h before) with
// Gunn-Marshall's 26.1 dBZ (10 log10(2000 R^2)) and the same visibility (the
// density is the extinction, whatever the type). The refused edits leave
// the state and the answer as they were: a density of 1.5 (refused next to
// its field, nothing sent); a second page, its editor disabled without the
// token, and with a wrong one the server's 401 (read-only again after);
// through the API hail of density 1.5 with the token (400 naming the
// density) and hail without the token (401).
cases.precipitation_type = async (cleanup) => {
  const { w, browser } = await setup("precipitation_type", cleanup);
  const density = 0.2, extinction_perkm = 10 * density;  // 0.01 /m per unit density (precipitation.hpp)
  const rain = { id: 9, type: "rain", base_m: 0, thickness_m: 2000, transition_band_m: 0, coverage: 1, density,
    wind: { speed_mps: 5, from_deg: 270, vertical_mps: 0 } };
  const r = await w.api("POST", "/api/changes", { author: "precipitation-test",
    changes: [{ op: "set_layer", layer: rain }] });
  assert(r.status === 200, `API change: ${r.text}`);
  // The layers as the server states them (its key order), to compare with after.
  const start = await w.state();
  const rain9 = start.layers.find((l) => l.id === 9), layer1 = start.layers.find((l) => l.id === 1);
  assert(rain9 && rain9.type === "rain" && rain9.density === density, `layer 9 as sent: ${JSON.stringify(rain9)}`);
  const point = "/api/conditions?lat_deg=46.2&lon_deg=14.5&alt_m=500";
  const conditions = async () => {
    const c = await w.api("GET", point);
    assert(c.status === 200, `GET ${point}: ${c.status} ${c.text}`);
    return c.json;
  };
  const rainRate_mmph = (extinction_perkm / 0.25) ** (1 / 0.63), snowRate_mmph = (extinction_perkm / 3.5) ** (1 / 0.7);
  const before = await until("rain at the point", async () => {
    const c = await conditions();
    return c.precipitation && c.precipitation.type === "rain" && c;
  });
  console.log(`  before: ${JSON.stringify(before.precipitation)}, visibility ${before.visibility_m} m`);
  near(before.precipitation.rate_mmph, rainRate_mmph, 0.01 * rainRate_mmph, "rain's rate at 2 /km");

  const allowed = [{ text: /status of 401/, url: /\/api\/changes$/, why: "page B's wrong token, refused on purpose" }];
  const a = await openConsole(browser, w, { token: TOKEN, name: "A" });
  const typeField = '#layer-form [name="type"]';
  await until("layer 9 in the table", async () => /rain/.test(await rowText(a.page, 9)));
  await a.page.click('#layer-table tbody tr[data-id="9"]');
  assert((await a.page.inputValue(typeField)) === "rain", "the editor shows layer 9's type");
  await a.page.selectOption(typeField, "snow");
  const edited = Date.now();
  await a.page.click("#layer-apply");
  await until("A's note to say applied", async () => /applied #/.test(await a.page.textContent("#layers .note")));
  const s = await w.state();
  const l9 = s.layers.find((l) => l.id === 9);
  assert(JSON.stringify(l9) === JSON.stringify({ ...rain9, type: "snow" }),
    `layer 9 as snow, nothing else changed: ${JSON.stringify(l9)} (was ${JSON.stringify(rain9)})`);
  assert(JSON.stringify(s.layers.find((l) => l.id === 1)) === JSON.stringify(layer1), "layer 1 untouched");
  const after = await until("snow at the point", async () => {
    const c = await conditions();
    return c.precipitation && c.precipitation.type === "snow" && c;
  });
  console.log(`  after: ${JSON.stringify(after.precipitation)}, visibility ${after.visibility_m} m ` +
    `(${Date.now() - edited} ms from Apply)`);
  near(after.precipitation.rate_mmph, snowRate_mmph, 0.01 * snowRate_mmph, "snow's rate at 2 /km");
  near(after.precipitation.reflectivity_dbz, 10 * Math.log10(2000 * snowRate_mmph ** 2), 0.1, "Gunn-Marshall dBZ");
  near(after.visibility_m, before.visibility_m, 0.005 * before.visibility_m, "the same extinction, the same visibility");
  await until("A's table to say snow", async () => /snow/.test(await rowText(a.page, 9)));

  // What the refused edits must leave as it is.
  const unchanged = async (what) => {
    const now = await w.state();
    assert(now.sequence === s.sequence && JSON.stringify(now.layers) === JSON.stringify(s.layers),
      `${what} changed the state: ${JSON.stringify(now.layers)}`);
    const c = await conditions();
    assert(c.precipitation && c.precipitation.type === "snow" &&
      Math.abs(c.precipitation.rate_mmph - after.precipitation.rate_mmph) < 1e-9,
    `${what} changed the point's answer: ${JSON.stringify(c.precipitation)}`);
  };
  // A's draft with a density out of range: named next to the field, not sent.
  let posts = 0;
  a.page.on("request", (req) => { if (req.method() === "POST") ++posts; });
  await a.page.selectOption(typeField, "hail");
  await a.page.fill('#layer-form [name="density"]', "1.5");
  await a.page.click("#layer-apply");
  await new Promise((res) => setTimeout(res, 500));
  const densityError = await a.page.textContent('#layer-form [data-err="density"]');
  assert(/outside 0–1/.test(densityError), `the density's message: ${densityError}`);
  assert(posts === 0, `a draft with density 1.5 was sent (${posts} POSTs)`);
  await unchanged("a draft with density 1.5");
  // B without the token: read-only; with a wrong one the server refuses.
  const b = await openConsole(browser, w, { name: "B", allowed });
  for (const sel of ["#layer-apply", typeField]) assert(await b.page.isDisabled(sel), `${sel} disabled in B without the token`);
  await b.page.fill('[name="token"]', "not-the-token");
  await b.page.click("#token-use");
  await b.page.click('#layer-table tbody tr[data-id="9"]');
  await b.page.selectOption(typeField, "hail");
  await b.page.click("#layer-apply");
  await until("B's refusal", async () => /refused the token/.test(await b.page.textContent("#layers .note")));
  assert(/read-only/.test(await b.page.textContent("#token-state")), "B is read-only after the refusal");
  await unchanged("B's edit with a wrong token");
  // The API's own refusals, asked from outside the browser.
  const hail = { ...rain, type: "hail" };
  const bad = await w.api("POST", "/api/changes", { changes: [{ op: "set_layer", layer: { ...hail, density: 1.5 } }] });
  assert(bad.status === 400 && bad.json && /density/.test(bad.json.error), `hail of density 1.5: ${bad.status} ${bad.text}`);
  console.log(`  refused: ${bad.text}`);
  const noToken = await w.api("POST", "/api/changes", { changes: [{ op: "set_layer", layer: hail }] }, null);
  assert(noToken.status === 401, `hail without the token: ${noToken.status} ${noToken.text}`);
  await unchanged("the API's refused edits");
  noProblems(a.problems, b.problems);
};

// Lightning asked for from the console (POST /api/events): an in-cloud
// flash at the map's centre as the page reports it (#map data-focus) is in
// GET /api/events, asked here, at that place (1e-6 deg) and of that kind; the
// page draws its marker where Web Mercator, computed here, puts that place;
// the API refuses a flash without the token (401) and one off the globe (400
// naming the field).
cases.lightning = async (cleanup) => {
  const { w, browser } = await setup("lightning", cleanup);
  const a = await openConsole(browser, w, { token: TOKEN, name: "A", hash: "#focus=46.1,13.2&zoom=9" });
  await settled(a.page, w);
  await a.page.selectOption("#lightning-kind", "in-cloud");
  const [lat0, lon0] = (await a.page.getAttribute("#map", "data-focus")).split(",").map(Number);
  await a.page.click("#lightning-flash");
  await until("the page's note to say a flash", async () => /in-cloud flash at/.test(await a.page.textContent("#lightning .note")));
  const flash = await until("the flash in GET /api/events", async () => {
    const r = await w.api("GET", "/api/events?limit=50");
    assert(r.status === 200 && Array.isArray(r.json.lightning), `GET /api/events: ${r.text}`);
    return r.json.lightning.find((f) => Math.abs(f.lat_deg - lat0) <= 1e-6 && Math.abs(f.lon_deg - lon0) <= 1e-6);
  });
  console.log(`  flash ${flash.seed} at ${flash.lat_deg}, ${flash.lon_deg} (centre ${lat0}, ${lon0}), ` +
    `${flash.kind}, ${flash.bottom_m}-${flash.top_m} m, clock ${flash.time_s} s`);
  assert(flash.kind === "in-cloud", `the flash is in-cloud: ${flash.kind}`);
  const marker = `.flash[data-seed="${flash.seed}"]`;
  await until("the flash's marker", async () => (await a.page.$(marker)) !== null);
  assert((await a.page.getAttribute(marker, "data-kind")) === "in-cloud", "the marker is of the flash's kind");
  assert(Number(await a.page.getAttribute("#map", "data-flashes")) >= 1, "the map counts the flash drawn");
  const box = await a.page.locator(marker).boundingBox();
  const want = await screenOf(a.page, flash.lat_deg, flash.lon_deg);
  const off_px = Math.hypot(box.x + box.width / 2 - want.x, box.y + box.height / 2 - want.y);
  assert(off_px < 2, `the marker is drawn at the flash: ${off_px.toFixed(2)} px off`);
  const opacity = Number(await a.page.$eval(marker, (e) => e.style.opacity));
  assert(opacity > 0.5, `a new flash is nearly opaque: ${opacity}`);
  // The API's refusals, asked from outside the browser.
  const place = { lat_deg: 46.1, lon_deg: 13.2 };
  const noToken = await w.api("POST", "/api/events", { lightning: place }, null);
  assert(noToken.status === 401, `a flash without the token: ${noToken.status} ${noToken.text}`);
  const offGlobe = await w.api("POST", "/api/events", { lightning: { ...place, lat_deg: 95 } });
  assert(offGlobe.status === 400 && offGlobe.json && offGlobe.json.field === "lightning.lat_deg" &&
    /lightning\.lat_deg/.test(offGlobe.json.error), `a flash at 95 N: ${offGlobe.status} ${offGlobe.text}`);
  noProblems(a.problems);
};

const name = process.argv[2];
if (!cases[name]) {
  console.log(`usage: node console_test.mjs <${Object.keys(cases).join("|")}>`);
  process.exit(2);
}
run(name, (cleanup) => cases[name](cleanup));
