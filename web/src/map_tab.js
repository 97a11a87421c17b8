// The side panel's map tab (the maps themselves: map.js): the singularity map, or for a
// compliant model the first natural frequency's or a chosen point's weakest stiffness.
import { $, app, fmt } from "./state.js";
import { LEVELS, frequencyRows, mapRanges, mapper, paintMap, sigmaRows, sigmaScale, spanScale, stiffnessRows } from "./map.js";

/** The maps: each its rows, its colour scale, its grids (a first frequency or a stiffness
 * costs about a millisecond a cell, an eigenproblem or a factorisation of the compliant
 * model, so their maps stop at 50 x 50: about 3 s) and legend. */
const KINDS = {
  sigma: { rows: sigmaRows, scale: () => sigmaScale(), levels: LEVELS, what: () => "σ (type II)",
    legend: () => "pale: far from a singularity; dark red: at one" },
  frequency: { rows: frequencyRows, scale: (g) => spanScale(g.sigma), levels: LEVELS.slice(0, 2), what: () => "the first natural frequency (Hz; motors held)",
    legend: (g) => span(g, "Hz") },
  stiffness: { rows: (mech) => stiffnessRows(mech, $("map-point").value), scale: (g) => spanScale(g.sigma), levels: LEVELS.slice(0, 2),
    what: () => `the weakest stiffness of ${$("map-point").value} (N/m)`, legend: (g) => span(g, "N/m") },
};

/** The lowest and highest value of a grid, as the colours run. */
function span(grid, unit) {
  const v = grid.sigma.filter(Number.isFinite);
  return `${fmt(Math.min(...v))} ${unit} dark red to ${fmt(Math.max(...v))} ${unit} pale`;
}

/** The points whose stiffness can be mapped (a body carries them), the last first (a 5R's or
 * a robot's end effector is usually drawn last). */
function listPoints() {
  const sel = $("map-point"), ground = new Set(app.info.groundPoints);
  const names = app.info.points.filter((p) => !ground.has(p)).reverse();
  if ([...sel.options].map((o) => o.value).join() !== names.join()) sel.replaceChildren(...names.map((p) => new Option(p, p)));
}

/** The map of a two-coordinate model, refined level by level while the page stays responsive
 * (only while its tab is open). */
export function startMap() {
  const note = $("map-note");
  if (app.mapJob) cancelAnimationFrame(app.mapJob);
  $("map-kind-box").hidden = !(app.info && app.info.compliant);
  if (app.info) listPoints();
  $("map-point").hidden = !app.info || !app.info.compliant || $("map-kind").value !== "stiffness";
  if (!app.info || app.info.dof !== 2) {
    note.textContent = "The maps are drawn for mechanisms of two coordinates (a 5R, a two-input robot).";
    return;
  }
  if (!$("tab-map").classList.contains("on")) return;
  const kind = KINDS[app.info.compliant ? $("map-kind").value : "sigma"];
  const ranges = mapRanges(app.info, app.q);
  const [q, x0] = [Float64Array.from(app.q), app.x];
  const rows = kind.rows(app.mech);
  let level = 0;
  let grid = mapper(rows, ranges, kind.levels[0], x0, q);
  const t0 = performance.now();
  const names = app.info.coordinateNames;
  const work = () => {
    const done = grid.step();
    paintMap($("map"), grid, ranges, q, kind.scale(grid));
    if (done && level + 1 < kind.levels.length) grid = mapper(rows, ranges, kind.levels[++level], x0, q, grid);
    else if (done) {
      note.textContent = `${kind.what()} over ${names[0]} × ${names[1]}, ${grid.n} × ${grid.n}, in ${(performance.now() - t0).toFixed(0)} ms (${kind.legend(grid)}; grey: does not assemble on this branch)`;
      app.mapGrid = grid;
      return;
    }
    note.textContent = `computing ${grid.n} × ${grid.n}…`;
    app.mapJob = requestAnimationFrame(work);
  };
  app.mapJob = requestAnimationFrame(work);
}
