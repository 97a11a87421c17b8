//! Dense output of a run: q(t) and qd(t) at any time of it, from each accepted step's own
//! interpolant. A step's interpolant is a polynomial in t of the method's dense order p
//! ([`crate::integrate::Method::dense_order`]); it is stored as its values at p + 1
//! Chebyshev-Lobatto nodes of the step and evaluated by the barycentric formula, which gives
//! that polynomial back to round-off whatever the method (and needs no per-method layout).
//! The nodes include both ends, so the solution is continuous from step to step and equals
//! the accepted states at the step ends.

use crate::error::Time;

/// Pieces a step integrated in a partition chart is stored in, each with its own nodes. There
/// q(t) is not a polynomial but the assembly at the chart's interpolated values, whose
/// derivatives grow near the user's chart's singularity (why the chart is in use): through
/// the step's p + 1 points alone, qd was up to 85 times the run's tolerance off the mapped
/// interpolant (the five-bar free fall, DOPRI5 at rtol 1e-5). Pieces divide that by about
/// PIECES^(p + 1), at PIECES times the step's assemblies: with 3, below 0.3 of the tolerance
/// on the five-bars at rtol 1e-5 ... 1e-9 with DOPRI5, DOP853 and Radau5
/// (tests/test_dense_charts.py); from 1e-10 the assembly's round-off near the singularity,
/// 1e-10 ... 3e-10 rad/s, is that large. On the alternative charts' steps of the five-bar free
/// fall, 0.34 at most (DOPRI5 at rtol 1e-7, atol 1e-3 rtol, where a rate passes through 0 and
/// the tolerance is atol alone; 0.009 with DOP853) over rtol 1e-3 ... 1e-10, and sol's error
/// against a run at rtol 1e-13 is the outputs' own to 0.1 % (benchmarks/dense_sweep.py).
pub const PARTITION_PIECES: usize = 3;

/// The continuous solution of a run, step by step.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct DenseOutput {
    /// Number of coordinates m.
    pub m: usize,
    /// Nodes per step (the interpolant's degree + 1).
    pub nodes: usize,
    /// (steps + 1) step boundaries (s), increasing: the spans the nodes were placed on.
    pub breaks: Vec<f64>,
    /// End of the solution (s): the last break, or earlier after [`DenseOutput::truncate`].
    pub t_end: f64,
    /// (steps x nodes x 2m) [q, qd] at the nodes of each step.
    pub samples: Vec<f64>,
}

/// Piece k of `pieces` equal pieces of [t0, t1], its end t1 exactly for the last.
pub fn piece(t0: f64, t1: f64, k: usize, pieces: usize) -> (f64, f64) {
    let at = |j: usize| if j == pieces { t1 } else { t0 + (t1 - t0) * j as f64 / pieces as f64 };
    (at(k), at(k + 1))
}

/// Fraction theta in [0, 1] of the step at which node j of `nodes` lies.
pub fn node(j: usize, nodes: usize) -> f64 {
    if j == 0 {
        return 0.0;
    }
    if j + 1 == nodes {
        return 1.0;
    }
    0.5 * (1.0 - (std::f64::consts::PI * j as f64 / (nodes - 1) as f64).cos())
}

impl DenseOutput {
    /// An empty solution for m coordinates and interpolants of degree `degree`.
    pub fn new(m: usize, degree: usize) -> Self {
        DenseOutput { m, nodes: degree + 1, breaks: Vec::new(), t_end: f64::NAN, samples: Vec::new() }
    }

    /// Number of steps stored.
    pub fn steps(&self) -> usize {
        self.breaks.len().saturating_sub(1)
    }

    /// Time span [t_first, t_last] covered (s); `None` before the first step.
    pub fn span(&self) -> Option<(f64, f64)> {
        Some((*self.breaks.first()?, self.t_end)).filter(|_| self.steps() > 0)
    }

    /// Append the step [t0, t1] with its [q, qd] at the nodes (nodes x 2m, in node order).
    pub fn push(&mut self, t0: f64, t1: f64, samples: &[f64]) {
        debug_assert_eq!(samples.len(), self.nodes * 2 * self.m);
        if self.breaks.is_empty() {
            self.breaks.push(t0);
        }
        self.breaks.push(t1);
        self.t_end = t1;
        self.samples.extend_from_slice(samples);
    }

    /// End the solution at `t` (within the last step, as a terminal event does): the last
    /// step keeps its polynomial, over a shorter span.
    pub fn truncate(&mut self, t: f64) {
        self.t_end = self.t_end.min(t);
    }

    /// q and qd (m each) at time t, from step k's polynomial (t in or at the edge of it).
    fn eval_step(&self, k: usize, t: f64, q: &mut [f64], qd: &mut [f64]) {
        let (n, m) = (self.nodes, self.m);
        let t0 = self.breaks[k];
        let h = self.breaks[k + 1] - t0;
        let theta = if h > 0.0 { (t - t0) / h } else { 0.0 };
        let rows = &self.samples[k * n * 2 * m..(k + 1) * n * 2 * m];
        let (mut num, mut den) = (vec![0.0; 2 * m], 0.0);
        for j in 0..n {
            let d = theta - node(j, n);
            // Within a rounding unit of a node (theta is of order 1) the node's value is the
            // polynomial's to round-off; 1/d would overflow for a subnormal d (t = 5e-324).
            if d.abs() < f64::EPSILON {
                q.copy_from_slice(&rows[j * 2 * m..j * 2 * m + m]);
                qd.copy_from_slice(&rows[j * 2 * m + m..(j + 1) * 2 * m]);
                return;
            }
            // Barycentric weights of the Chebyshev-Lobatto nodes: (-1)^j, halved at the ends.
            let sign = if j % 2 == 0 { 1.0 } else { -1.0 };
            let w = if j == 0 || j + 1 == n { 0.5 * sign } else { sign } / d;
            den += w;
            for (acc, v) in num.iter_mut().zip(&rows[j * 2 * m..(j + 1) * 2 * m]) {
                *acc += w * v;
            }
        }
        q.iter_mut().zip(&num[..m]).for_each(|(o, v)| *o = v / den);
        qd.iter_mut().zip(&num[m..]).for_each(|(o, v)| *o = v / den);
    }

    /// q and qd (m each) at time t (s), which must lie within the run's span.
    pub fn eval(&self, t: f64, q: &mut [f64], qd: &mut [f64]) -> Result<(), String> {
        let Some((a, b)) = self.span() else {
            return Err("the run has no step: its dense output is empty".to_string());
        };
        if !(t >= a && t <= b) {
            return Err(format!(
                "t = {} s is outside the run [{}, {}] s: the dense output only covers the times integrated",
                Time(t),
                Time(a),
                Time(b)
            ));
        }
        // The step whose span holds t (the earlier one at a shared boundary: both agree there).
        let k = self.breaks[1..].partition_point(|&e| e < t).min(self.steps() - 1);
        self.eval_step(k, t, q, qd);
        Ok(())
    }
}
