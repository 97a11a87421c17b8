//! Pair reactions from the Lagrange multipliers: with the accelerations known,
//! M xdd = f + Phi_x^T mu, solved as J^T lambda = M xdd - f in the current chart (the chart
//! rows carry no force, so their multipliers vanish up to round-off; docs/formulation.md).

use crate::kinematics::constraints::rotate;
use crate::model::{Link, Mechanism, PairKind};
use crate::workspace::Workspace;

/// For each pair, [F_x, F_y, M]: the force (N, global) and the couple (N m) that body a
/// exerts on body b (the pair's first and second body), after a forward evaluation in `ws`.
/// The force acts at b's copy of the pair point (where a slider touches its guide); a
/// revolute pair transmits no couple; a prismatic pair's force is normal to its guide.
pub fn reactions(mech: &Mechanism, ws: &mut Workspace) -> Vec<[f64; 3]> {
    let mut lambda: Vec<f64> = (0..ws.x.len())
        .map(|i| {
            let b = &mech.bodies[i / 3];
            let mi = if i % 3 == 2 { b.inertia } else { b.mass };
            mi * ws.xdd[i] - ws.f[i]
        })
        .collect();
    ws.sys.solve_transpose(&mut lambda);
    mech.pairs
        .iter()
        .enumerate()
        .map(|(k, pair)| {
            // A redundant row left out of F carries no multiplier: the split of the load
            // between redundant pairs is statically indeterminate.
            let mu = [mech.row_slot[2 * k], mech.row_slot[2 * k + 1]].map(|s| s.map_or(0.0, |i| lambda[i]));
            match pair.kind {
                // Phi = p_a - p_b: the multiplier is the force on a, so -mu acts on b.
                PairKind::Revolute => [-mu[0], -mu[1], 0.0],
                PairKind::Prismatic { axis } => {
                    let phi_a = match pair.a {
                        Link::Ground => 0.0,
                        Link::Body(b) => ws.x[3 * b.0 + 2],
                    };
                    let n = rotate(phi_a, [-axis[1], axis[0]]);
                    [mu[1] * n[0], mu[1] * n[1], mu[0]]
                }
            }
        })
        .collect()
}
