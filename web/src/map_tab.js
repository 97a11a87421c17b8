// The side panel's map tab (the maps themselves: map.js): the singularity map, or for a
// compliant model the first natural frequency's.
import { $, app, fmt } from "./state.js";
import { LEVELS, frequencyRows, frequencyScale, mapRanges, mapper, paintMap, sigmaRows, sigmaScale } from "./map.js";

/** The maps: each its rows, its colour scale, its grids (a first frequency costs about a
 * millisecond a cell, an eigenproblem, so its map stops at 50 x 50: about 3 s) and legend. */
const KINDS = {
  sigma: { rows: sigmaRows, scale: () => sigmaScale(), levels: LEVELS, what: "σ (type II)",
    legend: () => "pale: far from a singularity; dark red: at one" },
  frequency: { rows: frequencyRows, scale: (g) => frequencyScale(g.sigma), levels: LEVELS.slice(0, 2), what: "the first natural frequency (Hz; motors held)",
    legend: (g) => { const f = g.sigma.filter(Number.isFinite); return `${fmt(Math.min(...f))} Hz dark red to ${fmt(Math.max(...f))} Hz pale`; } },
};

/** The map of a two-coordinate model, refined level by level while the page stays responsive
 * (only while its tab is open). */
export function startMap() {
  const note = $("map-note");
  if (app.mapJob) cancelAnimationFrame(app.mapJob);
  $("map-kind-box").hidden = !(app.info && app.info.compliant);
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
      note.textContent = `${kind.what} over ${names[0]} × ${names[1]}, ${grid.n} × ${grid.n}, in ${(performance.now() - t0).toFixed(0)} ms (${kind.legend(grid)}; grey: does not assemble on this branch)`;
      app.mapGrid = grid;
      return;
    }
    note.textContent = `computing ${grid.n} × ${grid.n}…`;
    app.mapJob = requestAnimationFrame(work);
  };
  app.mapJob = requestAnimationFrame(work);
}
