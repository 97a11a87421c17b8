// Dragging a point of the drawing: the coordinates q that bring the point to the pointer, by
// damped least squares on the point's Jacobian d(point)/dq. The Jacobian is taken by finite
// differences of the engine's exact assembly (m assemblies a step), so any point of any
// mechanism can be dragged, a robot's platform as a crank: inverse kinematics live.

/** Relative step of the finite differences (of the mechanism's size L or of 1 rad). */
const FD_STEP = 1e-6;
/** Damping of the least squares, as a fraction of L: keeps a step bounded near a
 * singularity, where the point cannot follow the pointer in some direction. */
const DAMPING = 0.02;
/** Largest change of one coordinate in one step (rad, or this fraction of L). */
const MAX_STEP = 0.25;
const ITERATIONS = 4;

/** The point `k` (index into the carried points) of body coordinates x. */
function pointAt(mech, x, k) {
  const p = mech.points(x);
  return [p[2 * k], p[2 * k + 1]];
}

/** New {q, x} moving point k towards `target` (world, m), or null if no step assembles. */
export function dragTowards(mech, info, q, x, k, target) {
  const m = info.dof;
  const L = info.scale;
  const unit = info.coordinateKinds.map((kind) => (kind === "angle" ? 1 : L));
  let [cq, cx] = [Float64Array.from(q), Float64Array.from(x)];
  for (let it = 0; it < ITERATIONS; it++) {
    const p = pointAt(mech, cx, k);
    const e = [target[0] - p[0], target[1] - p[1]];
    if (Math.hypot(e[0], e[1]) < 1e-9 * L) break;
    // J (2 x m) by forward differences; a coordinate that does not assemble moved is left out.
    const J = [];
    for (let j = 0; j < m; j++) {
      const h = FD_STEP * unit[j];
      const qh = Float64Array.from(cq);
      qh[j] += h;
      try {
        const ph = pointAt(mech, mech.assemble(qh, cx), k);
        J.push([(ph[0] - p[0]) / h, (ph[1] - p[1]) / h]);
      } catch {
        J.push([0, 0]);
      }
    }
    // dq = J^T (J J^T + lambda^2 I)^-1 e, a 2 x 2 solve.
    const l2 = (DAMPING * L) ** 2;
    let [a, b, d] = [l2, 0, l2];
    for (const [jx, jy] of J) { a += jx * jx; b += jx * jy; d += jy * jy; }
    const det = a * d - b * b;
    const y = [(d * e[0] - b * e[1]) / det, (a * e[1] - b * e[0]) / det];
    const dq = J.map(([jx, jy], j) => Math.max(-MAX_STEP * unit[j], Math.min(MAX_STEP * unit[j], jx * y[0] + jy * y[1])));
    const qn = cq.map((v, j) => v + dq[j]);
    try {
      cx = mech.assemble(qn, cx);
      cq = qn;
    } catch {
      return it ? { q: cq, x: cx } : null;
    }
  }
  return { q: cq, x: cx };
}
