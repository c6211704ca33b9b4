// Test harness of the console's browser tests: a real skyshell-weatherd on
// ephemeral loopback ports with a token file, and Debian's Chromium driven by
// playwright-core. Every page is watched: an uncaught exception or an error
// in Chromium's console fails the test, unless the test declared that exact
// kind of message expected (a refusal it provokes on purpose, a server it
// stops) and says why.
import { spawn } from "node:child_process";
import crypto from "node:crypto";
import fs from "node:fs";
import http from "node:http";
import path from "node:path";

export const SKIP = 77;  // ctest SKIP_RETURN_CODE

// Every process a test starts, killed when this one exits however it exits
// (a failed assertion, an exception, SIGTERM/SIGINT), so none outlives it.
const children = new Set();
process.on("exit", () => { for (const p of children) if (p.exitCode === null && p.signalCode === null) p.kill("SIGKILL"); });
for (const signal of ["SIGTERM", "SIGINT"]) process.on(signal, () => process.exit(1));
function track(proc) {
  children.add(proc);
  proc.on("exit", () => children.delete(proc));
  return proc;
}
export const TOKEN = "console-test-token";

const env = (name, fallback) => process.env[name] || fallback;
export const config = {
  weatherd: env("SKY_WEATHERD"),
  render: env("SKY_RENDER"),
  replay: env("SKY_REPLAY"),
  flight: env("SKY_TEST_FLIGHT"),
  scenario: env("SKY_SCENARIO"),
  stations: env("SKY_METAR_STATIONS"),
  namGrib: env("SKY_NAM_GRIB"),
  out: env("SKY_CONSOLE_OUTPUT_DIR", path.resolve("console-output")),
  chromium: env("SKY_CHROMIUM", "/usr/bin/chromium"),
};

// Thrown to end a test as skipped; run() stops what the test started first.
class Skipped extends Error {}
export function skip(reason) {
  throw new Skipped(reason);
}

// The flags Chromium needs on this machine (.library/env/machines/cpp.md):
// no sandbox as root, no GPU, and no background networking, whose
// connections a closed network refuses.
const CHROMIUM_ARGS = ["--disable-gpu", "--disable-quic", "--no-first-run", "--disable-background-networking",
  "--disable-component-update", "--disable-sync", "--disable-dev-shm-usage"];

export async function loadPlaywright() {
  if (Number(process.versions.node.split(".")[0]) < 20) skip(`playwright-core needs Node.js 20, this is ${process.version}`);
  if (!fs.existsSync(config.chromium)) skip(`no Chromium at ${config.chromium} (Debian package chromium; deploy/setup)`);
  try {
    return await import("playwright-core");
  } catch {
    return skip("playwright-core is not installed (deploy/test runs npm ci in tests/console)");
  }
}

export async function launch() {
  const { chromium } = await loadPlaywright();
  return chromium.launch({ executablePath: config.chromium, headless: true, chromiumSandbox: false, args: CHROMIUM_ARGS });
}

export async function until(what, fn, timeout_ms = 20000, every_ms = 100) {
  const deadline = Date.now() + timeout_ms;
  let last;
  for (;;) {
    try {
      last = await fn();
      if (last) return last;
    } catch (e) {
      last = e;
    }
    if (Date.now() > deadline) throw new Error(`timed out waiting for ${what} (last: ${last})`);
    await new Promise((r) => setTimeout(r, every_ms));
  }
}

// One skyshell-weatherd: start(), stop(), restart() on the same ports and
// file. args: more command-line arguments (a forecast: ["--grib", FILE]).
export class Weatherd {
  constructor(name, { db = false, args = [] } = {}) {
    if (!config.weatherd || !config.scenario) throw new Error("SKY_WEATHERD and SKY_SCENARIO must be set");
    this.dir = path.join(config.out, name);
    fs.rmSync(this.dir, { recursive: true, force: true });
    fs.mkdirSync(this.dir, { recursive: true });
    fs.writeFileSync(path.join(this.dir, "token"), `${TOKEN}\n`);
    this.db = db ? path.join(this.dir, "weather.sqlite") : null;
    this.extraArgs = args;
    this.httpPort = 0;
    this.starts = 0;
  }

