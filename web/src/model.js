// The model: built from text (a file, the page's data, the editor), its loader errors shown
// in place under the editor, the last good model kept meanwhile.
import { $, app, status } from "./state.js";
import { describe } from "./engine.js";
import { moveTo } from "./view.js";
import { setMode } from "./timeline.js";
import { buildSliders, sweep } from "./design.js";
import { buildRunModes } from "./run.js";
import { startMap } from "./map_tab.js";
import { listModes } from "./modes.js";
import { warmEngine } from "./warm.js";

/** Build the model from text; on an error, show it in place and keep the last model. The
 * model is shown at its initial state (q0, else as drawn), at the last state when only its
 * numbers were edited (`fromEditor`), or as drawn (`drawn`: its drawing is being edited). */
export function setModel(text, format, source, { fromEditor = false, drawn = false } = {}) {
  let mech;
  try {
    mech = app.pd.load(text, format, source);
  } catch (err) {
    showModelError(err);
    return false;
  }
  showModelError(null);
  const keep = app.info && app.info.dof === mech.info().dof && fromEditor;
  if (app.mech) app.mech.free();
  Object.assign(app, { mech, info: mech.info(), text, format, source, x: null, run: null, replay: null, mode: "design" });
  // Another model (not an edit of this one) opens on its own default channels and view.
  if (!fromEditor && !drawn) {
    app.charts.chosen = false;
    app.bounds = null;
  }
  if (!fromEditor) $("editor").value = text;
  $("title").textContent = app.info.name;
  const starts = drawn ? [app.info.drawnQ] : keep ? [app.q, app.info.q0, app.info.drawnQ] : [app.info.q0, app.info.drawnQ];
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
  warmEngine();
  status(`${app.info.name}: ${count(app.info.dof, "coordinate")}, ${count(app.info.bodyNames.length, "body", "bodies")}; drag a point or a slider` +
    (app.info.warnings.length ? ` — ${app.info.warnings.join("; ")}` : ""));
  return true;
}

/** "1 coordinate", "3 coordinates". */
const count = (n, one, many = `${one}s`) => `${n} ${n === 1 ? one : many}`;

/** The loader's error under the editor, with its line selected on a click. */
function showModelError(err) {
  const box = $("model-error");
  $("editor").classList.toggle("bad", !!err);
  box.hidden = !err;
  if (!err) return;
  // The core locates every refused field (loader/locate.rs): its line is in the error.
  const line = err.line;
  box.dataset.line = line ?? "";
  box.textContent = (line ? `line ${line}: ` : "") + describe(err);
  status(`the model has an error (${err.field || err.name})`, true);
}

/** The side panel: the editor (the model rebuilt as it is typed, its error's line selected
 * on a click) and the tabs. */
export function installEditor() {
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
    if (b.dataset.tab === "modes") listModes();
  }));
  $("map-kind").addEventListener("change", startMap);
  $("map-point").addEventListener("change", startMap);
  for (const id of ["load-fx", "load-fy", "load-m"]) $(id).addEventListener("change", startMap);
}
