//! Motion laws of the coordinates a model drives by motion (`drives: [{coordinate, motion}]`):
//! a constant rate, or a cubic spline through a table with not-a-knot end conditions:
//! position, rate and acceleration continuous (C2), the jerk piecewise constant.
//!
//! Not-a-knot (the third derivative continuous across the second and the last-but-one
//! knots) assumes nothing at the ends: a natural spline would force zero acceleration there
//! and a clamped one needs end rates a table does not have (zero invents a stop), and either
//! puts the end efforts of a motion that does not start at rest far off. Not-a-knot
//! reproduces any cubic exactly, ends included. Two points give a line, three a parabola.
//! Written here (a tridiagonal solve for the knot slopes, then Hermite pieces) because the
//! Rust spline crates interpolate without not-a-knot ends or without the derivatives.

/// A motion law of one coordinate; times in s, q in rad or m.
#[derive(Debug, Clone, PartialEq)]
pub enum MotionLaw {
    /// Constant rate w (rad/s or m/s) from the start value: q = q(t0) + w (t - t0).
    Speed(f64),
    /// Through a table of times and positions ([`Spline`]).
    Table(Spline),
}

/// A C2 cubic through (t_i, q_i); t increasing strictly. Times in s, q in rad or m.
#[derive(Debug, Clone, PartialEq)]
pub struct Spline {
    t: Vec<f64>,
    q: Vec<f64>,
    /// (n) slopes dq/dt at the knots.
    s: Vec<f64>,
}

impl Spline {
    /// The spline through the table, or a message if it has fewer than 2 points, lengths
    /// differ, a value is not finite or the times do not increase strictly.
    pub fn new(t: &[f64], q: &[f64]) -> Result<Spline, String> {
        let n = t.len();
        if n < 2 || q.len() != n {
            return Err(format!(
                "a motion table needs at least 2 times and as many positions; got {n} and {}",
                q.len()
            ));
        }
        if let Some(k) = t.iter().chain(q).position(|v| !v.is_finite()) {
            return Err(format!("entry {} of the table is not finite", k % n));
        }
        if let Some(k) = (1..n).find(|&k| !(t[k] > t[k - 1])) {
            return Err(format!(
                "t[{k}] = {} does not come after t[{}] = {}: times must increase strictly",
                t[k],
                k - 1,
                t[k - 1]
            ));
        }
        Ok(Spline { s: slopes(t, q), t: t.to_vec(), q: q.to_vec() })
    }

    /// The time span [t_first, t_last] (s) the table covers.
    pub fn span(&self) -> (f64, f64) {
        (self.t[0], self.t[self.t.len() - 1])
    }

    /// [q, qd, qdd] at time t; outside the table the end pieces are extended.
    pub fn eval(&self, t: f64) -> [f64; 3] {
        let last = self.t.len() - 1;
        let k = self.t.partition_point(|&ti| ti <= t).clamp(1, last) - 1;
        let h = self.t[k + 1] - self.t[k];
        let d = (self.q[k + 1] - self.q[k]) / h;
        let (s0, s1) = (self.s[k], self.s[k + 1]);
        // q = q_k + s0 x + c2 x^2 + c3 x^3 with x = t - t_k (the Hermite cubic of the piece).
        let c2 = (3.0 * d - 2.0 * s0 - s1) / h;
        let c3 = (s0 + s1 - 2.0 * d) / (h * h);
        let x = t - self.t[k];
        [self.q[k] + x * (s0 + x * (c2 + x * c3)), s0 + x * (2.0 * c2 + 3.0 * x * c3), 2.0 * c2 + 6.0 * x * c3]
    }
}

