// The page's modes (design: dragging; run: a run made here; replay: a Python run) and the
// timeline of the timed ones: the scrubber, the frame shown, playing.
import { $, app } from "./state.js";
import { runState, showState, stopMode } from "./view.js";

/** Show frame i of the run (or of a loaded Python run). */
export function setFrame(i) {
  const src = app.mode === "replay" ? app.replay : app.run;
  app.frame = Math.max(0, Math.min(src.t.length - 1, i));
  $("scrub").value = app.frame;
  $("time").textContent = `t = ${src.t[app.frame].toFixed(3)} s`;
  if (app.mode === "run") {
    const r = app.run, m = app.info.dof, P = app.info.points.length, nx = app.info.x0.length;
    app.q = r.q.slice(app.frame * m, (app.frame + 1) * m);
    const x = r.x.slice(app.frame * nx, (app.frame + 1) * nx);
    app.ev = { x, points: r.points.subarray(app.frame * 2 * P, (app.frame + 1) * 2 * P), reactions: runState().reactions };
  }
  document.body.dataset.frame = app.frame;
  showState();
}

export function setMode(mode) {
  stopMode();
  app.mode = mode;
  const timed = mode !== "design";
  const src = mode === "replay" ? app.replay : app.run;
  $("scrub").disabled = $("play").disabled = !timed;
  $("design").disabled = mode !== "run";
  $("simulate").disabled = !app.mech;
  if (timed) {
    $("scrub").max = src.t.length - 1;
    setFrame(0);
  } else {
    play(false);
    $("time").textContent = "";
    showState();
  }
}

export function play(on) {
  app.playing = on;
  $("play").textContent = on ? "❚❚" : "▶";
  if (!on) return;
  const src = app.mode === "replay" ? app.replay : app.run;
  let last = performance.now();
  const t0 = src.t[0];
  let t = src.t[app.frame] - t0;
  const tick = (now) => {
    if (!app.playing || app.mode === "design") return;
    t += (now - last) / 1000;
    last = now;
    let i = app.frame;
    while (i + 1 < src.t.length && src.t[i + 1] - t0 <= t) i++;
    setFrame(i);
    if (i + 1 >= src.t.length) return play(false);
    requestAnimationFrame(tick);
  };
  requestAnimationFrame(tick);
}
