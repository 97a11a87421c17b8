// The planardyn app: a mechanism drawn from the engine (WebAssembly, in this page), dragged
// by its sliders or by any point, with its drive efforts, pair reactions, singularity
// measure and point paths recomputed live; simulated and played; edited as text with the
// loader's errors in place; exported. `window.planardyn` is the app's state (for scripts and
// tests); <body data-ready="1"> once the first model is shown, data-error on an uncaught error.
//
// The parts, each a module: state.js (the state and small helpers), view.js (the current
// state drawn and listed), timeline.js (modes, frames, playing), design.js (sliders, drag,
// sweep), run.js (runs here and Python's), model.js (the model from text, the editor),
// map_tab.js (the map tab: singularity or first frequency), modes.js (natural modes, shown
// animated), edit_drag.js (Shift + drag: a point of the model's drawing moved), files.js
// (open, drop, export), warm.js (the engine warmed in idle time).
import { $, app, status } from "./state.js";
import { engine } from "./engine.js";
import { Charts } from "./charts.js";
import { frequencyRows, mapRanges, mapper, sigmaRows, stiffnessRows } from "./map.js";
import { drawingSvg, fitView, moveTo, showState } from "./view.js";
import { play, setFrame } from "./timeline.js";
import { installDrag, sweep } from "./design.js";
import { installEditDrag } from "./edit_drag.js";
import { backToDesign, showReplay, simulate } from "./run.js";
import { installEditor, setModel } from "./model.js";
import { startMap } from "./map_tab.js";
import { listModes, showMode } from "./modes.js";
import { installFiles, installShipped } from "./files.js";

window.planardyn = app;

window.addEventListener("error", (e) => { document.body.dataset.error = e.message; });
window.addEventListener("unhandledrejection", (e) => { document.body.dataset.error = String(e.reason); });

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
  installEditDrag();
  installFiles();
  installEditor();
  $("simulate").onclick = simulate;
  $("play").onclick = () => play(!app.playing);
  $("design").onclick = backToDesign;
  $("fit").onclick = fitView;
  $("scrub").addEventListener("input", () => { play(false); setFrame(+$("scrub").value); });
  // The drawing and the charts follow their boxes: the window's size, and the header's (a status
  // line may wrap the title after the first drawing).
  const observer = new ResizeObserver(() => { if (app.info || app.replay) { app.charts.render(); showState(); } });
  for (const id of ["drawing", "charts"]) observer.observe($(id));
  Object.assign(app, { setModel, simulate, setFrame, moveTo, showState, drawingSvg, startMap, sweep, mapTools: { mapRanges, mapper, sigmaRows, frequencyRows, stiffnessRows }, listModes, showMode });
  const data = JSON.parse($("planardyn-data").textContent);
  if (data.model) setModel(data.model.text, data.model.format, data.model.source);
  if (data.run) showReplay(data.run);
  if (data.shipped) installShipped(data.shipped);
  if (!data.model && !data.run) status(`open or drop a model file (.yaml, .json)${data.shipped ? ", or choose a shipped model" : ""}`);
  app.timings.readyMs = performance.now();
  document.body.dataset.ready = "1";
}

start();
