//! Why a run stopped, with the data its message needs: every stage of [`super::run::Run`]
//! returns `ControlFlow<Stop>`, and this file alone turns a [`Stop`] into the trajectory's
//! [`Status`] and message.

use super::charts::NEAR_PASSIVE_SINGULAR;
use super::trajectory::Status;
use crate::error::Time;
use crate::integrate::StepError;
use crate::kinematics::effector::IK_CONTINUATION_STEP;
use crate::Error;

/// Why a run stopped. Times in s.
#[derive(Debug)]
pub enum Stop {
    /// t_end was reached (also inside a change point's crossing).
    Reached { t_end: f64 },
    /// A drive failed at the start.
    StartDrive(Error),
    /// A step could not be completed, even with the smallest step size; `crossing` says why
    /// no change point could be crossed from the last accepted point, when one was near.
    Step { error: StepError<Error>, crossing: Option<String> },
    /// An event function failed at the start.
    EventAtStart { t: f64, error: String },
    /// The dense output of the step to t could not be evaluated.
    DenseOutput { t: f64, error: Error },
    /// An event function failed in the step to t.
    EventInStep { t: f64, error: String },
    /// The output at t could not be evaluated.
    Output { t: f64, error: Error },
    /// Terminal event `index` occurred at t.
    TerminalEvent { index: usize, t: f64 },
    /// The state at terminal event `index` (time t) could not be evaluated.
    EventState { index: usize, t: f64, error: Error },
    /// The end of the step at t could not be made the predictor's anchor.
    Accept { t: f64, error: Error },
    /// A change point ahead of the point at t (passive measure `passive`) could not be crossed.
    NoCrossing { t: f64, passive: f64, why: String },
    /// The passive mechanism is singular at t.
    PassiveSingular { t: f64, passive: f64 },
    /// The run cannot reach t_end at its rate of progress (see `Run::progress_rate`): at t,
    /// after `attempts` steps of mean `mean` (last `last`), below `floor`.
    Hopeless { t: f64, attempts: usize, mean: f64, last: f64, floor: f64, t_end: f64, max_steps: usize },
    /// The prescribed motion runs into a fold of its driven coordinates: at t their measure is
    /// `driven`, and its square, linear in t, reaches 0 at `t_star` (see `run::FoldWatch`).
    Fold { t: f64, t_star: f64, driven: f64 },
    /// Changing the chart at t failed.
    ChartChange { t: f64, error: String },
    /// The progress callback asked to stop at t.
    Cancelled { t: f64 },
}

/// The passive and the prescribed coordinates' measures at the last accepted point, for a
/// failure's message (`passive_sigma_min`, `prescribed_sigma_min`).
pub struct Near {
    pub passive: f64,
    pub driven: f64,
    /// How far the mechanism moves at its rates there (body rates, translations per the
    /// characteristic length L: [`super::crossing::scaled_speed`]) in the integrator's smallest
    /// step (`Options::h_min`), and that step (s); `start`: no step was accepted.
    pub reach: f64,
    pub h_min: f64,
    pub start: bool,
    /// The fold of the driven coordinates the run was running into, if their measure fell
    /// towards one within its last steps (`FoldWatch::ahead`).
    pub fold: Option<f64>,
}

impl Stop {
    /// Whether the last accepted state is kept as the final row when the outputs did not
    /// reach it: the run stopped between two of its accepted steps.
    pub fn keeps_last(&self) -> bool {
        matches!(
            self,
            Stop::Step { .. }
                | Stop::DenseOutput { .. }
                | Stop::EventInStep { .. }
                | Stop::Hopeless { .. }
                | Stop::Fold { .. }
                | Stop::Cancelled { .. }
        )
    }

