// The current state on the page: evaluated at q (design), or a frame of a run or of a
// Python run (replay); drawn on the canvas (or as SVG) and listed in the values table.
import { $, app, fmt, status, zeros } from "./state.js";
import { describe } from "./engine.js";
import { arrowTip, canvasPen, drawScene, fitBounds, holds, svgPen, transform } from "./draw.js";
import { unitOf } from "./channels.js";
import { replayScene } from "./replay.js";

/** Evaluate at q (continuing from app.x); near a type II singularity, where the dynamics is
 * not defined, the positions and measures alone. False if q does not assemble. */
export function moveTo(q, xStart = app.x) {
  stopMode();
  const z = zeros();
  try {
    app.ev = app.mech.evaluate(q, z, z, xStart ?? undefined);
  } catch (err) {
    try {
      const x = app.mech.assemble(q, xStart ?? undefined);
      const m = app.mech.measures(x);
      app.ev = { x, points: app.mech.points(x), sigma: m.sigma, sigmaPassive: m.sigmaPassive, note: describe(err) };
    } catch (err2) {
      status(describe(err2), true);
      return false;
    }
  }
  app.q = q;
  app.x = app.ev.x;
  return true;
}

function arrowsOf(reactions, x) {
  if (!reactions) return null;
  const geom = app.mech.pairGeometry(x);
  const items = geom.map((g, j) => {
    const at = g.pins.length ? g.pins : g.blocks;
    return { x: at[0], y: at[1], fx: reactions[3 * j], fy: reactions[3 * j + 1] };
  }).filter((a) => Number.isFinite(a.x));
  return { ref: app.arrowRef, items };
}

/** The tips (m: x, y, ...) of the reaction arrows of states: `reactions` (3 per pair a state)
 * at body coordinates `xs` (the model's x0 length a state), drawn at the reference app.arrowRef. */
export function arrowTips(reactions, xs) {
  const nx = app.info.x0.length, p3 = 3 * app.info.pairs.length, tips = [];
  if (!reactions || !(app.arrowRef > 0)) return tips;
  for (let i = 0; (i + 1) * nx <= xs.length; i++) {
    for (const a of arrowsOf(reactions.slice(i * p3, (i + 1) * p3), xs.slice(i * nx, (i + 1) * nx)).items) tips.push(...arrowTip(a, app.arrowRef, app.info.scale));
  }
  return tips;
}

/** Hold `content` (arrays of x, y, ... in m: points, paths, arrow tips) in the view: the view
 * (app.bounds) stays as it is while it holds them, so that its scale is fixed while the user
 * works on one model; where they leave it (or with no view yet) it widens to hold them too. */
export function holdView(content) {
  if (app.bounds && holds(app.bounds, content)) return;
  const [f, b] = [fitBounds(content, app.info.scale), app.bounds];
  app.bounds = b ? [Math.min(b[0], f[0]), Math.max(b[1], f[1]), Math.min(b[2], f[2]), Math.max(b[3], f[3])] : f;
}

/** The Fit button: the view fitted to what is shown (the sweep's or the run's points, paths
 * and arrows: app.viewContent; a Python run's own bounds). */
export function fitView() {
  if (!app.info && !app.replay) return;
  app.bounds = app.mode === "replay" ? app.replay.data.bounds : fitBounds(app.viewContent, app.info.scale);
  showState();
}

/** Stop showing a natural mode (modes.js): the drawing is the state's again. */
export function stopMode() {
  app.modeAnim = null;
  app.modeX = null;
  delete document.body.dataset.modeShown;
}

/** The scene of the current state (design), displaced along a natural mode while one is
 * shown, or of a run's frame. */
function scene() {
  if (app.mode === "replay") return replayScene(app.replay, app.frame);
  const x = app.modeX ?? app.ev.x;
  return {
    points: app.modeX ? app.mech.points(x) : app.ev.points, bodies: bodyIndices(), ground: groundIndices(),
    geometry: app.mech.pairGeometry(x), arrows: app.modeX ? null : arrowsOf(app.ev.reactions, x),
    paths: app.mode === "design" ? app.paths : [], scale: app.info.scale,
  };
}

const bodyIndices = () => app.info.bodies.map((b) => b.map((n) => app.info.points.indexOf(n)).filter((i) => i >= 0));
export const groundIndices = () => app.info.groundPoints.map((n) => app.info.points.indexOf(n)).filter((i) => i >= 0);

