// The request loop of a map layer that shows the server's answer about the
// view (the radar picture, the wind field): asked for after a move settles,
// every refresh_ms while shown and when the weather changes, with at most one
// request in flight. An ask while one is in flight is made once that one is
// answered, with the view as it is then, so a burst of asks costs one more.

export class RequestLoop {
  // wanted(): whether the layer is shown on a map (nothing is asked
  // otherwise, and an answer that arrives after it was hidden is dropped).
  // send(): one request for the view now (async), resolving to its answer.
  // answered(answer): what the layer does with it.
  // settle_ms: how long after the last move the view is asked for, so a drag
  // or a few wheel notches make one request; refresh_ms: how often while
  // shown (ms). pauseHidden: a tab in the background skips its refreshes and
  // asks once it is shown again.
  constructor({ wanted, send, answered, settle_ms, refresh_ms, pauseHidden = false }) {
    Object.assign(this, { wanted, send, answered, settle_ms, refresh_ms, pauseHidden });
    this.inFlight = false;
    this.again = false;
    this.refreshSkipped = false;
    this.visible = () => {
      if (document.hidden || !this.refreshSkipped) return;
      this.refreshSkipped = false;
      this.ask();
    };
  }

  // The layer is on a map / off it.
  start() {
    if (this.pauseHidden) document.addEventListener("visibilitychange", this.visible);
  }
  stop() {
    if (this.pauseHidden) document.removeEventListener("visibilitychange", this.visible);
    this.cancel();
  }

  // The layer is hidden: no timer asks again until ask() is called.
  cancel() {
    clearTimeout(this.settleTimer);
    clearTimeout(this.refreshTimer);
    this.refreshSkipped = false;
  }

  // The view moved: ask once it has been still for settle_ms.
  moved() {
    clearTimeout(this.settleTimer);
    if (this.wanted()) this.settleTimer = setTimeout(() => this.ask(), this.settle_ms);
  }

  // Asks now, or right after the request in flight.
  async ask() {
    if (!this.wanted()) return;
    if (this.inFlight) {
      this.again = true;
      return;
    }
    clearTimeout(this.refreshTimer);
    this.inFlight = true;
    const answer = await this.send();
    this.inFlight = false;
    if (!this.wanted()) return;
    this.answered(answer);
    if (this.again) {
      this.again = false;
      this.ask();
    } else {
      this.refreshTimer = setTimeout(() => {
        if (this.pauseHidden && document.hidden) this.refreshSkipped = true;
        else this.ask();
      }, this.refresh_ms);
    }
  }
}
