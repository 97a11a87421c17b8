// Designing: the coordinates' sliders, dragging any point, and the sweep of the active
// coordinate behind the quasi-static charts and the points' paths.
import { $, app, fmt, status, zeros } from "./state.js";
import { defaultChannels, seriesChannels, unitOf } from "./channels.js";
import { transform } from "./draw.js";
import { dragTowards } from "./drag.js";
import { coordinateRange } from "./map.js";
import { arrowTips, groundIndices, holdView, moveTo, showState } from "./view.js";
import { setMode } from "./timeline.js";
import { listModes } from "./modes.js";

/** States of a sweep of one coordinate (the quasi-static charts and the point paths). */
const SWEEP_STEPS = 180;
/** A pointer this close (px) to a point grabs it. */
const GRAB_PX = 18;

export function buildSliders() {
  const box = $("sliders");
  box.replaceChildren();
  app.info.coordinateNames.forEach((name, k) => {
    const [lo, hi] = coordinateRange(app.info, k, app.q[k]);
    const label = document.createElement("label");
    label.textContent = `${name} (${unitOf(app.info, k, "q")})`;
    label.htmlFor = `q-${k}`;
    const s = Object.assign(document.createElement("input"), { type: "range", id: `q-${k}`, min: lo, max: hi, step: (hi - lo) / 1000, value: app.q[k] });
    const out = Object.assign(document.createElement("output"), { id: `q-out-${k}` });
    s.addEventListener("input", () => {
      const q = Float64Array.from(app.q);
      q[k] = +s.value;
      if (app.mode !== "design") setMode("design");
      if (moveTo(q)) status(statusLine());
      showState();
    });
    s.addEventListener("change", () => { app.active = k; sweep(); showState(); });
    box.append(label, s, out);
  });
}

function statusLine() {
  return `${app.info.name}: σ = ${fmt(app.ev.sigma)}` + (app.ev.note ? ` — ${app.ev.note}` : "");
}

/** Sweep the active coordinate over its slider's range from the current state, both ways by
 * continuation: the quasi-static charts (efforts, reactions, measures against it) and the
 * points' paths. Stops where it no longer assembles. */
export function sweep() {
  const k = app.active;
  const [lo, hi] = coordinateRange(app.info, k, app.q[k]);
  const h = (hi - lo) / SWEEP_STEPS;
  const states = [];
  for (const dir of [-1, 1]) {
    let x = app.x;
    const side = [];
    for (let s = dir < 0 ? 1 : 0; s <= SWEEP_STEPS / 2; s++) {
      const q = Float64Array.from(app.q);
      q[k] += dir * s * h;
      try {
        const z = zeros();
        const ev = app.mech.evaluate(q, z, z, x);
        x = ev.x;
        side.push({ q, ev });
      } catch {
        break;
      }
    }
    states.push(...(dir < 0 ? side.reverse() : side));
  }
  const cat = (f) => { const parts = states.map(f); const out = new Float64Array(parts.reduce((n, p) => n + p.length, 0)); let o = 0; for (const p of parts) { out.set(p, o); o += p.length; } return out; };
  const series = {
    q: cat((s) => s.q), tau: cat((s) => s.ev.tau), potential: cat((s) => [s.ev.potential]),
    sigma: cat((s) => [s.ev.sigma]), reactions: cat((s) => s.ev.reactions), points: cat((s) => s.ev.points),
  };
  const P = app.info.points.length;
  const ground = new Set(groundIndices());
  app.paths = [...Array(P).keys()].filter((i) => !ground.has(i)).map((i) => {
    const path = new Float64Array(2 * states.length);
    states.forEach((s, r) => { path[2 * r] = s.ev.points[2 * i]; path[2 * r + 1] = s.ev.points[2 * i + 1]; });
    return path;
  });
  app.sweepStates = states;
  app.arrowRef = arrowScale(series.reactions, app.info.pairs.length);
  app.viewContent = [app.ev.points, ...app.paths, arrowTips(series.reactions, cat((s) => s.ev.x))];
  holdView(app.viewContent);
  const chans = seriesChannels(app.info, series);
  const name = app.info.coordinateNames[k];
  app.sweepX = series.q.filter((_, i) => i % app.info.dof === k);
  app.charts.set(app.sweepX, `${name} (${unitOf(app.info, k, "q")}), at rest`, chans, defaultChannels(chans));
  listModes();
}

/** The force (N) drawn ARROW_FRACTION of L long: the upper quartile of the states' largest
 * pair forces, so that a few states near a singularity (forces without bound) do not shrink
 * every other arrow to nothing. */
export function arrowScale(reactions, p) {
  const n = reactions.length / (3 * p);
  const big = new Float64Array(n);
  for (let i = 0; i < n; i++) {
    for (let j = 0; j < p; j++) big[i] = Math.max(big[i], Math.hypot(reactions[3 * (i * p + j)], reactions[3 * (i * p + j) + 1]));
  }
  big.sort();
  return big[Math.floor(0.75 * (n - 1))] || 0;
}

/** The pointer of event `e` in world coordinates (m) on the drawing: [x, y]. */
export function pointerWorld(e) {
  const r = $("drawing").getBoundingClientRect();
  const tr = transform(app.bounds, r.width, r.height);
  return [tr.wx(e.clientX - r.left), tr.wy(e.clientY - r.top)];
}

/** The carried point (its index) drawn within GRAB_PX of the pointer, nearest first; ground
 * points only when `ground`. Null if none. */
export function nearestPoint(e, ground = false) {
  const r = $("drawing").getBoundingClientRect();
  const tr = transform(app.bounds, r.width, r.height);
  const fixed = new Set(ground ? [] : groundIndices());
  let best = null;
  app.info.points.forEach((_, i) => {
    if (fixed.has(i)) return;
    const d = Math.hypot(tr.px(app.ev.points[2 * i]) - (e.clientX - r.left), tr.py(app.ev.points[2 * i + 1]) - (e.clientY - r.top));
    if (d < GRAB_PX && (!best || d < best.d)) best = { i, d };
  });
  return best ? best.i : null;
}

export function installDrag() {
  const c = $("drawing");
  let grabbed = null;
  c.addEventListener("pointerdown", (e) => {
    // Shift + drag edits the model's drawing (edit_drag.js).
    if (app.mode === "replay" || e.shiftKey) return;
    if (app.mode === "run") setMode("design");
    grabbed = nearestPoint(e);
    if (grabbed === null) return;
    c.setPointerCapture(e.pointerId);
    c.classList.add("dragging");
    document.body.dataset.grabbed = app.info.points[grabbed];
  });
  c.addEventListener("pointermove", (e) => {
    if (grabbed === null) return;
    const [wx, wy] = pointerWorld(e);
    const next = dragTowards(app.mech, app.info, app.q, app.x, grabbed, [wx, wy]);
    if (next && moveTo(next.q, next.x)) status(statusLine());
    showState();
  });
  const release = () => {
    if (grabbed === null) return;
    grabbed = null;
    c.classList.remove("dragging");
    sweep();
    showState();
  };
  c.addEventListener("pointerup", release);
  c.addEventListener("pointercancel", release);
}
