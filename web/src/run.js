// Runs: simulating the model in the page (free, or one coordinate driven at a speed) and
// showing a run made in Python (the viewer's data); back to designing from a run's frame.
import { $, app, fmt, status, zeros } from "./state.js";
import { describe } from "./engine.js";
import { defaultChannels, seriesChannels, unitOf } from "./channels.js";
import { replayDefaults, replaySeries } from "./replay.js";
import { arrowTips, holdView, moveTo } from "./view.js";
import { play, setMode } from "./timeline.js";
import { arrowScale, sweep } from "./design.js";

/** Outputs of a run in the browser. */
const RUN_OUTPUTS = 600;

export function buildRunModes() {
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
    if (k !== "free") $("speed-unit").textContent = unitOf(app.info, +k, "qd");
  };
  sel.onchange();
}

export function simulate() {
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
  app.viewContent = [run.points, arrowTips(run.reactions, run.x)];
  holdView(app.viewContent);
  const chans = seriesChannels(app.info, run);
  app.charts.set(run.t, "t (s)", chans, defaultChannels(chans));
  setMode("run");
  status(`${run.status}: ${run.t.length} outputs in ${ms.toFixed(1)} ms; energy drift ${fmt(run.stats.energyDrift)} J; ${run.message}` + (run.note ? ` — ${run.note}` : ""), run.status !== "success");
  play(true);
  return run;
}

/** Back to dragging, from the run's current state. */
export function backToDesign() {
  const q = Float64Array.from(app.q);
  const x = app.ev.x;
  app.mode = "design";
  moveTo(q, x);
  sweep();
  setMode("design");
}

/** A Python run's results (the viewer's data), played. */
export function showReplay(data) {
  app.replay = replaySeries(data);
  app.bounds = data.bounds;
  app.charts.set(app.replay.t, "t (s)", app.replay.chans, replayDefaults(app.replay.chans));
  $("title").textContent = data.title;
  setMode("replay");
  status(data.info);
  play(true);
}
