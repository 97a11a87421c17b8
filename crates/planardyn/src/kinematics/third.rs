//! Third-order analogues: how the convective term c = sum_jl zd_j zd_l w_jl changes with the
//! coordinates (docs/formulation.md, *Derivatives*). Differentiating J c = -gamma(xd, xd)
//! along z_k, where x moves by u_k and xd = U zd by v_k = sum_l w_kl zd_l, gives
//!
//!   J dc/dz_k = -[gamma3(xd, xd, u_k) + gamma(c, u_k) + 2 gamma(xd, v_k)],
//!
//! one more right-hand side for the factorised J per coordinate.

use super::constraints::{gamma, Chart};
use super::frame::Frame;
use crate::model::pairs;
use crate::model::Mechanism;

/// gamma3(u, v, t) = d3F/dx3 [u, v, t] for every row of F (the chart rows of a partition
/// are linear), into `out` (3n).
#[allow(clippy::too_many_arguments)]
pub fn gamma3(
    mech: &Mechanism,
    chart: &Chart,
    x: &[f64],
    trig: &[[f64; 2]],
    u: &[f64],
    v: &[f64],
    t: &[f64],
    out: &mut [f64],
) {
    let nc = mech.n_constraints;
    for (pair, slots) in mech.pairs.iter().zip(&mech.pair_slots) {
        let rows = pairs::gamma3(pair, x, trig, u, v, t);
        for (slot, value) in slots.iter().zip(rows) {
            if let Some(i) = *slot {
                out[i] = value;
            }
        }
    }
    for (k, o) in out[nc..].iter_mut().enumerate() {
        *o = match chart {
            Chart::Inputs => pairs::coordinate_gamma3(&mech.pairs[mech.coordinates[k].pair.0], x, u, v, t),
            Chart::Partition(_) => 0.0,
            Chart::Pairs(idx) => pairs::coordinate_gamma3(&mech.pairs[idx[k]], x, u, v, t),
        };
    }
}

/// dc/dz_k (3n) into `dc`, for the direction u_k = `uk` and v_k = `vk` (both 3n), from the
/// buffers of `ws` after the convective stage; `scratch` has length 3n.
pub fn convective_derivative(
    mech: &Mechanism,
    ws: &mut Frame,
    uk: &[f64],
    vk: &[f64],
    dc: &mut [f64],
    scratch: &mut [f64],
) {
    {
        let (x, trig, xd) = (&ws.x, &ws.trig, &ws.xd);
        gamma3(mech, &ws.chart, x, trig, xd, xd, uk, dc);
        gamma(mech, &ws.chart, x, trig, &ws.c, uk, scratch);
        dc.iter_mut().zip(scratch.iter()).for_each(|(d, s)| *d += s);
        gamma(mech, &ws.chart, x, trig, xd, vk, scratch);
    }
    dc.iter_mut().zip(scratch.iter()).for_each(|(d, s)| *d = -(*d + 2.0 * s));
    ws.sys.solve(dc);
}
