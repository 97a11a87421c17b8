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
pub use crate::simulate::Overrides;
use crate::simulate::{simulate, Trajectory};
use crate::{Error, Mechanism, MechanismSpec};
use rayon::prelude::*;
use std::sync::Arc;


/// The model of a variant: a built mechanism (shared, not copied) or a specification that
/// is validated inside the task, so that building many edited models runs in parallel too.
#[derive(Debug, Clone)]
pub enum Model {
    Built(Arc<Mechanism>),
    Spec(MechanismSpec),
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