  async start() {
    const portFile = path.join(this.dir, "http.port");
    const streamPortFile = path.join(this.dir, "stream.port");
    fs.rmSync(portFile, { force: true });
    const args = ["--scenario", config.scenario, "--port", "0", "--port-file", streamPortFile,
      "--http-port", String(this.httpPort),
      "--http-port-file", portFile, "--token-file", path.join(this.dir, "token"), "--heartbeat-ms", "200"];
    if (config.stations) args.push("--metar-stations", config.stations);
    if (this.db) args.push("--db", this.db);
    args.push(...this.extraArgs);
    // The CIGI weather input too (UDP, loopback): a host's Weather Control
    // reaches the consoles like an API change.
    const cigiPortFile = path.join(this.dir, "cigi.port");
    fs.rmSync(cigiPortFile, { force: true });
    args.push("--cigi-port", "0", "--cigi-port-file", cigiPortFile);
    const log = fs.openSync(path.join(this.dir, `weatherd-${++this.starts}.log`), "w");
    this.proc = track(spawn(config.weatherd, args, { stdio: ["ignore", log, log] }));
    this.exited = new Promise((resolve) => this.proc.on("exit", (code, signal) => resolve({ code, signal })));
    const port = await until("the HTTP port file", async () => {
      const r = await Promise.race([this.exited.then((e) => ({ exit: e })), new Promise((res) => setTimeout(res, 50))]);
      if (r && r.exit) throw new Error(`skyshell-weatherd exited ${JSON.stringify(r.exit)}: ${this.log()}`);
      return fs.existsSync(portFile) ? Number(fs.readFileSync(portFile, "utf8")) : 0;
    }, 30000, 50).catch((e) => { throw new Error(`${e.message}\n${this.log()}`); });
    this.httpPort = port;
    this.streamPort = Number(fs.readFileSync(streamPortFile, "utf8"));
    this.cigiPort = await until("the CIGI port file", async () =>
      fs.existsSync(cigiPortFile) ? Number(fs.readFileSync(cigiPortFile, "utf8")) : 0, 10000, 50);
    this.base = `http://127.0.0.1:${port}`;
    return this;
  }

  log() {
    return fs.readFileSync(path.join(this.dir, `weatherd-${this.starts}.log`), "utf8");
  }

  async stop() {
    if (!this.proc || this.proc.exitCode !== null || this.proc.signalCode !== null) return;
    this.proc.kill("SIGTERM");
    const timer = setTimeout(() => this.proc.kill("SIGKILL"), 10000);
    await this.exited;
    clearTimeout(timer);
  }

  // A request to the API from outside the browser (the independent view):
  // an object body goes as JSON, a string as it is.
  async api(method, target, body, token = TOKEN) {
    const headers = { "Content-Type": typeof body === "string" ? "text/plain" : "application/json" };
    if (token) headers.Authorization = `Bearer ${token}`;
    const r = await fetch(this.base + target, { method, headers,
      body: body === undefined ? undefined : typeof body === "string" ? body : JSON.stringify(body) });
    const text = await r.text();
    let json = null;
    try { json = JSON.parse(text); } catch { /* not JSON */ }
    return { status: r.status, json, text };
  }

  async state() {
    return (await this.api("GET", "/api/state")).json;
  }

  // Whether GET /api/ws upgrades to a WebSocket (a handshake by hand: Node 20
  // has no WebSocket client).
  hasWebSocket() {
    return new Promise((resolve) => {
      const req = http.request({
        host: "127.0.0.1", port: this.httpPort, path: "/api/ws",
        headers: { Connection: "Upgrade", Upgrade: "websocket", "Sec-WebSocket-Version": "13",
          "Sec-WebSocket-Key": crypto.randomBytes(16).toString("base64") },
      });
      req.on("upgrade", (res, socket) => { socket.destroy(); resolve(true); });
      req.on("response", (res) => { res.resume(); resolve(false); });
      req.on("error", () => resolve(false));
      req.end();
    });
  }
}

