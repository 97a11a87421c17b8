//! The stages of an evaluation (docs/formulation.md eqs. 29-31), shared by forward and inverse
//! dynamics, the dynamics with losses, with prescribed coordinates and with redundant
//! actuation, and their derivatives: the kinematic stages (positions -> analogues U ->
//! convective term c, and the user's q, qd), the drives' efforts, A = U^T M U,
//! b = U^T (f - M c), its factor and zdd = A^-1 b, xdd = U zdd + c and the user's qdd.
//! Each reads and fills the buffers of a [`Workspace`] named in its doc.

use super::forces::Drives;
use super::workspace::Workspace;
use crate::kinematics::analogues::u_times_from;
use crate::kinematics::constraints::{
    coordinate_rates, coordinates, pair_coordinate_gamma, pair_coordinate_grad, pair_coordinate_rate, Dense,
};
use crate::kinematics::{convective, solve_position, velocity_analogues, Chart, Frame, USupport};
use crate::linalg::{
    cholesky_envelope, cholesky_envelope_fixed, cholesky_in_place, cholesky_solve, cholesky_solve_envelope,
    cholesky_solve_envelope_fixed, copy_small,
};
use crate::model::{Body, Mechanism, PairId};
use crate::{Error, KinematicsError, SingularityKind};

/// Positions, analogues and the convective term at chart coordinates z, zd (`ws.x` is the
/// Newton start), then the user's coordinates q and rates qd.
pub fn kinematic_stages(mech: &Mechanism, z: &[f64], zd: &[f64], ws: &mut Frame) -> Result<(), KinematicsError> {
    solve_position(mech, z, ws)?;
    velocity_analogues(ws)?;
    convective(mech, zd, ws);
    user_coordinates(mech, ws, z, zd);
    Ok(())
}

/// The user's coordinates and rates from x, xd. In the input chart they are the chart's own
/// z, zd: D(x) = z to the Newton tolerance and D_x U = I, so they are copied rather than
/// recomputed.
fn user_coordinates(mech: &Mechanism, ws: &mut Frame, z: &[f64], zd: &[f64]) {
    if ws.chart == Chart::Inputs {
        copy_small(&mut ws.q, z);
        copy_small(&mut ws.qd, zd);
    } else {
        coordinates(mech, &ws.x, &mut ws.q);
        coordinate_rates(mech, &ws.x, &ws.xd, &mut ws.qd);
    }
}

/// The drives' efforts at time t (s) and the point in `ws` into `ws.tau`, checked finite.
pub(crate) fn drive_efforts(t: f64, drives: &mut dyn Drives, ws: &mut Workspace) -> Result<(), Error> {
    drives.efforts(t, &ws.frame.q, &ws.frame.qd, &mut ws.tau).map_err(|message| Error::Drive { t, message })?;
    if let Some(bad) = ws.tau.iter().position(|v| !v.is_finite()) {
        return Err(Error::Drive { t, message: format!("effort {bad} is {}", ws.tau[bad]) });
    }
    Ok(())
}

/// Add the efforts of the pair actuators without a motor (`ws.pair_tau`) to `ws.f`; returns
/// their power (W). A motor's torque goes through its gear (`dynamics::gears`).
pub(crate) fn apply_pair_efforts(mech: &Mechanism, ws: &mut Workspace) -> f64 {
    let mut power = 0.0;
    for (a, &e) in mech.pair_actuators.iter().zip(&ws.pair_tau) {
        if e != 0.0 && a.drive.is_none() {
            let rate = pair_coordinate_rate(&mech.pairs[a.pair.0], &ws.x, &ws.xd);
            pair_grad(mech, a.pair, &ws.frame.x, &mut ws.frame.tmp);
            ws.f.iter_mut().zip(&ws.frame.tmp).for_each(|(f, g)| *f += e * g);
            power += e * rate;
        }
    }
    power
}

/// The gradient of `pair`'s relative coordinate along x into `grad` (3n values).
pub(crate) fn pair_grad(mech: &Mechanism, pair: PairId, x: &[f64], grad: &mut [f64]) {
    grad.fill(0.0);
    pair_coordinate_grad(&mech.pairs[pair.0], x, &mut Dense { j: grad, ncols: x.len() }, 0);
}