    /// The trajectory's status and message. A failure that usually means a change point (steps
    /// that shrink to nothing, a position that does not assemble) asks `near` for the measures
    /// at the last accepted point and says when one of them is near-singular.
    /// A run that ran out of steps or progress (`stalled`) gets the driven coordinates'
    /// diagnosis only: its passive measure does not explain small steps.
    pub fn describe(self, near: impl FnOnce() -> Near) -> (Status, String) {
        let stalled = self.stalled_at();
        let (status, message) = self.status_message();
        let failed = matches!(status, Status::StepSizeUnderflow | Status::AssemblyFailed | Status::NonFinite);
        if !failed && stalled.is_none() {
            return (status, message);
        }
        let Near { passive, driven, reach, h_min, start, fold } = near();
        if let Some(t) = stalled {
            if driven >= NEAR_PASSIVE_SINGULAR {
                return (status, message);
            }
            let message = format!(
                "{message}. The prescribed motion runs into a singularity of its driven coordinates at t = {} s \
                 (scaled measure {driven:.2e}): there they stop determining the mechanism, its steps shrink \
                 towards that time, and past it the mechanism may not assemble at the prescribed coordinates. \
                 {CHANGE_THE_MOTION}",
                Time(t)
            );
            return (status, message);
        }
        if passive < NEAR_PASSIVE_SINGULAR {
            let message = format!(
                "{message}; the passive mechanism is near-singular there (scaled measure {passive:.2e}): \
                 a change point where its motion is not determined"
            );
            (Status::PassiveSingularity, message)
        } else if driven < NEAR_PASSIVE_SINGULAR {
            let message = format!(
                "{message}; the coordinates driven by motion are near a singularity of their own there (scaled \
                 measure {driven:.2e}): they stop determining their part of the mechanism, and the efforts their \
                 motion needs grow without bound. Change the motion so that it avoids this configuration"
            );
            (status, message)
        } else if let Some(t_star) = fold {
            // The fold first: the failure (a position that does not assemble, friction efforts
            // that do not settle under a near-singular J) is its symptom.
            let message = format!(
                "the prescribed motion runs into a fold of its driven coordinates at t ≈ {} s: their scaled \
                 measure ({driven:.2e} at the last accepted point) falls like the square root of the time left to \
                 it, and past it the mechanism does not assemble at the prescribed coordinates. \
                 {CHANGE_THE_MOTION}. Near it the step failed, a symptom of the fold: {message}",
                Time(t_star)
            );
            (status, message)
        } else if reach > MAX_REACH {
            // The rates, not the positions or the tolerances: the failure is their symptom
            // (the advice of a failed position analysis is for positions). After the
            // singularities' diagnoses: near a fold the rates grow too, as its symptom.
            let (what, fix) = if start {
                ("the start rates qd0 are", "give smaller start rates (qd0)")
            } else {
                ("the rates are", "lower the efforts or start rates (qd0) that drive them there")
            };
            let message = format!(
                "{what} too large to integrate: the mechanism moves {reach:.2e} rad (or lengths per L) in the \
                 integrator's smallest step ({h_min:.0e} s), more than its position analysis follows in a step \
                 ({MAX_REACH}); {fix}. The step failed with: {message}"
            );
            (status, message)
        } else {
            (status, message)
        }
    }

    /// Where a run stopped that ran out of steps or of progress.
    fn stalled_at(&self) -> Option<f64> {
        match self {
            Stop::Step { error: StepError::TooManySteps { t, .. }, .. } | Stop::Hopeless { t, .. } => Some(*t),
            _ => None,
        }
    }

