//! Position analysis: Newton's method on F(x) = 0 from the last solution, and continuation
//! in the coordinates for larger moves (it stays on the branch the mechanism is drawn in).

use super::analogues::velocity_analogues;
use super::constraints::{body_trig, residual, set_row_scale, Chart};
use super::frame::Frame;
use crate::model::{CoordinateKind, Mechanism, MAX_CONTINUATION_DISTANCE};
use crate::KinematicsError;

/// Convergence test of Newton's method: the largest residual, lengths divided by the
/// characteristic length L and angles in radians, below 1e-14 (about 50 ulp of O(1) values).
/// Looser positions are noise in the right-hand side: at 1e-12 a five-bar integrated at
/// rtol 1e-12 through partition charts lost 3e-8 J; at 1e-14, 3e-10 J.
pub const POSITION_TOL: f64 = 1e-14;
/// A residual this small that Newton no longer reduces is accepted: round-off has been
/// reached (ill-conditioned J or large coordinates).
pub(crate) const ROUND_OFF_FLOOR: f64 = 1e-11;
/// Residuals above this (scaled) get a last Newton step after convergence, so positions
/// are accurate to ~1e-14 whichever way the tolerance was met.
pub(crate) const POLISH_BELOW: f64 = 1e-14;
/// Newton iterations before giving up; from a first-order predictor it takes 1 to 3.
pub const MAX_NEWTON: usize = 30;

/// Chord iterations (with the factorisation of the previous, nearby point) tried before
/// full Newton: each costs a residual and a solve instead of a factorisation, and converges
/// at a rate about the distance moved times the conditioning.
const MAX_CHORD: usize = 6;
/// A chord iteration must shrink the residual at least this much, else full Newton takes over.
const CHORD_RATE: f64 = 0.25;

/// F(x) into `ws.tmp` (with `ws.trig` refreshed for x); returns its scaled max-norm.
fn residual_norm(mech: &Mechanism, z: &[f64], ws: &mut Frame) -> f64 {
    body_trig(&ws.x, &mut ws.trig);
    residual(mech, &ws.chart, &ws.x, &ws.trig, z, &mut ws.tmp);
    ws.tmp.iter().zip(&ws.sys.row_scale).fold(0.0, |m: f64, (r, s)| m.max((r * s).abs()))
}

/// x -= J^-1 F with the factorisation held in `ws.sys`.
fn newton_update(ws: &mut Frame) {
    ws.sys.solve(&mut ws.tmp);
    for (xi, dx) in ws.x.iter_mut().zip(&ws.tmp) {
        *xi -= dx;
    }
}

/// Solve F(x; z) = 0 for x from the start guess in `ws.x`, in the chart `ws.chart`. On
/// success `ws.x` is the solution, `ws.trig` its angles' cos/sin, `ws.sys` holds J(x)
/// factorised and `ws.residual` the scaled residual. Fails if J is singular on the way or
/// Newton does not converge.
pub fn solve_position(mech: &Mechanism, z: &[f64], ws: &mut Frame) -> Result<(), KinematicsError> {
    let tol =
        POSITION_TOL * (1.0 + ws.x.iter().zip(&ws.sys.col_scale).fold(0.0, |m: f64, (v, s)| m.max((v / s).abs())));
    set_row_scale(mech, &ws.chart, &mut ws.sys.row_scale);
    if ws.sys.is_factored_for(&ws.chart) {
        ws.rhs.copy_from_slice(&ws.x);
        let (mut first, mut last) = (f64::NAN, f64::INFINITY);
        for it in 0..MAX_CHORD {
            let norm = residual_norm(mech, z, ws);
            if norm <= tol {
                return converged(mech, ws, norm, it);
            }
            if it == 0 {
                first = norm;
            }
            if !(norm < CHORD_RATE * last) {
                if !(norm < first) {
                    ws.x.copy_from_slice(&ws.rhs); // went astray: restart Newton from the guess
                }
                break;
            }
            last = norm;
            newton_update(ws);
        }
    }
    let (mut first, mut previous) = (f64::INFINITY, f64::INFINITY);
    for it in 0..=MAX_NEWTON {
        let norm = residual_norm(mech, z, ws);
        if !norm.is_finite() || norm > 1e6 * first.max(1.0) {
            break;
        }
        first = first.min(norm);
        if norm <= tol || (norm <= ROUND_OFF_FLOOR && norm > 0.5 * previous) {
            return converged(mech, ws, norm, it);
        }
        previous = norm;
        factor(mech, ws)?;
        newton_update(ws);
    }
    let residual = residual_norm(mech, z, ws);
    Err(KinematicsError::AssemblyFailed { residual, iterations: MAX_NEWTON })
}