/// a^T M b over the bodies of `runs` ([first, end), ascending; a and b: 3n values each),
/// M = blockdiag(m, m, I) per body; the terms added in order from -0.0 (f64's `Sum`).
/// Inlined: called per entry of A and of b, a call's overhead is a five-bar's whole sum.
#[inline(always)]
pub(crate) fn m_dot(mech: &Mechanism, a: &[f64], b: &[f64], runs: &[(usize, usize)]) -> f64 {
    let mut s = -0.0;
    for &run in runs {
        s = m_dot_from(s, mech, a, b, run);
    }
    s
}

/// `s` plus the terms of [`m_dot`], added one after the other (f64's `Sum` starts at -0.0).
#[inline]
fn m_dot_from(s: f64, mech: &Mechanism, a: &[f64], b: &[f64], (first, end): (usize, usize)) -> f64 {
    if first >= end {
        return s;
    }
    let (a, b) = (&a[3 * first..3 * end], &b[3 * first..3 * end]);
    mech.bodies[first..end]
        .iter()
        .zip(a.chunks_exact(3).zip(b.chunks_exact(3)))
        .fold(s, |s, (body, (a, b))| s + (body.mass * (a[0] * b[0] + a[1] * b[1]) + body.inertia * a[2] * b[2]))
}

/// A = U^T M U (m x m, row-major) into `ws.a`, from `ws.u`: the pairs of columns that share a
/// body (`System::a_pairs`), over the bodies they share (`System::a_runs`; the columns of
/// independent parts of a mechanism, five-bars side by side, share none). The other entries
/// keep the zeros of the last clearing, except where the Cholesky factor may have filled in
/// (`System::a_fill_in`): cleared at each call.
pub fn mass_matrix(mech: &Mechanism, ws: &mut Workspace) {
    let n = ws.x.len();
    let m = ws.b.len();
    let id = ws.sys.supports_id();
    if ws.a_zeros_for != id {
        ws.a.fill(0.0);
        ws.a_zeros_for = id;
    } else {
        for &(k, j) in ws.frame.sys.a_fill_in() {
            ws.a[k * m + j] = 0.0;
        }
    }
    for (p, &(j, k)) in ws.frame.sys.a_pairs().iter().enumerate() {
        let (uj, uk) = (&ws.frame.u[j * n..(j + 1) * n], &ws.frame.u[k * n..(k + 1) * n]);
        let s = m_dot(mech, uj, uk, ws.frame.sys.a_runs(p));
        ws.a[j * m + k] = s;
        ws.a[k * m + j] = s;
    }
}

/// b = U^T (f - M c) = U^T f - (U^T M c) into `ws.b`, from `ws.u`, `ws.f`, `ws.c`, each column
/// over its runs of bodies (`System::u_support`).
pub(crate) fn bias(mech: &Mechanism, ws: &mut Workspace) {
    let n = ws.x.len();
    let support = ws.frame.sys.u_support();
    for (j, bj) in ws.b.iter_mut().enumerate() {
        let uj = &ws.frame.u[j * n..(j + 1) * n];
        *bj = support.dot(j, uj, &ws.f) - m_dot(mech, uj, &ws.frame.c, support.runs(j));
    }
}

/// A = U^T M U and b = U^T (f - M c) into `ws.a` and `ws.b`, as [`mass_matrix`] and [`bias`]
/// give them; for up to [`FIXED_M`] coordinates in one pass over the bodies with fixed-size
/// accumulators ([`fixed_mass_matrix_and_bias`]), beyond that over the supports of U.
pub(crate) fn mass_matrix_and_bias(mech: &Mechanism, ws: &mut Workspace) {
    match ws.b.len() {
        1 => fixed_mass_matrix_and_bias::<1>(mech, ws),
        2 => fixed_mass_matrix_and_bias::<2>(mech, ws),
        3 => fixed_mass_matrix_and_bias::<3>(mech, ws),
        FIXED_M => fixed_mass_matrix_and_bias::<FIXED_M>(mech, ws),
        _ => {
            mass_matrix(mech, ws);
            bias(mech, ws);
        }
    }
}

/// A and b as the lossless forward evaluation ([`fixed_dynamics`]) sums them, to the bit: from 2
/// to [`FIXED_M`] coordinates b as [`fixed_mass_matrix_and_net_bias`] does, else as
/// [`mass_matrix_and_bias`]. For the other lossless callers whose accelerations are the
/// forward evaluation's (the derivatives' qdd is `forward_dynamics`' to the bit).
pub(crate) fn lossless_mass_matrix_and_bias(mech: &Mechanism, ws: &mut Workspace) {
    match ws.b.len() {
        2 => fixed_mass_matrix_and_net_bias::<2>(mech, ws),
        3 => fixed_mass_matrix_and_net_bias::<3>(mech, ws),
        FIXED_M => fixed_mass_matrix_and_net_bias::<FIXED_M>(mech, ws),
        _ => mass_matrix_and_bias(mech, ws),
    }
}

