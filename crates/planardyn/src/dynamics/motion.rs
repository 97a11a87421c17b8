//! Prescribed motion: coordinates driven by a motion law q_p(t) instead of an effort. The
//! set [`Prescribed`] evaluates q_p, qd_p, qdd_p of the driven coordinates at a time; the
//! efforts they need come from `dynamics::prescribed`.

use crate::error::Time;
use crate::model::{Mechanism, MotionLaw};

/// A motion given by the caller as a function of time (a Python callable, a closed form).
pub trait MotionFunction {
    /// [q, qd, qdd] at time t (s): rad, rad/s, rad/s^2 for an angle; m, m/s, m/s^2 for a
    /// displacement.
    fn motion(&mut self, t: f64) -> Result<[f64; 3], String>;
}

/// The motion of one coordinate.
pub enum Motion<'a> {
    Law(MotionLaw),
    Function(&'a mut dyn MotionFunction),
}

/// The coordinates driven by motion in a run and their motions, with q_p, qd_p, qdd_p at
/// the last [`Prescribed::eval`].
pub struct Prescribed<'a> {
    names: Vec<String>,
    /// (m_p) Indices of the prescribed coordinates, ascending, and their motions.
    pub p: Vec<usize>,
    motions: Vec<Motion<'a>>,
    /// Start time (s) and start values (m_p) the `Speed` laws count from.
    t0: f64,
    start: Vec<f64>,
    /// (m_p) The motion at the last evaluation.
    pub q: Vec<f64>,
    pub qd: Vec<f64>,
    pub qdd: Vec<f64>,
    /// Numbers of coordinates m and of body coordinates 3n, and the buffers of
    /// `dynamics::prescribed` sized for them.
    m: usize,
    nx: usize,
    pub(crate) scratch: Scratch,
}

impl<'a> Prescribed<'a> {
    /// The motions the model file gives (`drives: [{coordinate, motion}]`).
    pub fn from_model(mech: &Mechanism) -> Prescribed<'a> {
        let mut set = Prescribed {
            names: mech.coordinate_names().iter().map(|s| s.to_string()).collect(),
            p: Vec::new(),
            motions: Vec::new(),
            t0: 0.0,
            start: Vec::new(),
            q: Vec::new(),
            qd: Vec::new(),
            qdd: Vec::new(),
            m: mech.dof(),
            nx: mech.n_x(),
            scratch: Scratch::default(),
        };
        for (k, law) in mech.motions.iter().enumerate() {
            if let Some(law) = law {
                // k < m: one law per coordinate.
                let _ = set.set(k, Motion::Law(law.clone()));
            }
        }
        set
    }

    /// Drive coordinate k (0-based, < m) by `motion`, replacing any motion it had.
    pub fn set(&mut self, k: usize, motion: Motion<'a>) -> Result<(), String> {
        if k >= self.m {
            return Err(format!("no coordinate {k}: the mechanism has {} ({})", self.m, self.names.join(", ")));
        }
        match self.p.binary_search(&k) {
            Ok(i) => self.motions[i] = motion,
            Err(i) => {
                self.p.insert(i, k);
                self.motions.insert(i, motion);
            }
        }
        let mp = self.p.len();
        for v in [&mut self.start, &mut self.q, &mut self.qd, &mut self.qdd] {
            v.resize(mp, 0.0);
        }
        self.scratch = Scratch::new(self.m, mp, self.nx);
        Ok(())
    }

    /// Number of prescribed coordinates m_p.
    pub fn len(&self) -> usize {
        self.p.len()
    }
    pub fn is_empty(&self) -> bool {
        self.p.is_empty()
    }

    /// Start the run at t0 (s) from coordinates q0 (m): the `Speed` laws count from there.
    /// A table must cover the run, [t0, t_end]; a message names the coordinate and the fix.
    pub fn start(&mut self, t0: f64, t_end: f64, q0: &[f64]) -> Result<(), String> {
        self.t0 = t0;
        for (i, (&k, motion)) in self.p.iter().zip(&self.motions).enumerate() {
            self.start[i] = q0[k];
            if let Motion::Law(MotionLaw::Table(s)) = motion {
                let (a, b) = s.span();
                if t0 < a || t_end > b {
                    return Err(format!(
                        "the motion table of '{}' covers t = {} to {} s but the run goes from {} to {} s: \
                         extend the table or shorten t_end",
                        self.names[k],
                        Time(a),
                        Time(b),
                        Time(t0),
                        Time(t_end)
                    ));
                }
            }
        }
        Ok(())
    }

    /// Evaluate every motion at time t (s) into `q`, `qd`, `qdd`.
    pub fn eval(&mut self, t: f64) -> Result<(), String> {
        for (i, motion) in self.motions.iter_mut().enumerate() {
            let v = match motion {
                Motion::Law(MotionLaw::Speed(w)) => [self.start[i] + *w * (t - self.t0), *w, 0.0],
                Motion::Law(MotionLaw::Table(s)) => s.eval(t),
                Motion::Function(f) => f.motion(t)?,
            };
            if let Some(d) = v.iter().position(|v| !v.is_finite()) {
                let what = ["position", "rate", "acceleration"][d];
                return Err(format!(
                    "the motion of '{}' gives a non-finite {what} {} at t = {} s",
                    self.names[self.p[i]],
                    v[d],
                    Time(t)
                ));
            }
            [self.q[i], self.qd[i], self.qdd[i]] = v;
        }
        Ok(())
    }

    /// Put the last evaluation's q_p and qd_p into a state [q, qd, ...] of the user's
    /// coordinates (m of each).
    pub fn overwrite(&self, m: usize, y: &mut [f64]) {
        for (i, &k) in self.p.iter().enumerate() {
            y[k] = self.q[i];
            y[m + k] = self.qd[i];
        }
    }
}

/// Buffers of `dynamics::prescribed::forward_prescribed`, held by the set ([`Prescribed`]) so
/// that a run allocates them once: sized for m coordinates, m_p of them prescribed, and 3n
/// body coordinates.
#[derive(Debug, Clone, Default)]
pub struct Scratch {
    /// (m_p x 3n) the prescribed coordinates' gradients D_p,x.
    pub(super) grad: Vec<f64>,
    /// (m_p x m) G = D_p,x U, then (m x m_p, column-major) A^-1 G^T.
    pub(super) g: Vec<f64>,
    pub(super) ainv_gt: Vec<f64>,
    /// (m_p x m_p) G A^-1 G^T and its factor; (m_p) the rows' h, and h - G A^-1 b, then tau_p;
    /// the same of a homogeneous solve (h = 0).
    pub(super) s: Vec<f64>,
    pub(super) h0: Vec<f64>,
    pub(super) h: Vec<f64>,
    pub(super) t: Vec<f64>,
}

impl Scratch {
    pub fn new(m: usize, mp: usize, nx: usize) -> Scratch {
        Scratch {
            grad: vec![0.0; mp * nx],
            g: vec![0.0; mp * m],
            ainv_gt: vec![0.0; m * mp],
            s: vec![0.0; mp * mp],
            h0: vec![0.0; mp],
            h: vec![0.0; mp],
            t: vec![0.0; mp],
        }
    }
}
