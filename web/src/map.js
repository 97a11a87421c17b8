// The maps of a two-coordinate mechanism (a 5R, a two-input robot): over a grid of (q1, q2),
// on the branch reached by continuation from the current state (each cell starts Newton from
// its neighbour), the type II measure sigma (the engine's `sigmaRows`) or, for a compliant
// model, the first natural frequency or a point's weakest stiffness (the engine's `modes` or
// `stiffness` a cell). Computed progressively,
// coarse grids first, in slices that leave the page responsive; cells that do not assemble
// are grey.

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

/** The type II measure's rows (`Mechanism.sigmaRows`: one workspace, each row walked from
 * column i0 both ways, continuing from x): `{sigma (rows x n), x (where the next rows
 * continue)}`. */
export const sigmaRows = (mech) => (q, axes, i0, rows, x) => mech.sigmaRows(q, 0, 1, axes[0], axes[1], i0, rows, x);

/** Rows of a value computed a cell at a time by `cell(qCell, x)` -> {value, x} (one engine
 * call at the cell's q from its neighbour's body coordinates x), walked as `sigmaRows` walks
 * them; NaN where the call throws (it does not assemble there, or has no value), the next
 * cell then starting from the last that did. */
const cellRows = (cell) => (q, axes, i0, rows, xStart) => {
  const n = axes[0].length;
  const out = new Float64Array(rows.length * n).fill(NaN);
  let xRow = xStart;
  rows.forEach((j, r) => {
    let xNext = null;
    for (const dir of [1, -1]) {
      let x = xRow;
      for (let i = dir > 0 ? i0 : i0 - 1; i >= 0 && i < n; i += dir) {
        const qc = Float64Array.from(q);
        [qc[0], qc[1]] = [axes[0][i], axes[1][j]];
        try {
          const c = cell(qc, x);
          out[r * n + i] = c.value;
          x = c.x;
          if (i === i0) xNext = c.x;
        } catch { /* not computed here: NaN */ }
      }
    }
    if (xNext) xRow = xNext;
  });
  return { sigma: out, x: xRow };
};

/** The first natural frequency's rows (Hz; the engine's `modes`, motors held). */
export const frequencyRows = (mech) => cellRows((q, x) => {
  const m = mech.modes(q, false, x);
  return { value: m.omega[0] / (2 * Math.PI), x: m.x };
});

/** The rows of the weakest translational stiffness (N/m) of `point` (the engine's `stiffness`). */
export const stiffnessRows = (mech, point) => cellRows((q, x) => {
  const s = mech.stiffness(q, point, x);
  return { value: s.weakest, x: s.x };
});

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