/// The most coordinates the stages take with fixed-size loops (`mass_matrix_and_bias`, the
/// Cholesky factor and solve): past a few, U's supports (which the fixed-size loops do not
/// use) save more than the loops' bookkeeping costs.
pub(crate) const FIXED_M: usize = 4;

/// [`mass_matrix_and_bias`] for M coordinates: every entry of A's upper triangle and of b
/// summed body by body over all bodies. U is zero outside its supports and a zero term leaves a
/// non-zero sum's bits as they are, so the entries are [`mass_matrix`]'s and [`bias`]'s to the
/// bit (an entry of zero terms only may differ in its zero's sign). A is written whole: its
/// zeros outside the envelope are there (`a_zeros_for`). From [`SPLIT_FROM_M`] coordinates A's
/// sums and b's take a pass over the bodies each: the same terms added in the same order, with
/// half the running sums of one pass (which then no longer fit the registers).
#[inline(never)]
fn fixed_mass_matrix_and_bias<const M: usize>(mech: &Mechanism, ws: &mut Workspace) {
    fixed_sums::<M, false>(mech, ws);
}

/// [`fixed_mass_matrix_and_bias`] with b = U^T g summed as eq. 31 writes it, g = f - M c a
/// body's net force ([`add_bias_terms`] with `NET`): one product a term of U instead of two (3-RRR
/// -255 instructions an evaluation, five-bar -50). The same A; b to round-off (the same sum
/// re-associated). For the lossless forward evaluation at 2 to [`FIXED_M`] coordinates only:
/// at m = 1 it cost 5 to 27 instructions, and the losses' and prescribed paths keep
/// [`bias`]'s bits (tests/test_prescribed_fold.py locates a self-locking fold's time to 1e-7 s
/// through friction, which the round-off moved by 3e-7 s).
#[inline(never)]
fn fixed_mass_matrix_and_net_bias<const M: usize>(mech: &Mechanism, ws: &mut Workspace) {
    fixed_sums::<M, true>(mech, ws);
}

/// [`fixed_mass_matrix_and_bias`]'s sums (with `NET`, [`fixed_mass_matrix_and_net_bias`]'s),
/// inlined where one coordinate's (a few instructions a body) are worth no call.
#[inline(always)]
fn fixed_sums<const M: usize, const NET: bool>(mech: &Mechanism, ws: &mut Workspace) {
    let n = ws.x.len();
    // Each column's body by body: three values a step with no bounds check of their own.
    let columns = || -> [std::slice::ChunksExact<f64>; M] {
        std::array::from_fn(|j| ws.frame.u[j * n..(j + 1) * n].chunks_exact(3))
    };
    let rows = |u: &mut [std::slice::ChunksExact<f64>; M]| -> [[f64; 3]; M] {
        std::array::from_fn(|j| {
            let p = u[j].next().expect("a column of U has three values a body");
            [p[0], p[1], p[2]]
        })
    };
    // The sums of `m_dot` and `bias` start at -0.0 (f64's `Sum`); with `NET`, `uf` is b.
    let (mut a, mut uf, mut umc) = ([[-0.0; M]; M], [-0.0; M], [-0.0; M]);
    let forces = ws.f.chunks_exact(3).zip(ws.frame.c.chunks_exact(3));
    if M >= SPLIT_FROM_M {
        let mut u = columns();
        for body in &mech.bodies {
            add_mass_terms(&mut a, body, &rows(&mut u));
        }
        let mut u = columns();
        for (body, (f, c)) in mech.bodies.iter().zip(forces) {
            add_bias_terms::<M, NET>(&mut uf, &mut umc, body, &rows(&mut u), f, c);
        }
    } else {
        let mut u = columns();
        for (body, (f, c)) in mech.bodies.iter().zip(forces) {
            let ui = rows(&mut u);
            add_mass_terms(&mut a, body, &ui);
            add_bias_terms::<M, NET>(&mut uf, &mut umc, body, &ui, f, c);
        }
    }
    for (j, row) in a.iter().enumerate() {
        for (k, &v) in row.iter().enumerate().skip(j) {
            (ws.a[j * M + k], ws.a[k * M + j]) = (v, v);
        }
        ws.b[j] = if NET { uf[j] } else { uf[j] - umc[j] };
    }
    ws.a_zeros_for = ws.frame.sys.supports_id();
}

