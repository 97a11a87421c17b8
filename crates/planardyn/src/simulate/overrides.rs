//! A caller's changes to a model file's `simulate` defaults, applied the same way by the
//! Python `Mechanism.simulate`, the batch runner and Rust users.

use super::{check, grid, Settings};
use crate::dynamics::{Motion, Prescribed};
use crate::error::Setting;
use crate::integrate::Method;
use crate::model::{Mechanism, MotionLaw};
use crate::Error;

/// Changes to the model file's `simulate` defaults (`None`: the model's value). Times in s,
/// coordinates in rad or m, rates in rad/s or m/s.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Overrides {
    pub t_end: Option<f64>,
    pub method: Option<String>,
    pub rtol: Option<f64>,
    pub atol: Option<f64>,
    /// Fixed step (s); an adaptive `method` given without it drops the file's `dt`.
    pub dt: Option<f64>,
    pub t_eval: Option<Vec<f64>>,
    pub output_dt: Option<f64>,
    pub q0: Option<Vec<f64>>,
    pub qd0: Option<Vec<f64>>,
    pub max_steps: Option<usize>,
    /// Coordinates driven by motion (index, law), replacing the model file's motion of that
    /// coordinate if it has one.
    pub motion: Vec<(usize, MotionLaw)>,
}

impl Overrides {
    /// The settings of a run: the model's defaults ([`Settings::for_model`]) with these
    /// changes, as `Mechanism.simulate` in Python makes them.
    pub fn settings(&self, mech: &Mechanism) -> Result<Settings, Error> {
        let mut s = Settings::without_outputs(mech)?;
        s.t_end = self.t_end.unwrap_or(s.t_end);
        if let Some(name) = &self.method {
            s.method = name.parse::<Method>().map_err(Error::Options)?;
            if s.method.is_adaptive() && self.dt.is_none() {
                s.options.dt = None;
            }
        }
        s.options.rtol = self.rtol.unwrap_or(s.options.rtol);
        s.options.atol = self.atol.unwrap_or(s.options.atol);
        s.options.dt = self.dt.or(s.options.dt);
        s.options.max_steps = self.max_steps.unwrap_or(s.options.max_steps);
        s.t_eval = self.t_eval.clone();
        s.q0 = self.q0.clone();
        s.qd0 = self.qd0.clone();
        // The settings' one check (as `simulate` makes it), before t_end is used for the grid.
        check(&s, mech)?;
        if let (None, Some(h)) = (&s.t_eval, self.output_dt.or(mech.simulate.output_dt)) {
            s.t_eval = Some(output_grid(s.t0, s.t_end, h)?);
        }
        Ok(s)
    }

    /// The motions of a run: the model file's, with [`Overrides::motion`] replacing them.
    pub fn prescribed<'a>(&self, mech: &Mechanism) -> Result<Prescribed<'a>, Error> {
        let mut p = Prescribed::from_model(mech);
        for (k, law) in &self.motion {
            p.set(*k, Motion::Law(law.clone())).map_err(Error::Options)?;
        }
        Ok(p)
    }
}

/// Output times every h (s) from t0 to t_end, clamped to t_end without a duplicate end.
pub(super) fn output_grid(t0: f64, t_end: f64, h: f64) -> Result<Vec<f64>, Error> {
    Setting::check_outputs(t0, t_end, h)?;
    let mut t = grid(t0, t_end, h);
    t.iter_mut().for_each(|v| *v = v.min(t_end));
    t.dedup();
    Ok(t)
}