/// Factorise J at the solution (the analogues need it); if the residual is only just below
/// the tolerance, take one more Newton step with that J (F(x) is still in `ws.tmp`), which
/// takes it to round-off for one solve. J and the trig cache then belong to a point within
/// the tolerance, as accurate as the analogues are anyway. Then record the figures.
fn converged(mech: &Mechanism, ws: &mut Frame, norm: f64, iterations: usize) -> Result<(), KinematicsError> {
    factor(mech, ws)?;
    if norm > POLISH_BELOW || matches!(ws.chart, Chart::Partition(_)) {
        newton_update(ws);
    }
    ws.residual = norm;
    ws.iterations = iterations;
    Ok(())
}

fn factor(mech: &Mechanism, ws: &mut Frame) -> Result<(), KinematicsError> {
    let chart = &ws.chart;
    ws.sys.factor(mech, chart, &ws.x, &ws.trig).map_err(|_| KinematicsError::singular(chart.singularity()))
}

/// Smallest continuation step, as a fraction of the whole move, before giving up.
const MIN_CONTINUATION_STEP: f64 = 1e-6;
/// Largest continuation step in any coordinate: 0.1 rad, or 0.1 L for a displacement. The
/// Newton correction after a first-order predictor is then O(0.01) (scaled), far inside the
/// basin of the branch being followed.
const MAX_CONTINUATION_MOVE: f64 = 0.1;
/// A Newton correction larger than this (scaled: lengths / L, angles in rad) means the solve
/// may have left the branch it started on (another assembly mode is O(1) away): the step is
/// refused and cut, by continuation here and by the integrator in a simulation.
pub const MAX_CORRECTION: f64 = 0.1;

/// Largest scaled difference between two body-coordinate vectors.
pub fn scaled_distance(a: &[f64], b: &[f64], col_scale: &[f64]) -> f64 {
    let [d] = scaled_distances(a, [b], col_scale);
    d
}

/// [`scaled_distance`] of `a` from each of `bs`, in one pass. Each distance is the largest of
/// its scaled differences, taken in two lanes (even and odd entries, one packed divide for both)
/// and then between the lanes: a maximum is the same whatever the order of its terms, so this is
/// the entry-by-entry maximum to the bit (11 instructions a pair of entries and distance, where
/// one loop packing two distances across a register took 14 an entry).
#[inline]
pub fn scaled_distances<const K: usize>(a: &[f64], bs: [&[f64]; K], col_scale: &[f64]) -> [f64; K] {
    // Up to 7 bodies, the count of entries a constant: the pairs' loop unrolls, with no bounds
    // check or loop control. The ODE's two distances of every evaluation (`benchmarks/icount`):
    // four-bar 147 -> 121 instructions, five-bar 179 -> 151, 3-RRR 279 -> 217.
    match a.len().min(col_scale.len()) {
        6 => lanes(6, a, bs, col_scale),
        9 => lanes(9, a, bs, col_scale),
        12 => lanes(12, a, bs, col_scale),
        15 => lanes(15, a, bs, col_scale),
        18 => lanes(18, a, bs, col_scale),
        21 => lanes(21, a, bs, col_scale),
        n => lanes(n, a, bs, col_scale),
    }
}

/// [`scaled_distances`] over the first n entries. A pass over the entries for each distance:
/// the compiler then packs a pair of entries, not a pair of distances, into one divide.
#[inline(always)]
fn lanes<const K: usize>(n: usize, a: &[f64], bs: [&[f64]; K], col_scale: &[f64]) -> [f64; K] {
    let mut d = [0.0; K];
    for (d, b) in d.iter_mut().zip(bs) {
        *d = lane_distance(&a[..n], &b[..n], &col_scale[..n]);
    }
    d
}