/// From how many coordinates [`fixed_mass_matrix_and_bias`] sums A and b in a pass each (the
/// 3-RRR's 12 running sums in one pass spill to the stack).
const SPLIT_FROM_M: usize = 3;

/// One body's terms of A's upper triangle (`ui` its rows of U's columns), as `m_dot` adds them.
#[inline(always)]
fn add_mass_terms<const M: usize>(a: &mut [[f64; M]; M], body: &Body, ui: &[[f64; 3]; M]) {
    for (j, p) in ui.iter().enumerate() {
        for (k, q) in ui.iter().enumerate().skip(j) {
            a[j][k] += body.mass * (p[0] * q[0] + p[1] * q[1]) + body.inertia * p[2] * q[2];
        }
    }
}

/// One body's terms of U^T f (`uf`, as `USupport::dot` adds them) and of U^T M c (`umc`, as
/// `m_dot`), f and c its forces and convective accelerations; with `NET`, of b = U^T g into
/// `uf`, g = f - M c the body's net force (as `USupport::dot` adds U^T g's).
#[inline(always)]
fn add_bias_terms<const M: usize, const NET: bool>(
    uf: &mut [f64; M],
    umc: &mut [f64; M],
    body: &Body,
    ui: &[[f64; 3]; M],
    f: &[f64],
    c: &[f64],
) {
    if NET {
        let g = [f[0] - body.mass * c[0], f[1] - body.mass * c[1], f[2] - body.inertia * c[2]];
        for (b, p) in uf.iter_mut().zip(ui) {
            *b = *b + p[0] * g[0] + p[1] * g[1] + p[2] * g[2];
        }
        return;
    }
    for (j, p) in ui.iter().enumerate() {
        uf[j] = uf[j] + p[0] * f[0] + p[1] * f[1] + p[2] * f[2];
        umc[j] += body.mass * (p[0] * c[0] + p[1] * c[1]) + body.inertia * p[2] * c[2];
    }
}

/// `ws.a` into its Cholesky factor, or the singularity that keeps A from being positive definite.
/// Over A's envelope from the supports of U when `mass_matrix` left A within it.
pub(crate) fn factor_mass_matrix(ws: &mut Workspace) -> Result<(), KinematicsError> {
    let m = ws.b.len();
    let factored = if ws.a_zeros_for == ws.sys.supports_id() {
        cholesky_envelope(&mut ws.a, m, ws.frame.sys.a_first())
    } else {
        cholesky_in_place(&mut ws.a, m)
    };
    if !factored {
        return Err(not_positive_definite(ws));
    }
    Ok(())
}

/// The singularity that keeps A from being positive definite in the chart of `ws`.
fn not_positive_definite(ws: &Workspace) -> KinematicsError {
    let type_ii = matches!(ws.chart, Chart::Inputs);
    KinematicsError::singular(SingularityKind::MassMatrix { type_ii })
}

/// The stages after the forces for M coordinates (up to [`FIXED_M`]) in one function and no
/// bookkeeping of A's pattern: A and b as [`mass_matrix_and_bias`] sums them (from 2
/// coordinates b as [`fixed_mass_matrix_and_net_bias`] does, to round-off), A's factor into
/// `ws.a` (as [`factor_mass_matrix`] leaves it), zdd = A^-1 b, xdd = U zdd + c and the user's
/// qdd; the operations of [`mass_matrix_and_bias`], [`factor_mass_matrix`],
/// [`solve_mass_matrix`] and [`accelerations`] (with its few columns' one pass), without the
/// dispatch on m and the calls between the stages.
pub(crate) fn fixed_dynamics<const M: usize>(mech: &Mechanism, ws: &mut Workspace) -> Result<(), KinematicsError> {
    // Inlined at M = 1 (the five m = 1 models -3 to -13 instructions an evaluation); at M = 2
    // and 3 the call keeps the caller's code as it compiles best (s18: 3-RRR +149 inlined).
    if M == 1 {
        fixed_sums::<M, false>(mech, ws);
    } else {
        fixed_mass_matrix_and_net_bias::<M>(mech, ws);
    }
    let first = ws.frame.sys.a_first();
    if !cholesky_envelope_fixed::<M>(&mut ws.a, first) {
        return Err(not_positive_definite(ws));
    }
    let mut zdd: [f64; M] = std::array::from_fn(|j| ws.b[j]);
    cholesky_solve_envelope_fixed::<M>(&ws.a, first, &mut zdd);
    ws.zdd.copy_from_slice(&zdd);
    // xdd = c + U zdd, each entry's terms added column by column (as `body_accelerations`).
    let n = ws.xdd.len();
    let u: [&[f64]; M] = std::array::from_fn(|j| &ws.frame.u[j * n..][..n]);
    for (i, (x, c)) in ws.xdd.iter_mut().zip(&ws.frame.c[..n]).enumerate() {
        let mut s = *c;
        for (uj, zj) in u.iter().zip(&zdd) {
            s += uj[i] * zj;
        }
        *x = s;
    }
    user_accelerations(mech, ws);
    Ok(())
}

