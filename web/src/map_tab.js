// The side panel's singularity map tab (the map itself: map.js).
import { $, app } from "./state.js";
import { LEVELS, mapRanges, mapper, paintMap } from "./map.js";

/** The singularity map of a two-coordinate model, refined level by level while the page stays
 * responsive (only while its tab is open). */
export function startMap() {
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
