//! The start of a run: the mechanism assembled at q0 (coordinates driven by motion where
//! their motion starts), with its rates, in the chart it is integrated in first.

use super::charts::{chart_sigma, measure, next_chart, state_in, PASSIVE_SINGULAR};
use super::ode::MechanismOde;
use super::prepared::Prepared;
use super::Settings;
use crate::dynamics::{Drives, Prescribed};
use crate::kinematics::{assemble_into, velocity_analogues, Chart};
use crate::model::Mechanism;
use crate::{Error, KinematicsError, SingularityKind};

/// The start: assembled at q0, in the user's chart unless it is near-singular there.
/// Coordinates driven by motion start where their motion is at t0 (a `speed` counts from q0).
/// The buffers and what the run derives from the model alone are copies of `prepared`'s.
pub fn start<'a>(
    mech: &'a Mechanism,
    prepared: &Prepared,
    s: &Settings,
    drives: &'a mut dyn Drives,
    motion: &'a mut Prescribed<'a>,
) -> Result<(MechanismOde<'a>, Vec<f64>), Error> {
    let (q0m, qd0m) = mech.initial_state();
    let mut q0 = s.q0.clone().unwrap_or(q0m);
    let mut qd0 = s.qd0.clone().unwrap_or(qd0m);
    if !motion.is_empty() {
        motion.start(s.t0, s.t_end, &q0).map_err(Error::Options)?;
        motion.eval(s.t0).map_err(|message| Error::Drive { t: s.t0, message })?;
        for (i, &k) in motion.p.iter().enumerate() {
            (q0[k], qd0[k]) = (motion.q[i], motion.qd[i]);
        }
    }
    let mut ws = prepared.workspace();
    assemble_into(mech, &q0, &mut ws)?;
    // Body velocities from qd0 need U in the user's chart, i.e. a regular start; at rest a
    // singular start is fine (xd = 0).
    ws.xd.fill(0.0);
    if qd0.iter().any(|&v| v != 0.0) {
        velocity_analogues(&mut ws).map_err(|_| KinematicsError::singular(SingularityKind::TypeIIStartInMotion))?;
        for (j, r) in qd0.iter().enumerate() {
            let n = ws.x.len();
            for i in 0..n {
                ws.xd[i] += ws.u[j * n + i] * r;
            }
        }
    }
    ws.q.copy_from_slice(&q0);
    ws.qd.copy_from_slice(&qd0);
    let mut ode = MechanismOde::from_parts(
        mech,
        ws,
        drives,
        prepared.closed_form(),
        prepared.inputs_system(),
        prepared.alt_charts(),
    )
    .with_motion(motion);
    let m0 = measure(&mut ode);
    if m0.passive < PASSIVE_SINGULAR {
        return Err(
            KinematicsError::Singular { kind: SingularityKind::PassiveAtStart, sigma_min: Some(m0.passive) }.into()
        );
    }
    let (chart, known) = next_chart(&mut ode, &m0, m0.sigma).unwrap_or((Chart::Inputs, Some(m0.sigma)));
    let m = mech.dof();
    let mut y = vec![0.0; 2 * m + 1];
    state_in(&ode, &chart, 0.0, &mut y);
    ode.set_chart(chart, s.t0, &y)?;
    let own = known.unwrap_or_else(|| chart_sigma(&mut ode, m0.sigma));
    ode.limit_correction(own);
    ode.limit_step_reach();
    Ok((ode, y))
}