/// zdd = A^-1 b into `ws.zdd`, with the factor from [`factor_mass_matrix`].
pub(crate) fn solve_mass_matrix(ws: &mut Workspace) {
    let mut zdd = std::mem::take(&mut ws.zdd);
    zdd.copy_from_slice(&ws.b);
    solve_factored(ws, &mut zdd);
    ws.zdd = zdd;
}

/// A^-1 rhs in place, with the factor from [`factor_mass_matrix`] (over its envelope when it
/// kept one).
pub(crate) fn solve_factored(ws: &Workspace, rhs: &mut [f64]) {
    let m = rhs.len();
    if ws.a_zeros_for == ws.sys.supports_id() {
        cholesky_solve_envelope(&ws.a, m, ws.sys.a_first(), rhs);
    } else {
        cholesky_solve(&ws.a, m, rhs);
    }
}

/// Body accelerations xdd = U zdd + c and the user's qdd from the chart accelerations
/// `ws.zdd`, at the point of the kinematic stages.
pub(crate) fn accelerations(mech: &Mechanism, ws: &mut Workspace) {
    body_accelerations(&ws.frame.u, &ws.frame.c, &ws.zdd, ws.frame.sys.u_support(), &mut ws.xdd);
    user_accelerations(mech, ws);
}

/// The user's accelerations from x, xd and xdd; in the input chart the chart's own zdd
/// (as [`user_coordinates`]). Inlined, that copy: the other charts' pass out of line.
#[inline(always)]
fn user_accelerations(mech: &Mechanism, ws: &mut Workspace) {
    if ws.chart == Chart::Inputs {
        copy_small(&mut ws.qdd, &ws.zdd);
    } else {
        user_accelerations_from_x(mech, ws);
    }
}

/// The user's accelerations from x, xd and xdd (outside the input chart).
#[inline(never)]
fn user_accelerations_from_x(mech: &Mechanism, ws: &mut Workspace) {
    for (k, c) in mech.coordinates.iter().enumerate() {
        let p = &mech.pairs[c.pair.0];
        ws.qdd[k] = pair_coordinate_rate(p, &ws.x, &ws.xdd) + pair_coordinate_gamma(p, &ws.x, &ws.xd, &ws.xd);
    }
}

