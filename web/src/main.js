// The planardyn app: a mechanism drawn from the engine (WebAssembly, in this page), dragged
// by its sliders or by any point, with its drive efforts, pair reactions, singularity
// measure and point paths recomputed live; simulated and played; edited as text with the
// loader's errors in place; exported. `window.planardyn` is the app's state (for scripts and
// tests); <body data-ready="1"> once the first model is shown, data-error on an uncaught error.
import { engine, describe } from "./engine.js";
import { canvasPen, drawScene, fitBounds, svgPen, transform } from "./draw.js";
import { Charts } from "./charts.js";
import { defaultChannels, seriesChannels, toCsv } from "./channels.js";
import { dragTowards } from "./drag.js";
import { LEVELS, mapRanges, mapper, paintMap } from "./map.js";
import { replayScene, replaySeries, isRun } from "./replay.js";

const $ = (id) => document.getElementById(id);
/** States of a sweep of one coordinate (the quasi-static charts and the point paths). */
const SWEEP_STEPS = 180;
/** A pointer this close (px) to a point grabs it. */
const GRAB_PX = 18;
/** Outputs of a run in the browser. */
const RUN_OUTPUTS = 600;

const app = {
  pd: null, mech: null, info: null, text: "", format: "yaml", source: "",
  q: null, x: null, ev: null, bounds: null, paths: [], arrowRef: 0,
  mode: "design", active: 0, run: null, frame: 0, playing: false, replay: null,
  charts: null, map: null, errors: [],
};
window.planardyn = app;

window.addEventListener("error", (e) => { document.body.dataset.error = e.message; });
window.addEventListener("unhandledrejection", (e) => { document.body.dataset.error = String(e.reason); });

function status(text, bad = false) {
  $("status").textContent = text;
  $("status").classList.toggle("bad", bad);
}

const zeros = () => new Float64Array(app.info.dof);
const fmt = (v) => (Number.isFinite(v) ? (Math.abs(v) >= 1e4 || (Math.abs(v) < 1e-3 && v !== 0) ? v.toExponential(3) : v.toPrecision(4)) : "–");

// ---- the model -----------------------------------------------------------------------

/** Build the model from text; on an error, show it in place and keep the last model. */
function setModel(text, format, source, { fromEditor = false } = {}) {
  let mech;
  try {
    mech = app.pd.load(text, format, source);
  } catch (err) {
    showModelError(err, text);
    return false;
  }
  showModelError(null);
  const keep = app.info && app.info.dof === mech.info().dof && fromEditor;
  if (app.mech) app.mech.free();
  Object.assign(app, { mech, info: mech.info(), text, format, source, x: null, run: null, replay: null, mode: "design" });
  if (!fromEditor) $("editor").value = text;
  $("title").textContent = app.info.name;
  const starts = keep ? [app.q, app.info.q0, app.info.drawnQ] : [app.info.q0, app.info.drawnQ];
  if (!starts.some((q) => moveTo(Float64Array.from(q), null))) {
    status("the model does not assemble at q0 nor as drawn", true);
    return false;
  }
  app.active = Math.min(app.active, app.info.dof - 1);
  buildSliders();
  buildRunModes();
  sweep();
  setMode("design");
  startMap();
  status(`${app.info.name}: ${app.info.dof} coordinates, ${app.info.bodyNames.length} bodies; drag a point or a slider` +
    (app.info.warnings.length ? ` — ${app.info.warnings.join("; ")}` : ""));
  return true;
}

/** The loader's error under the editor, with its line selected on a click. */
function showModelError(err, text) {
  const box = $("model-error");
  $("editor").classList.toggle("bad", !!err);
  box.hidden = !err;
  if (!err) return;
  const line = err.line ?? lineOfField(text, err.field);
  box.dataset.line = line ?? "";
  box.textContent = (line ? `line ${line}: ` : "") + describe(err);
  status(`the model has an error (${err.field || err.name})`, true);
}