// A child process with its output in `dir`/`name`.log, stopped by stop().
export function child(dir, name, file, args, extraEnv = {}) {
  const log = fs.openSync(path.join(dir, `${name}.log`), "w");
  const proc = track(spawn(file, args, { stdio: ["ignore", log, log], env: { ...process.env, ...extraEnv } }));
  const exited = new Promise((resolve) => proc.on("exit", (code, signal) => resolve({ code, signal })));
  return {
    proc, exited,
    log: () => fs.readFileSync(path.join(dir, `${name}.log`), "utf8"),
    async stop() {
      if (proc.exitCode !== null || proc.signalCode !== null) return;
      proc.kill("SIGTERM");
      const timer = setTimeout(() => proc.kill("SIGKILL"), 10000);
      await exited;
      clearTimeout(timer);
    },
  };
}

// Watches a page: console errors and uncaught exceptions are failures unless
// one of `allowed` ({text: RegExp, url?: RegExp, why}) matches.
export function watch(page, name, allowed = []) {
  const problems = [];
  page.on("pageerror", (e) => problems.push(`${name}: uncaught ${e.message}`));
  page.on("console", (msg) => {
    if (msg.type() !== "error") return;
    const url = (msg.location() && msg.location().url) || "";
    const ok = allowed.some((a) => a.text.test(msg.text()) && (!a.url || a.url.test(url)));
    if (ok) console.log(`  (expected in ${name}: ${msg.text()} ${url})`);
    else problems.push(`${name}: console error: ${msg.text()} ${url}`);
  });
  return problems;
}

// routes: { "/api/path": body } answered by the browser with that JSON (a
// fixture, for what this server cannot show, e.g. a NATS cluster).
export async function openConsole(browser, weatherd, { token = null, hash = "", allowed = [], name = "page",
  viewport = { width: 1600, height: 1000 }, routes = {} } = {}) {
  const context = await browser.newContext({ viewport });
  for (const [route, body] of Object.entries(routes))
    await context.route(`**${route}`, (r) => r.fulfill({ status: 200, contentType: "application/json",
      body: JSON.stringify(body) }));
  const page = await context.newPage();
  const problems = watch(page, name, allowed);
  await page.goto(`${weatherd.base}/${hash}`);
  await until(`${name} to connect`, async () => ["live", "polling"].includes(await page.getAttribute("body", "data-link")));
  if (token) {
    await page.fill('[name="token"]', token);
    await page.click("#token-use");
  }
  await until(`${name} to show the state`, async () => (await page.getAttribute("body", "data-sequence")) !== null);
  return { page, context, problems };
}

// Runs one named test: exits 0 when it passed, 1 when it failed (with the
// reason), SKIP when it cannot run here.
export async function run(name, body) {
  const cleanups = [];
  let failed = null;
  try {
    await body((fn) => cleanups.push(fn));
  } catch (e) {
    failed = e;
  }
  for (const fn of cleanups.reverse()) {
    try { await fn(); } catch (e) { if (!failed) failed = e; }
  }
  if (failed instanceof Skipped) {
    // deploy/test installed Node.js, Chromium and playwright-core: there a
    // missing one is a broken set-up, not a reason to skip.
    if (process.env.SKY_REQUIRE_DEPS === "1") {
      console.log(`FAILED: ${failed.message} (SKY_REQUIRE_DEPS=1: deploy/setup installs it, so it must be usable)`);
      process.exit(1);
    }
    console.log(`SKIPPED: ${failed.message}`);
    process.exit(SKIP);
  }
  if (failed) {
    console.log(`FAILED ${name}: ${failed.stack || failed}`);
    process.exit(1);
  }
  console.log(`PASSED ${name}`);
  process.exit(0);
}

export function assert(cond, message) {
  if (!cond) throw new Error(`assertion failed: ${message}`);
}

export function near(actual, expected, tolerance, what) {
  assert(Math.abs(actual - expected) <= tolerance, `${what}: ${actual} is not within ${tolerance} of ${expected}`);
}