/// Knot slopes of the not-a-knot cubic (de Boor, *A Practical Guide to Splines*, ch. IV):
/// a tridiagonal system, solved by elimination (it is diagonally dominant but for its first
/// and last rows, whose elimination divides by a positive pivot).
fn slopes(t: &[f64], q: &[f64]) -> Vec<f64> {
    let n = t.len();
    let h: Vec<f64> = t.windows(2).map(|w| w[1] - w[0]).collect();
    let d: Vec<f64> = (0..n - 1).map(|k| (q[k + 1] - q[k]) / h[k]).collect();
    if n == 2 {
        return vec![d[0]; 2];
    }
    if n == 3 {
        // The parabola through the three points.
        let c = (d[1] - d[0]) / (h[0] + h[1]);
        return (0..3).map(|k| d[0] + c * (2.0 * t[k] - t[0] - t[1])).collect();
    }
    // Rows: sub[k] s[k-1] + diag[k] s[k] + sup[k] s[k+1] = r[k].
    let (mut sub, mut diag, mut sup, mut r) = (vec![0.0; n], vec![0.0; n], vec![0.0; n], vec![0.0; n]);
    diag[0] = h[1];
    sup[0] = h[0] + h[1];
    r[0] = ((h[0] + 2.0 * sup[0]) * h[1] * d[0] + h[0] * h[0] * d[1]) / sup[0];
    for k in 1..n - 1 {
        sub[k] = h[k];
        diag[k] = 2.0 * (h[k - 1] + h[k]);
        sup[k] = h[k - 1];
        r[k] = 3.0 * (h[k] * d[k - 1] + h[k - 1] * d[k]);
    }
    let (a, b) = (h[n - 3], h[n - 2]);
    sub[n - 1] = a + b;
    diag[n - 1] = a;
    r[n - 1] = (b * b * d[n - 3] + (2.0 * (a + b) + b) * a * d[n - 2]) / (a + b);
    for k in 1..n {
        let w = sub[k] / diag[k - 1];
        diag[k] -= w * sup[k - 1];
        r[k] -= w * r[k - 1];
    }
    let mut s = vec![0.0; n];
    s[n - 1] = r[n - 1] / diag[n - 1];
    for k in (0..n - 1).rev() {
        s[k] = (r[k] - sup[k] * s[k + 1]) / diag[k];
    }
    s
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A cubic is reproduced to round-off on an uneven grid, ends included.
    #[test]
    fn reproduces_a_cubic() {
        let f = |t: f64| [2.0 - t + 0.5 * t * t - 0.3 * t.powi(3), -1.0 + t - 0.9 * t * t, 1.0 - 1.8 * t];
        let t = [0.0, 0.3, 0.45, 1.0, 1.2, 2.0];
        let q: Vec<f64> = t.iter().map(|&t| f(t)[0]).collect();
        let s = Spline::new(&t, &q).unwrap();
        for k in 0..=40 {
            let tk = 2.0 * k as f64 / 40.0;
            let (got, want) = (s.eval(tk), f(tk));
            for i in 0..3 {
                assert!((got[i] - want[i]).abs() < 1e-12, "t = {tk}, derivative {i}: {} vs {}", got[i], want[i]);
            }
        }
    }

    /// Three points give their parabola, two their line.
    #[test]
    fn short_tables() {
        let s = Spline::new(&[0.0, 1.0, 3.0], &[0.0, 1.0, 9.0]).unwrap();
        let [q, qd, qdd] = s.eval(2.0);
        assert!((q - 4.0).abs() < 1e-14 && (qd - 4.0).abs() < 1e-14 && (qdd - 2.0).abs() < 1e-14);
        let s = Spline::new(&[1.0, 2.0], &[1.0, 3.0]).unwrap();
        assert_eq!(s.eval(1.5), [2.0, 2.0, 0.0]);
    }

    #[test]
    fn rejects_bad_tables() {
        assert!(Spline::new(&[0.0], &[0.0]).is_err());
        assert!(Spline::new(&[0.0, 1.0], &[0.0]).is_err());
        assert!(Spline::new(&[0.0, 0.0, 1.0], &[0.0, 1.0, 2.0]).unwrap_err().contains("t[1]"));
        assert!(Spline::new(&[0.0, 1.0], &[0.0, f64::NAN]).is_err());
    }
}
