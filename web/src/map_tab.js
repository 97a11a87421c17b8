// The side panel's map tab (the maps themselves: map.js): the singularity map, or for a
// compliant model the first natural frequency's or a chosen point's weakest stiffness.
import { $, app, fmt } from "./state.js";
import { unitOf } from "./channels.js";
import { LEVELS, frequencyRows, mapRanges, mapper, paintMap, sigmaRows, sigmaScale, spanScale, stiffnessRows } from "./map.js";

/** The maps: each its rows, its colour scale and legend; all on the same grids (`LEVELS`). */
const KINDS = {
  sigma: { rows: sigmaRows, scale: () => sigmaScale(), what: () => "σ (type II)",
    legend: () => "pale: far from a singularity; dark red: at one" },
  frequency: { rows: frequencyRows, scale: (g) => spanScale(g.sigma), what: () => "the first natural frequency (Hz; motors held)",
    legend: (g) => span(g, "Hz") },
  stiffness: { rows: (mech) => stiffnessRows(mech, $("map-point").value, pointLoad()), scale: (g) => spanScale(g.sigma),
    what: () => `the weakest stiffness of ${$("map-point").value} (N/m${loaded() ? ", loaded" : ""})`, legend: (g) => span(g, "N/m") },
};

/** The load on the mapped point as the engine's `LoadOption`: the wrench [F_x, F_y, M] (N,
 * N, N m) and, where the model has more actuators than coordinates, each one's preload (N m
 * or N; the efforts its transmission spring carries). */
export function pointLoad() {
  const wrench = ["load-fx", "load-fy", "load-m"].map((id) => Number($(id).value) || 0);
  const preload = {};
  for (const input of $("load-preload").querySelectorAll("input")) {
    if (Number(input.value)) preload[input.dataset.actuator] = Number(input.value);
  }
  return { wrench, preload };
}

const loaded = () => { const l = pointLoad(); return l.wrench.some((v) => v !== 0) || Object.keys(l.preload).length > 0; };

/** A preload field per actuator where the actuation is redundant (more actuators than
 * coordinates: efforts can preload the mechanism without moving it). */
function listPreloads() {
  const box = $("load-preload"), names = app.info.dof < app.info.actuators.length ? app.info.actuators : [];
  if ([...box.querySelectorAll("input")].map((i) => i.dataset.actuator).join() === names.join()) return;
  box.replaceChildren(...names.map((name) => {
    const label = document.createElement("label"), input = document.createElement("input");
    Object.assign(input, { type: "number", value: "0", step: "any" });
    input.dataset.actuator = name;
    input.addEventListener("change", startMap);
    label.append(`preload ${name} `, input);
    return label;
  }));
}

/** The mapped point's stiffness at the current pose under the load (`Mechanism.stiffness`),
 * shown above the map; kept as `app.stiffnessHere`. */
function showStiffnessHere() {
  const point = $("map-point").value;
  try {
    const s = app.mech.stiffness(Float64Array.from(app.q), point, app.x, pointLoad());
    app.stiffnessHere = s;
    $("stiffness-here").textContent = `here: ${fmt(s.weakest)} N/m along (${fmt(s.direction[0])}, ${fmt(s.direction[1])})`;
  } catch (e) {
    app.stiffnessHere = null;
    $("stiffness-here").textContent = e.message;
  }
}

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

/** The map of a model over its first two coordinates (any others held), refined level by
 * level while the page stays responsive (only while its tab is open). */
export function startMap() {
  const note = $("map-note");
  if (app.mapJob) cancelAnimationFrame(app.mapJob);
  $("map-kind-box").hidden = !(app.info && app.info.compliant);
  if (app.info) { listPoints(); listPreloads(); }
  const stiffness = app.info && app.info.compliant && $("map-kind").value === "stiffness";
  $("map-point").hidden = !stiffness;
  $("map-load").hidden = !stiffness;
  // No empty frame where there is no map (a model of one coordinate).
  $("map").hidden = !app.info || app.info.dof < 2;
  if ($("map").hidden) {
    note.textContent = "The maps are over two coordinates: this model has one.";
    return;
  }
  if (!$("tab-map").classList.contains("on")) return;
  const kind = KINDS[app.info.compliant ? $("map-kind").value : "sigma"];
  if (stiffness) showStiffnessHere();
  const ranges = mapRanges(app.info, app.q);
  const [q, x0] = [Float64Array.from(app.q), app.x];
  const rows = kind.rows(app.mech);
  let level = 0;
  let grid = mapper(rows, ranges, LEVELS[0], x0, q);
  const t0 = performance.now();
  note.textContent = `computing ${grid.n} × ${grid.n}…`;  // not the last map's note meanwhile
  const names = app.info.coordinateNames;
  // The coordinates past the first two are held where they are (a 3-RRR's third input).
  const held = names.slice(2).map((n, k) => `${n} = ${fmt(q[k + 2])}`).join(", ");
  const axis = (k, way) => `${names[k]} ${way} from ${fmt(ranges[k][0])} to ${fmt(ranges[k][1])} ${unitOf(app.info, k, "q")}`;
  const axes = `${axis(0, "across")}, ${axis(1, "up")}`;
  const work = () => {
    let done;
    try {
      done = grid.step();
    } catch (e) { // a load the model refuses (a preload without a transmission spring)
      note.textContent = e.message;
      return;
    }
    paintMap($("map"), grid, ranges, q, kind.scale(grid));
    if (done && level + 1 < LEVELS.length) grid = mapper(rows, ranges, LEVELS[++level], x0, q, grid);
    else if (done) {
      note.textContent = `${kind.what()} over ${names[0]} × ${names[1]}, ${grid.n} × ${grid.n}, in ${(performance.now() - t0).toFixed(0)} ms` +
        ` (${axes}${held ? `; ${held} held` : ""}; ${kind.legend(grid)}; grey: does not assemble on this branch)`;
      app.mapGrid = grid;
      return;
    }
    note.textContent = `computing ${grid.n} × ${grid.n}…`;
    app.mapJob = requestAnimationFrame(work);
  };
  app.mapJob = requestAnimationFrame(work);
}
