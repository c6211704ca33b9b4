// The request loop the radar and the wind field share
// (server/console/request_loop.js), without a browser: on a clock this test
// moves by hand, with requests it answers by hand, at most one request is in
// flight, asks during one cost one more request, a move is asked for once
// the map has been still for settle_ms, refreshes follow every refresh_ms,
// nothing is asked or taken while the layer is not wanted, and with
// pauseHidden a tab in the background skips its refreshes and asks once shown.
import { assert, run, skip } from "./harness.mjs";

// Timers on a clock moved by advance(); the loop reads the globals when it
// sets one, so replacing them here is enough.
const clock = { now_ms: 0, timers: new Map(), nextId: 1 };
globalThis.setTimeout = (fn, ms) => {
  clock.timers.set(clock.nextId, { at_ms: clock.now_ms + ms, fn });
  return clock.nextId++;
};
globalThis.clearTimeout = (id) => clock.timers.delete(id);
// Lets the loop's awaits run (the answers are promises).
const settle = () => new Promise((resolve) => setImmediate(resolve));
async function advance(ms) {
  const end_ms = clock.now_ms + ms;
  for (;;) {
    const due = [...clock.timers].filter(([, t]) => t.at_ms <= end_ms).sort((x, y) => x[1].at_ms - y[1].at_ms)[0];
    if (!due) break;
    clock.timers.delete(due[0]);
    clock.now_ms = due[1].at_ms;
    due[1].fn();
    await settle();
  }
  clock.now_ms = end_ms;
  await settle();
}

// The page's visibility: hidden, and its event.
globalThis.document = Object.assign(new EventTarget(), { hidden: false });
function setHidden(hidden) {
  document.hidden = hidden;
  document.dispatchEvent(new Event("visibilitychange"));
}

const SETTLE_MS = 300, REFRESH_MS = 5000;

// A layer on the loop: its requests wait for answer(); it counts what it sent and took.
function layer(RequestLoop, options = {}) {
  const l = { wanted: true, sent: 0, taken: [], pending: [] };
  l.loop = new RequestLoop({
    wanted: () => l.wanted,
    send: () => { ++l.sent; return new Promise((resolve) => l.pending.push(resolve)); },
    answered: (a) => l.taken.push(a),
    settle_ms: SETTLE_MS, refresh_ms: REFRESH_MS, ...options,
  });
  l.answer = async (value) => { l.pending.shift()(value); await settle(); };
  return l;
}

run("request_loop", async () => {
  if (Number(process.versions.node.split(".")[0]) < 20) skip(`Node.js 20 or newer needed, this is ${process.version}`);
  const { RequestLoop } = await import("../../server/console/request_loop.js");

  // One in flight; three asks meanwhile cost one more request, sent when the
  // first is answered; then one refresh per refresh_ms.
  let l = layer(RequestLoop);
  l.loop.start();
  l.loop.ask();
  l.loop.ask(); l.loop.ask(); l.loop.ask();
  assert(l.sent === 1, `one request in flight: ${l.sent} sent`);
  await l.answer("first");
  assert(l.sent === 2 && l.taken.join() === "first", `the asks meanwhile make one more: ${l.sent} sent, ${l.taken}`);
  await l.answer("second");
  await advance(REFRESH_MS - 1);
  assert(l.sent === 2, `no refresh before refresh_ms: ${l.sent} sent`);
  await advance(1);
  assert(l.sent === 3, `a refresh at refresh_ms: ${l.sent} sent`);
  await l.answer("refresh");
  // An ask in between starts the refresh period again.
  await advance(REFRESH_MS / 2);
  l.loop.ask();
  await l.answer("asked");
  await advance(REFRESH_MS - 1);
  assert(l.sent === 4, `the refresh follows the last answer: ${l.sent} sent`);
  await advance(1);
  assert(l.sent === 5, `... refresh_ms after it: ${l.sent} sent`);
  await l.answer("refresh");

  // Moves: one request settle_ms after the last one.
  for (let i = 0; i < 3; ++i) {
    l.loop.moved();
    await advance(SETTLE_MS - 1);
  }
  assert(l.sent === 5, `no request while the map moves: ${l.sent} sent`);
  await advance(1);
  assert(l.sent === 6, `one request once the map is still: ${l.sent} sent`);

  // Not wanted when the answer comes (the layer was hidden meanwhile): not
  // taken, and no refresh follows; cancel() stops the pending refresh and
  // a move's request.
  l.wanted = false;
  await l.answer("late");
  assert(!l.taken.includes("late"), "an answer that comes after the layer was hidden is dropped");
  l.loop.ask();
  l.loop.moved();
  await advance(10 * REFRESH_MS);
  assert(l.sent === 6, `nothing asked while hidden: ${l.sent} sent`);
  l.wanted = true;
  l.loop.ask();
  await l.answer("again");
  l.loop.moved();
  l.loop.cancel();
  await advance(10 * REFRESH_MS);
  assert(l.sent === 7, `cancel() stops the refresh and the move's request: ${l.sent} sent`);
  l.loop.stop();

  // Without pauseHidden a tab in the background refreshes as usual ...
  l = layer(RequestLoop);
  l.loop.start();
  l.loop.ask();
  await l.answer("shown");
  setHidden(true);
  await advance(REFRESH_MS);
  assert(l.sent === 2, `a background tab refreshes without pauseHidden: ${l.sent} sent`);
  await l.answer("refresh");
  l.loop.stop();
  setHidden(false);

  // ... with it, the refresh is skipped and made once the tab is shown again.
  l = layer(RequestLoop, { pauseHidden: true });
  l.loop.start();
  l.loop.ask();
  await l.answer("shown");
  setHidden(true);
  await advance(10 * REFRESH_MS);
  assert(l.sent === 1, `no refresh in a background tab: ${l.sent} sent`);
  setHidden(false);
  await settle();
  assert(l.sent === 2, `the skipped refresh made once shown: ${l.sent} sent`);
  await l.answer("back");
  setHidden(true);
  setHidden(false);
  assert(l.sent === 2, `shown again with no refresh skipped: nothing asked (${l.sent} sent)`);
  l.loop.stop();
  setHidden(true);
  await advance(REFRESH_MS);
  setHidden(false);
  assert(l.sent === 2, `a stopped loop does not refresh: ${l.sent} sent`);
});
