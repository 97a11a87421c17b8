//! A mechanism prepared for runs: the set-up a run derives from the immutable model alone,
//! made once per model and copied into each run. The model (`Mechanism`), the prepared model
//! and a run's own state stay separate, as Pinocchio's `Model` and `Data`: a run borrows the
//! prepared model, starts from copies of its templates and changes only those.
//!
//! What it keeps, each as the constructor a run called before made it:
//! - the evaluation buffers at the drawing in the user's chart ([`Workspace::new`]), with the
//!   structure of J analysed there (`System::new`: the block pattern of `BlockLu`, the groups'
//!   lengths and vectors of the type II estimate, the supports of U and of A);
//! - the same analysis for the type II measure of the user's chart while a partition is
//!   integrated (`MechanismOde::inputs_sys`);
//! - the analysis of the passive measure's partition (`System::other_chart`), made by the first
//!   run that asks for that measure and lent to the later ones ([`Prepared::passive_measure`]);
//! - the user's chart in closed form where every group has one ([`ClosedForm::new`], which
//!   makes the Assur decomposition), its branches those of the drawing;
//! - through the copies of these `System`s, the analyses of the charts their runs switched to
//!   (`System`'s shared list of analyses): a later run's switch copies them, as its own
//!   switches back do (the five-bar free fall's later run: 18.38 M -> 16.91 M instructions);
//!   each is the analysis the run would make itself, fresh (before any factorisation).
//!
//! A copy of a template is the value the constructor gives (none of them reads the clock, the
//! state or anything but the model), so a run from a prepared model is the run without one, to
//! the bit (`tests/prepared.rs`). The one difference is `System`'s analysis id, which the
//! copies share: it only tells whether buffers were zeroed for the same supports, and copies
//! of one analysis have the same supports.

use crate::kinematics::alt_charts::AltCharts;
use crate::kinematics::{
    partition_sigma_below_with, passive_sigma_below_with, passive_sigma_min_with, ClosedForm, System,
};
use crate::model::Mechanism;
use crate::{Error, Workspace};
use std::sync::{Arc, OnceLock};

/// The set-up of every run of one mechanism ([`crate::simulate::simulate_prepared`]).
#[derive(Debug, Clone)]
pub struct Prepared {
    /// The workspace a run starts from: buffers sized for the model, at its drawing, J's
    /// structure analysed for the user's chart.
    workspace: Workspace,
    /// The user's chart in closed form (None where a group has none).
    closed: Option<ClosedForm>,
    /// The first run's analysis of the partition of its first passive measure (a `System`
    /// analysed for it), empty until a run asks for that measure: a run that never does pays
    /// nothing, and the later runs do not analyse it again (88 k of the 3-RRR benchmark run's
    /// 1.57 M instructions). A run whose partition is another re-analyses it (`System::fill`).
    partition: OnceLock<System>,
    /// The alternative charts (`kinematics::alt_charts`), analysed by the first run that leaves
    /// the user's chart and shared with the later ones.
    alt: Arc<OnceLock<AltCharts>>,
}

impl Prepared {
    /// The set-up of `mech`'s runs.
    pub fn new(mech: &Mechanism) -> Self {
        Prepared {
            workspace: Workspace::new(mech),
            closed: ClosedForm::new(mech),
            partition: OnceLock::new(),
            alt: Default::default(),
        }
    }

    /// Err unless this was prepared from a mechanism of `mech`'s size and drawing: a run
    /// given another model's set-up would index past its buffers or take its geometry.
    pub fn check(&self, mech: &Mechanism) -> Result<(), Error> {
        let ws = &self.workspace;
        if ws.q.len() == mech.dof() && ws.x == mech.x0 {
            return Ok(());
        }
        Err(Error::Options(format!(
            "the prepared model ({} coordinates, {} body coordinates) was made from another mechanism than \
             '{}' ({} coordinates, {} body coordinates): prepare it from the mechanism it runs",
            ws.q.len(),
            ws.x.len(),
            mech.name,
            mech.dof(),
            mech.n_x()
        )))
    }

    /// A run's workspace: a copy of the template.
    pub fn workspace(&self) -> Workspace {
        self.workspace.clone()
    }

    /// A run's analysis of J in the user's chart, for its type II measure in a partition.
    pub fn inputs_system(&self) -> System {
        self.workspace.frame.sys.clone()
    }

    /// The passive measure at x ([`passive_sigma_min_with`]) with a run's `inputs_sys`: the
    /// partition's analysis comes from here when the run has none yet, and the first run's is
    /// kept here for the later ones. The same value as without (the analysis is that of
    /// `System::for_chart`, and a partition that differs is analysed again).
    pub fn passive_measure(&self, inputs_sys: &mut System, mech: &Mechanism, x: &[f64]) -> f64 {
        self.with_partition(inputs_sys, |sys| passive_sigma_min_with(sys, mech, x))
    }

    /// Whether [`Prepared::passive_measure`] at x is below `t` (> 0), the same answer without the
    /// blocks' SVDs where rounding cannot change it ([`passive_sigma_below_with`]).
    pub fn passive_below(&self, inputs_sys: &mut System, mech: &Mechanism, x: &[f64], t: f64) -> bool {
        self.with_partition(inputs_sys, |sys| passive_sigma_below_with(sys, mech, x, t))
    }

    /// Whether the partition's half of [`Prepared::passive_measure`] is below `t` (> 0)
    /// ([`partition_sigma_below_with`]): the type II measure of the partition `select_partition`
    /// chooses at x (infinite without constraints), not the user's chart's. Where the caller has
    /// the user's chart's measure already, the passive measure is the larger of the two.
    pub fn partition_below(&self, inputs_sys: &mut System, mech: &Mechanism, x: &[f64], t: f64) -> bool {
        self.with_partition(inputs_sys, |sys| partition_sigma_below_with(sys, mech, x, t))
    }

    /// `measure(inputs_sys)` with the partition's analysis lent from here when the run has none
    /// yet, and the first run's kept here for the later ones.
    fn with_partition<T>(&self, inputs_sys: &mut System, measure: impl FnOnce(&mut System) -> T) -> T {
        if let Some(kept) = self.partition.get() {
            inputs_sys.keep_other(|| kept.clone());
        }
        let value = measure(inputs_sys);
        if let (None, Some(other)) = (self.partition.get(), inputs_sys.other()) {
            // Another thread's run may have kept its own meanwhile: either serves.
            let _ = self.partition.set(other.clone());
        }
        value
    }

    /// The alternative charts, shared by the runs (analysed by the first that needs them).
    pub fn alt_charts(&self) -> Arc<OnceLock<AltCharts>> {
        self.alt.clone()
    }

    /// A run's closed forms of the user's chart, if every group has one.
    pub fn closed_form(&self) -> Option<ClosedForm> {
        self.closed.clone()
    }
}
