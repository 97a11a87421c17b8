//! Batch runs: many variants of a mechanism (parameter sweeps, Monte Carlo over lengths,
//! masses, loads and start states) simulated in parallel on a rayon thread pool.
//!
//! A variant is a model plus its [`Overrides`] of the model's `simulate` defaults. The
//! [`Mechanism`] is immutable and `Send + Sync`, so variants may share one; every task makes
//! its own [`crate::Workspace`] inside [`simulate`](crate::simulate::simulate). Each variant
//! gets its own `Result`: a failing one (a start that cannot be assembled, invalid
//! settings, a spec that is not a mechanism) leaves the others untouched. The outputs are in
//! the order of the inputs and equal, bit for bit, those of a serial loop: a run does not
//! depend on which thread it lands on.

use crate::dynamics::ModelDrives;
use crate::integrate::Method;
use crate::simulate::{grid, simulate, Settings, Trajectory};
use crate::{Error, Mechanism, MechanismSpec};
use rayon::prelude::*;
use std::sync::Arc;

/// Most output times an `output_dt` may ask for (a guard against output_dt = 1e-12).
const MAX_OUTPUTS: f64 = 1e8;

/// The model of a variant: a built mechanism (shared, not copied) or a specification that
/// is validated inside the task, so that building many edited models runs in parallel too.
#[derive(Debug, Clone)]
pub enum Model {
    Built(Arc<Mechanism>),
    Spec(MechanismSpec),
}

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
}

impl Overrides {
    /// The settings of a run: the model's defaults ([`Settings::for_model`]) with these
    /// changes, as `Mechanism.simulate` in Python makes them.
    pub fn settings(&self, mech: &Mechanism) -> Result<Settings, Error> {
        let mut s = Settings::for_model(mech)?;
        if let Some(t_end) = self.t_end {
            if !(t_end.is_finite() && t_end > s.t0) {
                return Err(Error::Options(format!("t_end = {t_end} must be a finite time after t0 = {} s", s.t0)));
            }
            s.t_end = t_end;
        }
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
        s.t_eval = match (&self.t_eval, self.output_dt.or(mech.simulate.output_dt)) {
            (Some(te), _) => Some(te.clone()),
            (None, Some(h)) => Some(output_grid(s.t0, s.t_end, h)?),
            (None, None) => None,
        };
        s.q0 = self.q0.clone();
        s.qd0 = self.qd0.clone();
        Ok(s)
    }
}

/// Output times every h (s) from t0 to t_end, clamped to t_end without a duplicate end.
fn output_grid(t0: f64, t_end: f64, h: f64) -> Result<Vec<f64>, Error> {
    if !(h.is_finite() && h > 0.0) || (t_end - t0) / h > MAX_OUTPUTS {
        return Err(Error::Options(format!("output_dt = {h} must be > 0 s and give at most {MAX_OUTPUTS:e} outputs over [{t0}, {t_end}] s")));
    }
    let mut t = grid(t0, t_end, h);
    t.iter_mut().for_each(|v| *v = v.min(t_end));
    t.dedup();
    Ok(t)
}

/// One variant: its model and its settings.
#[derive(Debug, Clone)]
pub struct Variant {
    pub model: Model,
    pub overrides: Overrides,
}

impl Variant {
    /// Build (if needed), set up and simulate with the model's drives, in the caller's thread.
    pub fn simulate(&self) -> Result<Trajectory, Error> {
        let built;
        let mech: &Mechanism = match &self.model {
            Model::Built(m) => m,
            Model::Spec(spec) => {
                built = Mechanism::new(spec.clone(), "<variant>")?;
                &built
            }
        };
        let settings = self.overrides.settings(mech)?;
        simulate(mech, &settings, &mut ModelDrives(mech), None)
    }
}

/// Apply `f` to every item on a pool of `threads` threads (`None` or 0: one per core), the
/// results in input order. Fails only if the operating system refuses the threads.
pub fn map_many<T: Sync, R: Send>(items: &[T], threads: Option<usize>, f: impl Fn(&T) -> R + Sync + Send) -> Result<Vec<R>, Error> {
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads.unwrap_or(0))
        .thread_name(|i| format!("planardyn-batch-{i}"))
        .build()
        .map_err(|e| Error::Options(format!("cannot start the batch thread pool: {e}")))?;
    // One item a task: runs take from milliseconds to seconds, so work stealing balances
    // them better than fixed chunks.
    Ok(pool.install(|| items.par_iter().with_max_len(1).map(&f).collect()))
}

/// Simulate every variant in parallel on `threads` threads (`None`: all cores). The outer
/// `Err` only when no thread pool can be made; one `Result` per variant otherwise.
pub fn simulate_many(variants: &[Variant], threads: Option<usize>) -> Result<Vec<Result<Trajectory, Error>>, Error> {
    map_many(variants, threads, Variant::simulate)
}
