//! The exact Jacobian of the equations of motion y = [q, qd, W] (W the work of the
//! non-conservative forces) in the user's chart, for the implicit integrators:
//!
//!   d/dy [qd; qdd; P] = [[0, I, 0]; [dqdd/dq, dqdd/dqd, 0]; [dP/dq, dP/dqd, 0]],
//!
//! exact (`dynamics::derivatives`) at efforts depending on t alone.

use crate::dynamics::{motion_derivatives, Drives};
use crate::Workspace;
use crate::{Error, Mechanism};

/// Fill `jac` ((2m + 1)^2, row-major) at (t, y), Newton starting from `ws.x` (a copy of
/// `ws` is used: the integrator's evaluation state is left as it was).
pub(super) fn exact_jacobian(
    mech: &Mechanism,
    ws: &Workspace,
    drives: &mut dyn Drives,
    t: f64,
    y: &[f64],
    jac: &mut [f64],
) -> Result<(), Error> {
    let m = mech.dof();
    let n = 2 * m + 1;
    let (q, qd) = (&y[..m], &y[m..2 * m]);
    let mut tau = vec![0.0; m];
    drives.efforts(t, q, qd, &mut tau).map_err(|message| Error::Drive { t, message })?;
    let mut ws = ws.clone();
    let (_, d, power) = motion_derivatives(mech, q, qd, &tau, &mut ws)?;
    jac.fill(0.0);
    for i in 0..m {
        jac[i * n + m + i] = 1.0;
        for k in 0..m {
            jac[(m + i) * n + k] = d.dq[i * m + k];
            jac[(m + i) * n + m + k] = d.dqd[i * m + k];
        }
        jac[2 * m * n + i] = power.dq[i];
        jac[2 * m * n + m + i] = power.dqd[i];
    }
    Ok(())
}
