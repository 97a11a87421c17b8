//! Pair reactions from the Lagrange multipliers: with the accelerations known,
//! M xdd = f + Phi_x^T mu, solved as J^T lambda = M xdd - f in the current chart (the chart
//! rows carry no force, so their multipliers vanish up to round-off; docs/formulation.md).

use crate::model::pairs;
use crate::model::Mechanism;
use crate::workspace::Workspace;

/// For each pair, [F_x, F_y, M]: the force (N, global) and the couple (N m) that body a
/// exerts on body b (the pair's first and second body), after a forward evaluation in `ws`.
/// The force is reduced to b's copy of the pair point (where a slider touches its guide, a
/// gear's centre); a revolute pair transmits no couple; a prismatic pair's force is normal
/// to its guide; each kind's is described in its module of `model::pairs`.
pub fn reactions(mech: &Mechanism, ws: &mut Workspace) -> Vec<[f64; 3]> {
    let (mut lambda, mut out) = (vec![0.0; ws.x.len()], vec![[0.0; 3]; mech.pairs.len()]);
    reactions_into(mech, ws, &mut lambda, &mut out);
    out
}

/// [`reactions`] into `out` (one per pair), with `lambda` (3n) as scratch.
pub(crate) fn reactions_into(mech: &Mechanism, ws: &mut Workspace, lambda: &mut [f64], out: &mut [[f64; 3]]) {
    for (i, l) in lambda.iter_mut().enumerate() {
        let b = &mech.bodies[i / 3];
        let mi = if i % 3 == 2 { b.inertia } else { b.mass };
        *l = mi * ws.xdd[i] - ws.f[i];
    }
    ws.sys.solve_transpose(lambda);
    for ((pair, slots), r) in mech.pairs.iter().zip(&mech.pair_slots).zip(out.iter_mut()) {
        // A redundant row left out of F carries no multiplier: the split of the load
        // between redundant pairs is statically indeterminate.
        *r = pairs::reaction(pair, &ws.x, slots.map(|s| s.map_or(0.0, |i| lambda[i])));
    }
}
