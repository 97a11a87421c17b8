//! The linearised state-space model of the rigid mechanism about a state (q, qd) with efforts
//! tau (an equilibrium or a point of a trajectory), in scipy.signal's conventions
//! (`StateSpace(A, B, C, D)`, x' = A x + B u, y = C x + D u): states x = [dq; dqd] (2m),
//! inputs u = the efforts' increments (m), outputs y = the coordinates' increments and the
//! given points' displacements [dx, dy] (m). From the exact derivatives of forward dynamics
//! (`dynamics::forward_derivatives`): A = [[0, I], [dqdd/dq, dqdd/dqd]], B = [[0], [dqdd/dtau]],
//! the points' rows from the velocity analogues (dr_P/dq = S_P U).

use crate::dynamics::forward_derivatives;
use crate::kinematics::assemble_into;
use crate::model::pairs::frames::rotate;
use crate::model::BodyId;
use crate::model::Mechanism;
use crate::Error;
use crate::Workspace;

/// A, B, C, D row-major: A (2m x 2m), B (2m x m), C (p x 2m), D (p x m), p = m + 2 per point.
#[derive(Debug, Clone, PartialEq)]
pub struct StateSpace {
    pub a: Vec<f64>,
    pub b: Vec<f64>,
    pub c: Vec<f64>,
    pub d: Vec<f64>,
    pub n_outputs: usize,
}

/// The state-space model at (q, qd) with efforts tau held; `points` are (body, point in its
/// frame (m)) whose positions are outputs after the coordinates.
pub fn linearize(
    mech: &Mechanism,
    q: &[f64],
    qd: &[f64],
    tau: &[f64],
    points: &[(BodyId, [f64; 2])],
    ws: &mut Workspace,
) -> Result<StateSpace, Error> {
    let m = q.len();
    // By continuation from the drawing (the branch it is drawn in), then Newton from there.
    assemble_into(mech, q, ws)?;
    let (_, jac) = forward_derivatives(mech, q, qd, tau, ws)?;
    let n2 = 2 * m;
    let mut a = vec![0.0; n2 * n2];
    let mut b = vec![0.0; n2 * m];
    for i in 0..m {
        a[i * n2 + m + i] = 1.0;
        for k in 0..m {
            a[(m + i) * n2 + k] = jac.dq[i * m + k];
            a[(m + i) * n2 + m + k] = jac.dqd[i * m + k];
            b[(m + i) * m + k] = jac.dthird[i * m + k];
        }
    }
    let p = m + 2 * points.len();
    let mut c = vec![0.0; p * n2];
    for i in 0..m {
        c[i * n2 + i] = 1.0;
    }
    for (j, &(body, s)) in points.iter().enumerate() {
        let phi = ws.x[3 * body.0 + 2];
        let r = rotate(phi, s);
        for k in 0..m {
            let u = &ws.u_col(k)[3 * body.0..3 * body.0 + 3];
            c[(m + 2 * j) * n2 + k] = u[0] - r[1] * u[2];
            c[(m + 2 * j + 1) * n2 + k] = u[1] + r[0] * u[2];
        }
    }
    Ok(StateSpace { a, b, c, d: vec![0.0; p * m], n_outputs: p })
}