/// xdd = U zdd + c: the body accelerations of chart accelerations zdd (U column-major,
/// one column of 3n a coordinate), each column over its runs of bodies in `support`
/// (`System::u_support`), where it may be non-zero.
pub(crate) fn body_accelerations(u: &[f64], c: &[f64], zdd: &[f64], support: &USupport, xdd: &mut [f64]) {
    u_times_from(u, support, |j| zdd[j], |i, _| c[i], xdd);
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A and b with fixed-size sums body by body (`mass_matrix_and_bias` up to `FIXED_M`
    /// coordinates; from `SPLIT_FROM_M` on, A's sums and b's in a pass over the bodies each)
    /// equal those over U's supports (`mass_matrix`, `bias`) to the bit, but for the sign of an
    /// entry of zero terms only: the four-bar (m = 1), five-bar (2) and 3-RRR (3) at their
    /// drawings, with rates of both signs and forces of every component on every body.
    #[test]
    fn fixed_sums_are_the_supports_sums_to_the_bit() {
        for (model, m) in [("four-bar-gravity", 1), ("five-bar", 2), ("3-rrr", 3)] {
            let path = format!("{}/../../examples/models/{model}.yaml", env!("CARGO_MANIFEST_DIR"));
            let mech = crate::load(&path).unwrap();
            let (z, _) = mech.initial_state();
            assert_eq!(z.len(), m, "{model}");
            let zd = &[0.7, -1.3, 0.4][..m];
            let (mut fixed, mut supports) = (Workspace::new(&mech), Workspace::new(&mech));
            for ws in [&mut fixed, &mut supports] {
                kinematic_stages(&mech, &z, zd, ws).unwrap();
                // Forces with all three components on every body (gravity alone has one).
                ws.f.iter_mut().enumerate().for_each(|(i, f)| *f = 2.0 * (0.37 * i as f64).sin() + 0.1);
            }
            mass_matrix_and_bias(&mech, &mut fixed);
            mass_matrix(&mech, &mut supports);
            bias(&mech, &mut supports);
            for (what, x, y) in [("A", &fixed.a, &supports.a), ("b", &fixed.b, &supports.b)] {
                let same = x.iter().zip(y.iter()).all(|(p, q)| p.to_bits() == q.to_bits() || (*p == 0.0 && *q == 0.0));
                assert!(same && x.len() == y.len(), "{what} of {model}: {x:?} against {y:?}");
                assert!(x.iter().any(|v| *v != 0.0), "{what} of {model} is zero");
            }
        }
    }

    /// The lossless path's b = U^T g (g = f - M c body by body) equals U^T g summed over U's
    /// supports (`USupport::dot`, g formed apart) to the bit, and A is `mass_matrix`'s; and b
    /// agrees with U^T f - U^T M c (`bias`) to round-off (the sums re-associated). Five-bar (m = 2) and 3-RRR (3) at their
    /// drawings, rates of both signs, forces of every component on every body.
    #[test]
    fn net_bias_is_u_transpose_of_f_less_m_c() {
        for (model, m) in [("five-bar", 2), ("3-rrr", 3)] {
            let path = format!("{}/../../examples/models/{model}.yaml", env!("CARGO_MANIFEST_DIR"));
            let mech = crate::load(&path).unwrap();
            let (z, _) = mech.initial_state();
            let zd = &[0.7, -1.3, 0.4][..m];
            let mut ws = Workspace::new(&mech);
            kinematic_stages(&mech, &z, zd, &mut ws).unwrap();
            ws.f.iter_mut().enumerate().for_each(|(i, f)| *f = 2.0 * (0.37 * i as f64).sin() + 0.1);
            match m {
                2 => fixed_mass_matrix_and_net_bias::<2>(&mech, &mut ws),
                _ => fixed_mass_matrix_and_net_bias::<3>(&mech, &mut ws),
            }
            let (a, b) = (ws.a.clone(), ws.b.clone());
            let g: Vec<f64> = (mech.bodies.iter().zip(ws.f.chunks_exact(3)).zip(ws.frame.c.chunks_exact(3)))
                .flat_map(|((body, f), c)| {
                    [f[0] - body.mass * c[0], f[1] - body.mass * c[1], f[2] - body.inertia * c[2]]
                })
                .collect();
            let n = ws.x.len();
            let support = ws.frame.sys.u_support();
            let by_supports: Vec<f64> = (0..m).map(|j| support.dot(j, &ws.frame.u[j * n..(j + 1) * n], &g)).collect();
            assert!(
                b.iter().zip(&by_supports).all(|(p, q)| p.to_bits() == q.to_bits()),
                "{model}: {b:?} against {by_supports:?}"
            );
            // The sums' scale: U^T (|f| + |M c|) with |U|, whose n eps (n < 30 terms) bounds
            // the round-off of either association.
            let abs_u: Vec<f64> = ws.frame.u.iter().map(|v| v.abs()).collect();
            let abs_g: Vec<f64> = (mech.bodies.iter().zip(ws.f.chunks_exact(3)).zip(ws.frame.c.chunks_exact(3)))
                .flat_map(|((body, f), c)| {
                    [
                        f[0].abs() + (body.mass * c[0]).abs(),
                        f[1].abs() + (body.mass * c[1]).abs(),
                        f[2].abs() + (body.inertia * c[2]).abs(),
                    ]
                })
                .collect();
            let scale: Vec<f64> = (0..m).map(|j| support.dot(j, &abs_u[j * n..(j + 1) * n], &abs_g)).collect();
            mass_matrix(&mech, &mut ws);
            bias(&mech, &mut ws);
            let same = a.iter().zip(&ws.a).all(|(p, q)| p.to_bits() == q.to_bits() || (*p == 0.0 && *q == 0.0));
            assert!(same, "A of {model}: {a:?} against {:?}", ws.a);
            for j in 0..m {
                assert!(
                    (b[j] - ws.b[j]).abs() <= 30.0 * f64::EPSILON * scale[j],
                    "b of {model}: {b:?} against {:?}",
                    ws.b
                );
            }
        }
    }
}
