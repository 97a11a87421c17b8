// The maps of a two-coordinate mechanism (a 5R, a two-input robot) over a grid of (q1, q2):
// the type II measure sigma (the engine's `sigmaRows`) or, for a compliant model, the first
// natural frequency or a point's weakest stiffness under a load (`elasticRows`), on the branch
// of the current state (planardyn::dynamics::MapRows: where every group has a closed form
// without iteration, each cell in the assembly modes of the current state; with a triad, each
// cell along the straight path from the current state in its modes; else by continuation from
// it, each cell from its neighbour). Computed progressively, coarse grids first, in slices that
// leave the page responsive; cells that do not assemble on that branch are grey.

/** Grids of the progressive refinement; the last is the map's resolution. */
export const LEVELS = [25, 50, 100];
/** Work per slice before the page gets the main thread back (ms). */
const SLICE_MS = 12;
/** Rows per call of the engine: a 100-wide row takes about a millisecond. */
const ROWS_PER_CALL = 4;

/** The range of coordinate k about its value qk (a slider's, a map axis'): an angle qk +- pi,
 * a displacement qk +- L. */
export function coordinateRange(info, k, qk) {
  const half = info.coordinateKinds[k] === "angle" ? Math.PI : info.scale;
  return [qk - half, qk + half];
}

/** The grid's ranges: each coordinate's range about q. */
export function mapRanges(info, q) {
  return [0, 1].map((k) => coordinateRange(info, k, q[k]));
}

/** The type II measure's rows (`Mechanism.sigmaRows`: one workspace; each cell on its own on
 * x's branch, or for a mechanism without closed forms each row walked from column i0 both
 * ways, continuing from x): `{sigma (rows x n), x (where the next rows continue)}`. */
export const sigmaRows = (mech) => (q, axes, i0, rows, x) => mech.sigmaRows(q, 0, 1, axes[0], axes[1], i0, rows, x);

/** The rows of an elastic map (`Mechanism.elasticRows`, the same grid, rows and branch as
 * `sigmaRows`; `value` its `MapOption`), as `{sigma, x}`. */
const elasticRows = (mech, value) => (q, axes, i0, rows, x) => {
  const out = mech.elasticRows(q, 0, 1, axes[0], axes[1], i0, rows, x, value);
  return { sigma: out.values, x: out.x };
};

/** The first natural frequency's rows (Hz; motors held). */
export const frequencyRows = (mech) => elasticRows(mech, { kind: "frequency" });

/** The rows of the weakest translational stiffness (N/m) of `point` under `load` (the
 * engine's `LoadOption`: wrench at the point, preload by actuator name, gravity). */
export const stiffnessRows = (mech, point, load = {}) => elasticRows(mech, { kind: "stiffness", point, load });

/** A map on an n x n grid over `ranges` (row j: q2, column i: q1), NaN where it does not
 * assemble, computed a few rows a call of `rowsOf` (`sigmaRows` or `frequencyRows` of the
 * mechanism: continuation outwards from the current state q, whose body coordinates are x0:
 * its row first, then the rows above it, then those below). `coarse`, a finished coarser
 * grid, fills the cells not yet computed, so that the map refines in place. */
export function mapper(rowsOf, ranges, n, x0, q, coarse = null) {
  const sigma = new Float64Array(n * n).fill(NaN);
  if (coarse) {
    const c = coarse.n;
    for (let j = 0; j < n; j++) for (let i = 0; i < n; i++) sigma[j * n + i] = coarse.sigma[Math.floor((j * c) / n) * c + Math.floor((i * c) / n)];
  }
  const axes = ranges.map((r) => Float64Array.from({ length: n }, (_, i) => r[0] + ((r[1] - r[0]) * (i + 0.5)) / n));
  const j0 = Math.floor(n / 2);
  const order = [...Array(n - j0).keys()].map((d) => j0 + d).concat([...Array(j0).keys()].map((d) => j0 - 1 - d));
  let [done, x, xMiddle] = [0, x0, null];
  return {
    sigma, n,
    /** Work for `budget` ms (all at once when Infinity); true when the grid is done. */
    step(budget = SLICE_MS) {
      const end = performance.now() + budget;
      while (done < n && performance.now() < end) {
        // The rows below the middle continue from the middle row, not from the top one.
        if (done === n - j0) x = xMiddle;
        const count = done === 0 ? 1 : Math.min(ROWS_PER_CALL, (done < n - j0 ? n - j0 : n) - done);
        const rows = Uint32Array.from(order.slice(done, done + count));
        const out = rowsOf(q, axes, j0, rows, x);
        rows.forEach((j, r) => sigma.set(out.sigma.subarray(r * n, (r + 1) * n), j * n));
        x = out.x;
        if (done === 0) xMiddle = out.x;
        done += count;
      }
      return done >= n;
    },
  };
}

/** Where sigma lies between 1e-3 and 1, log scale (0 at a singularity). */
export const sigmaScale = () => (s) => (Math.log10(Math.max(s, 1e-3)) + 3) / 3;

/** Where a value (a frequency, a stiffness) lies between the lowest and highest of the grid,
 * log scale. */
export function spanScale(values) {
  const finite = values.filter((v) => Number.isFinite(v) && v > 0);
  const [lo, hi] = [Math.log10(Math.min(...finite)), Math.log10(Math.max(...finite))];
  return (f) => (hi > lo ? (Math.log10(f) - lo) / (hi - lo) : 1);
}

/** A colour for a value at `t` of its scale (0: dark red, the singularity or the lowest
 * frequency, to 1: pale); grey where there is none. */
function colour(t) {
  if (!Number.isFinite(t)) return [210, 214, 218];
  t = Math.max(0, Math.min(1, t));
  return [Math.round(120 + 135 * t), Math.round(20 + 215 * t), Math.round(30 + 190 * t)];
}

/** Paint a finished or partial grid on the canvas, each value placed on `scale` (sigmaScale
 * or frequencyScale), with the current state's cross. */
export function paintMap(canvas, grid, ranges, q, scale = sigmaScale()) {
  const ctx = canvas.getContext("2d");
  const { n, sigma } = grid;
  const img = ctx.createImageData(n, n);
  for (let j = 0; j < n; j++) {
    for (let i = 0; i < n; i++) {
      const [r, g, b] = colour(scale(sigma[j * n + i]));
      const o = ((n - 1 - j) * n + i) * 4;
      [img.data[o], img.data[o + 1], img.data[o + 2], img.data[o + 3]] = [r, g, b, 255];
    }
  }
  const off = new OffscreenCanvas(n, n);
  off.getContext("2d").putImageData(img, 0, 0);
  ctx.imageSmoothingEnabled = false;
  ctx.drawImage(off, 0, 0, canvas.width, canvas.height);
  const px = ((q[0] - ranges[0][0]) / (ranges[0][1] - ranges[0][0])) * canvas.width;
  const py = (1 - (q[1] - ranges[1][0]) / (ranges[1][1] - ranges[1][0])) * canvas.height;
  ctx.strokeStyle = "#000";
  ctx.lineWidth = 2;
  ctx.beginPath();
  ctx.moveTo(px - 7, py); ctx.lineTo(px + 7, py);
  ctx.moveTo(px, py - 7); ctx.lineTo(px, py + 7);
  ctx.stroke();
}