/** The line where the last key of a field path (`bodies.crank.mass`) is written, if found. */
function lineOfField(text, field) {
  const key = (field || "").split(/[.[\]]/).filter((s) => s && !/^\d+$/.test(s)).pop();
  if (!key) return null;
  const re = new RegExp(`^\\s*(- )?"?${key.replace(/[^\w]/g, "\\$&")}"?\\s*:`);
  const i = text.split("\n").findIndex((l) => re.test(l));
  return i >= 0 ? i + 1 : null;
}

// ---- one state -------------------------------------------------------------------------

/** Evaluate at q (continuing from app.x); near a type II singularity, where the dynamics is
 * not defined, the positions and measures alone. False if q does not assemble. */
function moveTo(q, xStart = app.x) {
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

/** The scene of the current state (design) or frame (run). */
function scene() {
  if (app.mode === "replay") return replayScene(app.replay, app.frame, app.info);
  const x = app.ev.x;
  return {
    points: app.ev.points, bodies: bodyIndices(), ground: groundIndices(),
    geometry: app.mech.pairGeometry(x), arrows: arrowsOf(app.ev.reactions, x),
    paths: app.mode === "design" ? app.paths : [], scale: app.info.scale,
  };
}

const bodyIndices = () => app.info.bodies.map((b) => b.map((n) => app.info.points.indexOf(n)).filter((i) => i >= 0));
const groundIndices = () => app.info.groundPoints.map((n) => app.info.points.indexOf(n)).filter((i) => i >= 0);

function draw() {
  const c = $("drawing");
  const dpr = window.devicePixelRatio || 1;
  const [w, h] = [c.clientWidth, c.clientHeight];
  if (c.width !== Math.round(w * dpr) || c.height !== Math.round(h * dpr)) [c.width, c.height] = [Math.round(w * dpr), Math.round(h * dpr)];
  const ctx = c.getContext("2d");
  ctx.setTransform(dpr, 0, 0, dpr, 0, 0);
  drawScene(canvasPen(ctx), scene(), transform(app.bounds, w, h), w, h);
}

function showState() {
  draw();
  renderValues();
  const k = app.active;
  if (app.mode === "design") app.charts.mark(app.q[k]);
  else app.charts.mark(app.mode === "run" ? app.run.t[app.frame] : app.replay.t[app.frame]);
  document.querySelectorAll("#sliders input").forEach((s, j) => {
    s.value = app.q[j];
    $(`q-out-${j}`).textContent = fmt(app.q[j]);
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
  const kinds = app.info.coordinateKinds;
  head(app.mode === "run" ? `t = ${fmt(app.run.t[app.frame])} s` : "coordinates and efforts (at rest)");
  app.info.coordinateNames.forEach((n, k) => {
    row(n, app.q[k], kinds[k] === "angle" ? "rad" : "m");
    if (ev.tau) row(`τ ${n}`, ev.tau[k], kinds[k] === "angle" ? "N m" : "N");
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

// ---- design: sliders, drag, sweep ---------------------------------------------------------

function sliderRange(k, q) {
  const half = app.info.coordinateKinds[k] === "angle" ? Math.PI : app.info.scale;
  return [q - half, q + half];
}

function buildSliders() {
  const box = $("sliders");
  box.replaceChildren();
  app.info.coordinateNames.forEach((name, k) => {
    const [lo, hi] = sliderRange(k, app.q[k]);
    const label = document.createElement("label");
    label.textContent = `${name} (${app.info.coordinateKinds[k] === "angle" ? "rad" : "m"})`;
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
function sweep() {
  const k = app.active;
  const [lo, hi] = sliderRange(k, app.q[k]);
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
  app.arrowRef = arrowScale(series.reactions, app.info.pairs.length);
  app.bounds = fitBounds([app.ev.points, ...app.paths], app.info.scale);
  const chans = seriesChannels(app.info, series);
  const name = app.info.coordinateNames[k];
  const unit = app.info.coordinateKinds[k] === "angle" ? "rad" : "m";
  app.sweepX = series.q.filter((_, i) => i % app.info.dof === k);
  app.charts.set(app.sweepX, `${name} (${unit}), at rest`, chans, defaultChannels(chans));
}

/** The force (N) drawn ARROW_FRACTION of L long: the upper quartile of the states' largest
 * pair forces, so that a few states near a singularity (forces without bound) do not shrink
 * every other arrow to nothing. */
function arrowScale(reactions, p) {
  const n = reactions.length / (3 * p);
  const big = new Float64Array(n);
  for (let i = 0; i < n; i++) {
    for (let j = 0; j < p; j++) big[i] = Math.max(big[i], Math.hypot(reactions[3 * (i * p + j)], reactions[3 * (i * p + j) + 1]));
  }
  big.sort();
  return big[Math.floor(0.75 * (n - 1))] || 0;
}

function installDrag() {
  const c = $("drawing");
  let grabbed = null;
  const world = (e) => {
    const r = c.getBoundingClientRect();
    const tr = transform(app.bounds, r.width, r.height);
    return [tr.wx(e.clientX - r.left), tr.wy(e.clientY - r.top), tr];
  };
  c.addEventListener("pointerdown", (e) => {
    if (app.mode === "replay") return;
    if (app.mode === "run") setMode("design");
    const [, , tr] = world(e);
    const r = c.getBoundingClientRect();
    const ground = new Set(groundIndices());
    let best = null;
    app.info.points.forEach((_, i) => {
      if (ground.has(i)) return;
      const d = Math.hypot(tr.px(app.ev.points[2 * i]) - (e.clientX - r.left), tr.py(app.ev.points[2 * i + 1]) - (e.clientY - r.top));
      if (d < GRAB_PX && (!best || d < best.d)) best = { i, d };
    });
    if (!best) return;
    grabbed = best.i;
    c.setPointerCapture(e.pointerId);
    c.classList.add("dragging");
    document.body.dataset.grabbed = app.info.points[grabbed];
  });
  c.addEventListener("pointermove", (e) => {
    if (grabbed === null) return;
    const [wx, wy] = world(e);
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

// ---- runs: simulate, play, scrub -----------------------------------------------------------

function buildRunModes() {
  const sel = $("run-mode");
  sel.replaceChildren(new Option("free: the model's drives", "free"));
  app.info.coordinateNames.forEach((n, k) => {
    if (!app.info.prescribed[k]) sel.append(new Option(`${n} driven at`, String(k)));
  });
  const t = app.info.simulate.tEnd;
  if (t) $("t-end").value = t;
  sel.onchange = () => {
    const k = sel.value;
    $("speed-box").hidden = k === "free";
    if (k !== "free") $("speed-unit").textContent = app.info.coordinateKinds[+k] === "angle" ? "rad/s" : "m/s";
  };
  sel.onchange();
}

function simulate() {
  const tEnd = +$("t-end").value;
  const k = $("run-mode").value;
  const motion = k === "free" ? [] : [{ coordinate: +k, speed: +$("speed").value }];
  const t0 = performance.now();
  let run;
  try {
    run = app.mech.simulate({ t_end: tEnd, output_dt: tEnd / RUN_OUTPUTS, q0: app.q, qd0: zeros(), motion });
  } catch (err) {
    status(describe(err), true);
    return null;
  }
  const ms = performance.now() - t0;
  try {
    Object.assign(run, app.mech.along(run.t, run.x, run.xd, run.q, run.qd, run.tau));
  } catch (err) {
    run.note = `no reactions along the run: ${describe(err)}`;
  }
  if (!run.points) run.points = app.mech.points(run.x);
  app.run = run;
  app.frame = 0;
  app.arrowRef = run.reactions ? arrowScale(run.reactions, app.info.pairs.length) : 0;
  app.bounds = fitBounds([run.points], app.info.scale);
  const chans = seriesChannels(app.info, run);
  app.charts.set(run.t, "t (s)", chans, defaultChannels(chans));
  setMode("run");
  status(`${run.status}: ${run.t.length} outputs in ${ms.toFixed(1)} ms; energy drift ${fmt(run.stats.energyDrift)} J; ${run.message}` + (run.note ? ` — ${run.note}` : ""), run.status !== "success");
  play(true);
  return run;
}

function runState() {
  const r = app.run, i = app.frame, m = app.info.dof, p = app.info.pairs.length;
  return {
    tau: r.tau.subarray(i * m, (i + 1) * m), sigma: r.sigma[i], kinetic: r.kinetic[i], potential: r.potential[i],
    reactions: r.reactions ? r.reactions.subarray(i * 3 * p, (i + 1) * 3 * p) : null,
  };
}

/** Show frame i of the run (or of a loaded Python run). */
function setFrame(i) {
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

function setMode(mode) {
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

function play(on) {
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

/** Back to dragging, from the run's current state. */
function backToDesign() {
  const q = Float64Array.from(app.q);
  const x = app.ev.x;
  app.mode = "design";
  moveTo(q, x);
  sweep();
  setMode("design");
}

// ---- a Python run's results (the viewer's data) ---------------------------------------------

function showReplay(data) {
  app.replay = replaySeries(data);
  app.bounds = data.bounds;
  app.charts.set(app.replay.t, "t (s)", app.replay.chans, new Set(app.replay.chans.filter((c) => c.on).map((c) => c.key)));
  $("title").textContent = data.title;
  setMode("replay");
  status(data.info);
  play(true);
}

// ---- files: open, drop, export ---------------------------------------------------------------

function openText(name, text) {
  if (/\.json$/i.test(name)) {
    let data = null;
    try { data = JSON.parse(text); } catch { /* not JSON: the loader says where */ }
    if (data && isRun(data)) return showReplay(data);
  }
  setModel(text, /\.json$/i.test(name) ? "json" : "yaml", name);
}

function download(name, blob) {
  const a = Object.assign(document.createElement("a"), { href: URL.createObjectURL(blob), download: name });
  a.click();
  setTimeout(() => URL.revokeObjectURL(a.href), 1000);
}

function installFiles() {
  $("open").addEventListener("change", async (e) => {
    const f = e.target.files[0];
    if (f) openText(f.name, await f.text());
  });
  window.addEventListener("dragover", (e) => { e.preventDefault(); $("drop-hint").hidden = false; });
  window.addEventListener("dragleave", () => { $("drop-hint").hidden = true; });
  window.addEventListener("drop", async (e) => {
    e.preventDefault();
    $("drop-hint").hidden = true;
    const f = e.dataTransfer.files[0];
    if (f) openText(f.name, await f.text());
  });
  const base = () => (app.info ? app.info.name.replace(/[^\w.-]+/g, "_") : "planardyn");
  $("export-model").onclick = () => download(`${base()}.${app.format === "json" ? "json" : "yaml"}`, new Blob([$("editor").value], { type: "text/plain" }));
  $("export-csv").onclick = () => {
    const { x, xLabel, chans } = app.charts;
    download(`${base()}.csv`, new Blob([toCsv(xLabel, x, chans)], { type: "text/csv" }));
  };
  $("export-png").onclick = () => $("drawing").toBlob((b) => download(`${base()}.png`, b));
  $("export-svg").onclick = () => download(`${base()}.svg`, new Blob([drawingSvg()], { type: "image/svg+xml" }));
}

/** The drawing as SVG, at the canvas's size. */
function drawingSvg() {
  const c = $("drawing");
  const [w, h] = [c.clientWidth, c.clientHeight];
  const pen = svgPen();
  drawScene(pen, scene(), transform(app.bounds, w, h), w, h);
  return pen.svg(w, h);
}

// ---- the side panel: editor, map --------------------------------------------------------------

function installEditor() {
  let timer = 0;
  $("editor").addEventListener("input", () => {
    clearTimeout(timer);
    timer = setTimeout(() => setModel($("editor").value, app.format, app.source || "<editor>", { fromEditor: true }), 250);
  });
  $("model-error").addEventListener("click", () => {
    const line = +$("model-error").dataset.line;
    if (!line) return;
    const ed = $("editor");
    const lines = ed.value.split("\n");
    const start = lines.slice(0, line - 1).reduce((n, l) => n + l.length + 1, 0);
    ed.focus();
    ed.setSelectionRange(start, start + (lines[line - 1] || "").length);
  });
  document.querySelectorAll("#side nav button").forEach((b) => b.addEventListener("click", () => {
    document.querySelectorAll("#side nav button, .tab").forEach((el) => el.classList.remove("on"));
    b.classList.add("on");
    $(`tab-${b.dataset.tab}`).classList.add("on");
    if (b.dataset.tab === "map") startMap();
  }));
}

/** The singularity map of a two-coordinate model, refined level by level while the page stays
 * responsive (only while its tab is open). */
function startMap() {
  const note = $("map-note");
  if (app.mapJob) cancelAnimationFrame(app.mapJob);
  if (!app.info || app.info.dof !== 2) {
    note.textContent = "The singularity map is drawn for mechanisms of two coordinates (a 5R, a two-input robot).";
    return;
  }
  if (!$("tab-map").classList.contains("on")) return;
  const ranges = mapRanges(app.info, app.q);
  const [q, x0] = [Float64Array.from(app.q), app.x];
  let level = 0;
  let grid = mapper(app.mech, ranges, LEVELS[0], x0, q);
  const t0 = performance.now();
  const names = app.info.coordinateNames;
  const work = () => {
    const done = grid.step();
    paintMap($("map"), grid, ranges, q);
    if (done && level + 1 < LEVELS.length) grid = mapper(app.mech, ranges, LEVELS[++level], x0, q, grid);
    else if (done) {
      note.textContent = `σ (type II) over ${names[0]} × ${names[1]}, ${grid.n} × ${grid.n}, in ${(performance.now() - t0).toFixed(0)} ms (pale: far from a singularity; dark red: at one; grey: does not assemble on this branch)`;
      app.mapGrid = grid;
      return;
    }
    note.textContent = `computing ${grid.n} × ${grid.n}…`;
    app.mapJob = requestAnimationFrame(work);
  };
  app.mapJob = requestAnimationFrame(work);
}

// ---- start ------------------------------------------------------------------------------

function start() {
  const t0 = performance.now();
  app.pd = engine();
  app.timings = { engineMs: performance.now() - t0 };
  app.charts = new Charts($("channels"), $("charts"), (i) => {
    if (app.mode === "design") {
      const q = Float64Array.from(app.q);
      q[app.active] = app.sweepX[i];
      if (moveTo(q)) showState();
    } else setFrame(i);
  });
  installDrag();
  installFiles();
  installEditor();
  $("simulate").onclick = simulate;
  $("play").onclick = () => play(!app.playing);
  $("design").onclick = backToDesign;
  $("scrub").addEventListener("input", () => { play(false); setFrame(+$("scrub").value); });
  window.addEventListener("resize", () => { if (app.info || app.replay) { app.charts.render(); showState(); } });
  Object.assign(app, { setModel, simulate, setFrame, moveTo, showState, drawingSvg, startMap, sweep, mapTools: { mapRanges, mapper } });
  const data = JSON.parse($("planardyn-data").textContent);
  if (data.model) setModel(data.model.text, data.model.format, data.model.source);
  if (data.run) showReplay(data.run);
  if (!data.model && !data.run) status("open or drop a model file (.yaml, .json)");
  app.timings.readyMs = performance.now();
  document.body.dataset.ready = "1";
}

start();
