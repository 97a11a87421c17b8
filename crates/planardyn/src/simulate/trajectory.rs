//! A simulation result: the trajectory computed (all of it, even when the run stopped early),
//! why it ended, and the figures that say how far to trust it.

use super::crossing::ChangePoint;
use super::dense::DenseOutput;
use super::events::EventRecords;
use super::ode::MechanismOde;
use crate::dynamics::{kinetic_energy, potential_energy};
use crate::integrate::Stats;
use crate::kinematics::Chart;

/// How a simulation ended.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Status {
    /// Reached t_end.
    #[default]
    Success,
    /// Position analysis failed even for the smallest step (the mechanism cannot move on).
    AssemblyFailed,
    /// The passive mechanism became singular (its constraints lost rank).
    PassiveSingularity,
    /// The step size underflowed (stiffness, or a discontinuity).
    StepSizeUnderflow,
    /// NaN or infinity appeared.
    NonFinite,
    /// A drive function failed or returned a non-finite effort.
    DriveFailed,
    /// The step budget was used up.
    TooManySteps,
    /// The steps became so small that the run could not reach t_end within its step budget
    /// (efforts too large for the model, or tolerances too tight): stopped early.
    StepSizeTooSmall,
    /// The progress callback asked to stop.
    Cancelled,
    /// A terminal event occurred: the run ends at its time.
    Event,
    /// An event function failed or returned a non-finite value.
    EventFailed,
}

impl Status {
    /// Short machine-readable name.
    pub fn name(self) -> &'static str {
        match self {
            Status::Success => "success",
            Status::AssemblyFailed => "assembly_failed",
            Status::PassiveSingularity => "passive_singularity",
            Status::StepSizeUnderflow => "step_size_underflow",
            Status::NonFinite => "non_finite",
            Status::DriveFailed => "drive_failed",
            Status::TooManySteps => "too_many_steps",
            Status::StepSizeTooSmall => "step_size_too_small",
            Status::Cancelled => "cancelled",
            Status::Event => "event",
            Status::EventFailed => "event_failed",
        }
    }
}

/// Counters and accuracy figures of a run.
#[derive(Debug, Clone, Default)]
pub struct SimStats {
    /// Integrator counters (evaluations, accepted and rejected steps, Jacobians, LUs).
    pub integrator: Stats,
    /// Changes between the user's coordinates and a partition, and between partitions.
    pub chart_switches: usize,
    /// Steps integrated in a partition chart (near type II singularities).
    pub partition_steps: usize,
    /// Steps integrated in an alternative chart of pair coordinates (`kinematics::alt_charts`).
    pub alt_steps: usize,
    /// Right-hand-side evaluations refused (Newton failed or would have changed branch); each
    /// made the integrator retry a shorter step.
    pub failed_evaluations: usize,
    /// Largest scaled loop-closure residual at the output points (lengths / L, angles in rad).
    pub max_residual: f64,
    /// Smallest type II measure seen at accepted steps (scaled singular value).
    pub min_sigma: f64,
    /// Smallest passive measure seen (see `charts::Measures::passive`) at the accepted steps
    /// and at the change points crossed (about 0 there: the path goes through them).
    pub min_passive_sigma: f64,
    /// Largest |E(t) - E(0)| at the outputs with E = T + V - W (J): energy balance error.
    pub energy_drift: f64,
}

/// Output arrays, time-major: row k belongs to `t[k]`. The columns, from `t` to `partitioned`,
/// are described (shape, unit, meaning) once, in [`super::columns::COLUMNS`], which the glues
/// and the Python package convert them by: a new one is a field here, a row there and a line
/// of [`Trajectory::record`].
#[derive(Debug, Clone, Default)]
pub struct Trajectory {
    /// Number of coordinates m and of body coordinates 3n (row lengths).
    pub m: usize,
    pub nx: usize,
    pub t: Vec<f64>,
    pub q: Vec<f64>,
    pub qd: Vec<f64>,
    pub qdd: Vec<f64>,
    pub tau: Vec<f64>,
    pub x: Vec<f64>,
    pub xd: Vec<f64>,
    pub kinetic: Vec<f64>,
    pub potential: Vec<f64>,
    pub work: Vec<f64>,
    pub sigma: Vec<f64>,
    pub residual: Vec<f64>,
    pub partitioned: Vec<bool>,
    /// The zeros of each event (see [`super::Observe`]): times and states.
    pub events: EventRecords,
    /// The continuous solution over the run, when asked for (see [`super::Observe`]).
    pub dense: Option<DenseOutput>,
    /// The change points crossed, in time order.
    pub change_points: Vec<ChangePoint>,
    pub status: Status,
    pub message: String,
    pub stats: SimStats,
}

impl Trajectory {
    pub fn new(m: usize, nx: usize) -> Self {
        Trajectory {
            m,
            nx,
            stats: SimStats { min_sigma: f64::INFINITY, min_passive_sigma: f64::INFINITY, ..Default::default() },
            ..Default::default()
        }
    }
    /// A trajectory with room for `rows` rows (a run's output grid): its columns grow once,
    /// not by doubling as rows come (20 k of the 3-RRR benchmark run's 1.57 M instructions).
    pub fn with_rows(m: usize, nx: usize, rows: usize) -> Self {
        let mut traj = Self::new(m, nx);
        for col in [&mut traj.q, &mut traj.qd, &mut traj.qdd, &mut traj.tau] {
            col.reserve_exact(rows * m);
        }
        for col in [&mut traj.x, &mut traj.xd] {
            col.reserve_exact(rows * nx);
        }
        for col in
            [&mut traj.t, &mut traj.kinetic, &mut traj.potential, &mut traj.work, &mut traj.sigma, &mut traj.residual]
        {
            col.reserve_exact(rows);
        }
        traj.partitioned.reserve_exact(rows);
        traj
    }
    pub fn len(&self) -> usize {
        self.t.len()
    }
    pub fn is_empty(&self) -> bool {
        self.t.is_empty()
    }
    /// Whether the run ended as asked: at t_end, or at a terminal event (as in `solve_ivp`).
    pub fn success(&self) -> bool {
        matches!(self.status, Status::Success | Status::Event)
    }
    /// Record the point analysed in `ode.ws` at time t with work W and type II measure sigma.
    pub fn record(&mut self, ode: &MechanismOde, t: f64, work: f64, sigma: f64) {
        let ws = &ode.ws;
        self.t.push(t);
        self.q.extend_from_slice(&ws.q);
        self.qd.extend_from_slice(&ws.qd);
        self.qdd.extend_from_slice(&ws.qdd);
        self.tau.extend_from_slice(&ws.tau);
        self.x.extend_from_slice(&ws.x);
        self.xd.extend_from_slice(&ws.xd);
        let (kin, pot) = (kinetic_energy(ode.mech, &ws.xd), potential_energy(ode.mech, &ws.x));
        self.kinetic.push(kin);
        self.potential.push(pot);
        self.work.push(work);
        self.sigma.push(sigma);
        self.residual.push(ws.residual);
        self.partitioned.push(ws.chart != Chart::Inputs);
        let e0 = self.kinetic[0] + self.potential[0] - self.work[0];
        self.stats.energy_drift = self.stats.energy_drift.max((kin + pot - work - e0).abs());
        self.stats.max_residual = self.stats.max_residual.max(ws.residual);
    }
}