    /// Status and message, before the diagnosis of [`Stop::describe`].
    fn status_message(self) -> (Status, String) {
        match self {
            Stop::Reached { t_end } => (Status::Success, format!("reached t_end = {} s", Time(t_end))),
            Stop::StartDrive(e) => (Status::DriveFailed, e.to_string()),
            Stop::Step { error, crossing } => {
                let (status, message) = step_failure(&error);
                match crossing {
                    Some(why) => (status, format!("{message}; {why}")),
                    None => (status, message),
                }
            }
            Stop::EventAtStart { t, error } => (Status::EventFailed, format!("at t = {} s: {error}", Time(t))),
            Stop::DenseOutput { t, error } => {
                let kind =
                    if matches!(error, Error::Drive { .. }) { Status::DriveFailed } else { Status::AssemblyFailed };
                (kind, format!("dense output of the step to t = {} s: {error}", Time(t)))
            }
            Stop::EventInStep { t, error } => {
                (Status::EventFailed, format!("in the step to t = {} s: {error}", Time(t)))
            }
            Stop::Output { t, error } => (Status::AssemblyFailed, format!("output at t = {}: {error}", Time(t))),
            Stop::TerminalEvent { index, t } => (Status::Event, format!("terminal event {index} at t = {} s", Time(t))),
            Stop::EventState { index, t, error } => {
                (Status::AssemblyFailed, format!("the state at terminal event {index}, t = {} s: {error}", Time(t)))
            }
            Stop::Accept { t, error } => (Status::AssemblyFailed, format!("at t = {}: {error}", Time(t))),
            Stop::NoCrossing { t, passive, why } => (
                Status::PassiveSingularity,
                format!(
                    "the passive mechanism is singular at t = {} s (scaled measure {passive:.2e}) and {why}",
                    Time(t)
                ),
            ),
            Stop::PassiveSingular { t, passive } => (
                Status::PassiveSingularity,
                format!(
                    "the passive mechanism is singular at t = {} s (scaled measure {passive:.2e}): its pair \
                     constraints lose rank and the motion is not determined beyond",
                    Time(t)
                ),
            ),
            Stop::Hopeless { t, attempts, mean, last, floor, t_end, max_steps } => (
                Status::StepSizeTooSmall,
                format!(
                    "step size too small at t = {} s: after {attempts} steps the mean step is {mean:.2e} s \
                     (last {last:.2e} s), below (t_end - t0) / ({PROGRESS_MARGIN} max_steps) = {floor:.2e} s, so \
                     the run cannot make progress to t_end = {} s within max_steps = {max_steps}. The efforts \
                     or rates are too large for the model or the tolerances too tight: lower the efforts or the \
                     start rates (qd0), loosen rtol/atol, shorten t_end, or raise max_steps",
                    Time(t),
                    Time(t_end)
                ),
            ),
            Stop::Fold { t, t_star, driven } => (
                Status::StepSizeTooSmall,
                format!(
                    "step size too small at t = {} s: the coordinates driven by motion are near a singularity of \
                     their own (scaled measure {driven:.2e}), a fold that the prescribed motion runs into at \
                     t ≈ {} s. Their measure falls like the square root of the time left to it, the steps shrink \
                     towards that time without passing it, and past it the mechanism does not assemble at the \
                     prescribed coordinates. {CHANGE_THE_MOTION}",
                    Time(t),
                    Time(t_star)
                ),
            ),
            Stop::ChartChange { t, error } => {
                (Status::AssemblyFailed, format!("changing coordinates at t = {} s: {error}", Time(t)))
            }
            Stop::Cancelled { t } => {
                (Status::Cancelled, format!("cancelled at t = {} s: the progress callback asked to stop", Time(t)))
            }
        }
    }
}

/// The most the mechanism may move (rad, or lengths per L) in the integrator's smallest step
/// for a failed step to be blamed on anything but its rates: the core's continuation step,
/// the farthest its position analysis is taken at once. Past it, the start rates 1e20 rad/s
/// of the four-bar's and the five-bar's runs failed their position analysis, with advice for
/// positions.
const MAX_REACH: f64 = IK_CONTINUATION_STEP;

/// A run whose mean step so far would need this many times its step budget to reach t_end
/// is stopped: it cannot finish, and waiting for the budget costs this many times more work.
pub const PROGRESS_MARGIN: f64 = 10.0;

/// What a prescribed motion that runs into its driven coordinates' singularity should change.
const CHANGE_THE_MOTION: &str =
    "Change the motion so that it avoids this configuration, or end the run before it (t_end)";

/// Status and message for a failed step.
fn step_failure(e: &StepError<Error>) -> (Status, String) {
    let status = match e {
        StepError::StepSizeUnderflow { .. } => Status::StepSizeUnderflow,
        StepError::NonFinite { .. } => Status::NonFinite,
        StepError::TooManySteps { .. } => Status::TooManySteps,
        StepError::Rhs { error: Error::Drive { .. }, .. } => Status::DriveFailed,
        StepError::Rhs { .. } => Status::AssemblyFailed,
    };
    let message = match e {
        StepError::Rhs { t, error } => format!("at t = {} s, even with the smallest step: {error}", Time(*t)),
        other => other.to_string(),
    };
    (status, message)
}