/** Draw the scene on the canvas. */
export function redraw() {
  const c = $("drawing");
  const dpr = window.devicePixelRatio || 1;
  const [w, h] = [c.clientWidth, c.clientHeight];
  if (c.width !== Math.round(w * dpr) || c.height !== Math.round(h * dpr)) [c.width, c.height] = [Math.round(w * dpr), Math.round(h * dpr)];
  const ctx = c.getContext("2d");
  ctx.setTransform(dpr, 0, 0, dpr, 0, 0);
  drawScene(canvasPen(ctx), scene(), transform(app.bounds, w, h), w, h);
}

/** The drawing as SVG, at the canvas's size. */
export function drawingSvg() {
  const c = $("drawing");
  const [w, h] = [c.clientWidth, c.clientHeight];
  const pen = svgPen();
  drawScene(pen, scene(), transform(app.bounds, w, h), w, h);
  return pen.svg(w, h);
}

/** The coordinates shown by the sliders: the state's, or while a Python run plays, its frame's
 * (its coordinate channels, by the model's coordinate names). */
function shownQ() {
  if (app.mode !== "replay") return app.q;
  const chans = app.replay.chans;
  return app.info.coordinateNames.map((n, k) => chans.find((c) => c.group === "q" && c.key === n)?.values[app.frame] ?? app.q[k]);
}

export function showState() {
  // A drag or a slider may take the mechanism, or its arrows, out of the view.
  if (app.mode === "design") holdView([app.ev.points, arrowTips(app.ev.reactions, app.ev.x)]);
  redraw();
  renderValues();
  const k = app.active;
  if (app.mode === "design") app.charts.mark(app.q[k]);
  else app.charts.mark(app.mode === "run" ? app.run.t[app.frame] : app.replay.t[app.frame]);
  const q = shownQ();
  document.querySelectorAll("#sliders input").forEach((s, j) => {
    s.value = q[j];
    $(`q-out-${j}`).textContent = fmt(q[j]);
  });
  document.body.dataset.q = Array.from(app.q ?? []).join(",");
}

function renderValues() {
  const rows = [];
  const head = (t) => rows.push(`<tr><th colspan="3">${t}</th></tr>`);
  const row = (a, v, u) => rows.push(`<tr><td>${a}</td><td class="num">${fmt(v)}</td><td>${u}</td></tr>`);
  if (app.mode === "replay") {
    head(`t = ${fmt(app.replay.t[app.frame])} s`);
    for (const c of app.replay.chans) row(c.label, c.values[app.frame], c.unit);
    $("values").innerHTML = rows.join("");
    return;
  }
  const ev = app.mode === "run" ? runState() : app.ev;
  head(app.mode === "run" ? `t = ${fmt(app.run.t[app.frame])} s` : "coordinates and efforts (at rest)");
  app.info.coordinateNames.forEach((n, k) => {
    row(n, app.q[k], unitOf(app.info, k, "q"));
    if (ev.tau) row(`τ ${n}`, ev.tau[k], unitOf(app.info, k, "tau"));
  });
  head("singularity measures");
  row("σ (type II)", ev.sigma, "");
  if (ev.sigmaPassive !== undefined) row("σ passive", ev.sigmaPassive, "");
  if (ev.note) rows.push(`<tr><td colspan="3" class="note">${ev.note}</td></tr>`);
  if (ev.kinetic !== undefined) {
    head("energies");
    row("T", ev.kinetic, "J");
    row("V", ev.potential, "J");
  }
  if (ev.reactions) {
    head("pair reactions |F| (a on b)");
    app.info.pairs.forEach((p, j) => row(p.name, Math.hypot(ev.reactions[3 * j], ev.reactions[3 * j + 1]), "N"));
  }
  $("values").innerHTML = rows.join("");
}

/** The efforts, measure, energies and reactions of the run's current frame. */
export function runState() {
  const r = app.run, i = app.frame, m = app.info.dof, p = app.info.pairs.length;
  return {
    tau: r.tau.subarray(i * m, (i + 1) * m), sigma: r.sigma[i], kinetic: r.kinetic[i], potential: r.potential[i],
    reactions: r.reactions ? r.reactions.subarray(i * 3 * p, (i + 1) * 3 * p) : null,
  };
}