/// One distance of [`scaled_distances`] (a, b and s of one length). An odd last entry starts
/// the even lane.
#[inline(always)]
fn lane_distance(a: &[f64], b: &[f64], s: &[f64]) -> f64 {
    let ((a_pairs, a_last), (b_pairs, b_last)) = (a.as_chunks::<2>(), b.as_chunks::<2>());
    let (s_pairs, s_last) = s.as_chunks::<2>();
    let mut lanes = [0.0_f64; 2];
    if let ([x], [b], [s]) = (a_last, b_last, s_last) {
        lanes[0] = at_least(0.0, (x - b).abs() / s);
    }
    for ((x, b), s) in a_pairs.iter().zip(b_pairs).zip(s_pairs) {
        for l in 0..2 {
            lanes[l] = at_least(lanes[l], (x[l] - b[l]).abs() / s[l]);
        }
    }
    at_least(lanes[0], lanes[1])
}

/// `d.max(q)` for a d that is never NaN (it starts at 0 and takes only a q above it): a NaN q
/// is passed over as `max` passes it over, and this select is x86's `maxpd`, one instruction
/// where `max`'s NaN test takes four.
#[inline(always)]
fn at_least(d: f64, q: f64) -> f64 {
    if q > d {
        q
    } else {
        d
    }
}

/// Move the solution in `ws` (converged at `z_from` in the input chart) to the user
/// coordinates `q` by continuation: steps of at most 0.1 rad (0.1 L), a first-order predictor
/// along the velocity analogues, a Newton corrector whose correction must stay small (so the
/// branch is kept), and the step cut by 4 when either fails.
pub fn continue_to(mech: &Mechanism, z_from: &[f64], q: &[f64], ws: &mut Frame) -> Result<(), KinematicsError> {
    ws.chart = Chart::Inputs;
    let (m, n) = (q.len(), ws.x.len());
    let move_scaled = mech.coordinates.iter().zip(q.iter().zip(z_from)).fold(0.0, |acc: f64, (c, (a, b))| {
        let unit = if c.kind == CoordinateKind::Angle { 1.0 } else { mech.scale };
        acc.max((a - b).abs() / unit)
    });
    if !(move_scaled <= MAX_CONTINUATION_DISTANCE) {
        return Err(KinematicsError::bad_argument(
            "q",
            format!(
                "coordinates within {MAX_CONTINUATION_DISTANCE:e} (rad, or lengths of the drawing) of the configuration \
                 the position analysis continues from ({z_from:?}); go there in shorter moves, each from the last"
            ),
            format!("{q:?}"),
        ));
    }
    let h_max = if move_scaled > 0.0 { (MAX_CONTINUATION_MOVE / move_scaled).min(1.0) } else { 1.0 };
    // U is unavailable at a singular start: plain Newton from x then.
    let mut u_ok = velocity_analogues(ws).ok().map(|_| ws.u.clone());
    let mut x_ok = ws.x.clone();
    let mut predicted = ws.x.clone();
    let (mut s, mut h) = (0.0_f64, h_max);
    let mut z = vec![0.0; m];
    while s < 1.0 {
        let s_new = (s + h).min(1.0);
        predicted.copy_from_slice(&x_ok);
        for k in 0..m {
            let dq = q[k] - z_from[k];
            z[k] = z_from[k] + s_new * dq;
            if let Some(u) = &u_ok {
                for (p, uk) in predicted.iter_mut().zip(&u[k * n..(k + 1) * n]) {
                    *p += uk * (s_new - s) * dq;
                }
            }
        }
        ws.x.copy_from_slice(&predicted);
        let solved = solve_position(mech, &z, ws).and_then(|()| {
            let correction = scaled_distance(&ws.x, &predicted, &ws.sys.col_scale);
            if u_ok.is_some() && correction > MAX_CORRECTION {
                Err(KinematicsError::AssemblyFailed { residual: correction, iterations: ws.iterations })
            } else {
                Ok(())
            }
        });
        match solved {
            Ok(()) => {
                s = s_new;
                x_ok.copy_from_slice(&ws.x);
                u_ok = velocity_analogues(ws).ok().map(|_| ws.u.clone());
                h = (2.0 * h).min(h_max);
            }
            Err(e) => {
                h /= 4.0;
                if h < MIN_CONTINUATION_STEP {
                    ws.x.copy_from_slice(&x_ok);
                    return Err(e);
                }
            }
        }
    }
    Ok(())
}

/// What a slice given for finite values holds, when it is not that: its length, or where a
/// non-finite value sits.
fn finite_values(v: &[f64]) -> String {
    match v.iter().position(|x| !x.is_finite()) {
        Some(i) => format!("{} at index {i} of {} values", v[i], v.len()),
        None => format!("{} values", v.len()),
    }
}

/// As [`assemble_into`], but continuing from the body coordinates `x_start` (a solution on
/// the wanted branch, e.g. the previous point of a path) instead of from the drawing.
pub fn assemble_from(mech: &Mechanism, x_start: &[f64], q: &[f64], ws: &mut Frame) -> Result<(), KinematicsError> {
    if x_start.len() != mech.n_x() || x_start.iter().any(|v| !v.is_finite()) {
        return Err(KinematicsError::bad_argument(
            "x_start",
            format!("{} finite body coordinates (X, Y, phi per body)", mech.n_x()),
            finite_values(x_start),
        ));
    }
    ws.chart = Chart::Inputs;
    ws.x.copy_from_slice(x_start);
    let mut z = vec![0.0; mech.dof()];
    super::constraints::coordinates(mech, x_start, &mut z);
    solve_position(mech, &z, ws)?;
    continue_to(mech, &z, q, ws)
}

/// Body coordinates x at user coordinates q, by continuation from the drawing.
pub fn assemble(mech: &Mechanism, q: &[f64]) -> Result<Vec<f64>, KinematicsError> {
    let mut ws = Frame::new(mech);
    assemble_into(mech, q, &mut ws)?;
    Ok(ws.x)
}

/// As [`assemble`], leaving the solution (and J factorised, if regular) in `ws`.
pub fn assemble_into(mech: &Mechanism, q: &[f64], ws: &mut Frame) -> Result<(), KinematicsError> {
    if q.len() != mech.dof() || q.iter().any(|v| !v.is_finite()) {
        return Err(KinematicsError::bad_argument(
            "q",
            format!("{} finite coordinate values ({})", mech.dof(), mech.coordinate_names().join(", ")),
            format!("{q:?}"),
        ));
    }
    ws.chart = Chart::Inputs;
    ws.x.copy_from_slice(&mech.x0);
    let drawn = mech.drawn_q();
    if drawn == q {
        // The drawing closes by construction; J may still be singular there.
        return match solve_position(mech, q, ws) {
            Err(KinematicsError::Singular { .. }) => Ok(()),
            other => other,
        };
    }
    solve_position(mech, &drawn, ws)?;
    continue_to(mech, &drawn, q, ws)
}

#[cfg(test)]
mod tests {
    /// `scaled_distances` (two lanes, then their maximum) gives each distance the bits of the
    /// entry-by-entry maximum `|a_i - b_i| / s_i` (a NaN entry passed over, as `f64::max`
    /// does), at odd and even lengths (the fixed sizes among them), for one to three distances.
    #[test]
    fn scaled_distances_are_the_entrywise_maximum_to_the_bit() {
        let entrywise = |a: &[f64], b: &[f64], s: &[f64]| {
            a.iter().zip(b).zip(s).fold(0.0_f64, |d, ((x, y), s)| d.max((x - y).abs() / s))
        };
        // A deterministic spread of values, signs and scales (no random source needed).
        let value = |k: usize| ((k * 7919 % 1013) as f64 - 506.0) * 1.37e-3 * (1.0 + (k % 5) as f64);
        for n in 0..25 {
            let a: Vec<f64> = (0..n).map(value).collect();
            let mut b: Vec<f64> = (0..n).map(|i| value(i + 101)).collect();
            let c: Vec<f64> = (0..n).map(|i| value(i + 211)).collect();
            let s: Vec<f64> = (0..n).map(|i| 0.5 + (i % 3) as f64).collect();
            if n > 4 {
                b[n / 2] = f64::NAN;
            }
            let [d1] = super::scaled_distances(&a, [&b], &s);
            let [d2, d3] = super::scaled_distances(&a, [&c, &b], &s);
            let [e1, e2, e3] = super::scaled_distances(&a, [&b, &c, &a], &s);
            assert_eq!(d1.to_bits(), entrywise(&a, &b, &s).to_bits(), "n = {n}");
            assert_eq!(d2.to_bits(), entrywise(&a, &c, &s).to_bits(), "n = {n}");
            assert_eq!((d3.to_bits(), e1.to_bits(), e2.to_bits()), (d1.to_bits(), d1.to_bits(), d2.to_bits()));
            assert_eq!(e3, 0.0, "n = {n}");
            assert!(n == 0 || d2 > 0.0, "n = {n}");
        }
    }
}
