//! The linearised state-space model of the rigid mechanism about a state (q, qd) with efforts
//! tau (an equilibrium or a point of a trajectory), in scipy.signal's conventions
//! (`StateSpace(A, B, C, D)`, x' = A x + B u, y = C x + D u): states x = [dq; dqd] (2m),
//! inputs u = the efforts' increments (m), outputs y = the coordinates' increments and the
//! given points' displacements [dx, dy] (m). From the exact derivatives of forward dynamics
//! (`dynamics::forward_derivatives`): A = [[0, I], [dqdd/dq, dqdd/dqd]], B = [[0], [dqdd/dtau]],
//! the points' rows from the velocity analogues (dr_P/dq = S_P U).
//!
//! The same for the compliant mechanism (`linearize_compliant`): the flexible-joint model in
//! the redundant coordinates of `elastic::model`, about a pose as its equilibrium.

use super::model::Output;
use super::modes::{condensation, mass_and_damping};
use super::stiffness::{elastic_at, loaded_stiffness, null_basis, Applied};
use crate::dynamics::forward_derivatives;
use crate::kinematics::assemble_into;
use crate::model::pairs::frames::rotate;
use crate::model::BodyId;
use crate::model::Mechanism;
use crate::Workspace;
use crate::{Error, KinematicsError};
use nalgebra::DMatrix;

/// A, B, C, D row-major: A (n_states x n_states), B (n_states x n_inputs), C (n_outputs x
/// n_states), D (n_outputs x n_inputs); n_outputs = m + 2 per point.
#[derive(Debug, Clone, PartialEq)]
pub struct StateSpace {
    pub a: Vec<f64>,
    pub b: Vec<f64>,
    pub c: Vec<f64>,
    pub d: Vec<f64>,
    pub n_states: usize,
    pub n_inputs: usize,
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
    Ok(StateSpace { a, b, c, d: vec![0.0; p * m], n_states: n2, n_inputs: m, n_outputs: p })
}

/// The linearised state-space model of the compliant mechanism with every elastic drive's
/// rotor free (the flexible-joint model) about coordinates q taken as its equilibrium (under
/// the model's gravity with `gravity`, the motors holding it with constant torques), in
/// scipy.signal's conventions. States x = [xi; xi'] (2h): xi the mass-whitened coordinates
/// of its h massive free motions (z = z0 + N T xi, T^T N^T M N T = I; the massless ones, a
/// slender link's tip, follow statically); inputs u the motor torques t_m (motor side, N m or
/// N) of the elastic drives with a rotor, each a force n t_m on its rotor; outputs y the
/// coordinates' increments (m, measured at their pairs) then each point's [dx, dy]. With
/// K_c = T^T N^T K N T and D_c likewise: A = [[0, I], [-K_c, -D_c]], B = [[0], [T^T N^T F_u]],
/// C = [[G N T, 0]] (G the outputs' gradients), D = 0 (the motor torques act on massive
/// rotors, so no input reaches a massless direction).
pub fn linearize_compliant(
    mech: &Mechanism,
    q: &[f64],
    gravity: bool,
    points: &[Output],
    ws: &mut Workspace,
) -> Result<StateSpace, KinematicsError> {
    let model = elastic_at(mech, q, true, ws)?;
    let rotors = model.rotors();
    if rotors.is_empty() {
        return Err(KinematicsError::BadArgument {
            name: "mechanism",
            expected: "an elastic drive with a rotor (`actuators`: `rotor_inertia` > 0): its motor torque is the input"
                .into(),
            got: "no elastic drive with a rotor".into(),
        });
    }
    let z = model.z0.clone();
    let n = null_basis(&model.rigid_rows(&z).1, &model.col_scale);
    let k = loaded_stiffness(&model, &z, Applied::gravity(gravity), &[], &n)?;
    let (m, d) = mass_and_damping(&model, &z, &n);
    let t = condensation(&k, &m);
    let nt = &n * &t;
    let (kc, dc) = (t.transpose() * k * &t, t.transpose() * d * &t);
    let h = t.ncols();
    let mut fu = DMatrix::zeros(model.n_cols(), rotors.len());
    for (j, &(c, a)) in rotors.iter().enumerate() {
        fu[(c, j)] = mech.actuators.get(a).and_then(Option::as_ref).map_or(1.0, |act| act.ratio);
    }
    let bu = nt.transpose() * fu;
    let mut g = DMatrix::zeros(mech.dof() + 2 * points.len(), model.n_cols());
    for k in 0..mech.dof() {
        g.row_mut(k).copy_from_slice(&model.coordinate_gradient(k, &z));
    }
    for (j, &p) in points.iter().enumerate() {
        let s = model.output(p, &z).1;
        g.rows_mut(mech.dof() + 2 * j, 2).copy_from(&s.rows(0, 2));
    }
    let cx = g * &nt;
    let (n2, nu, p) = (2 * h, rotors.len(), cx.nrows());
    let mut a = DMatrix::zeros(n2, n2);
    a.view_mut((0, h), (h, h)).fill_with_identity();
    a.view_mut((h, 0), (h, h)).copy_from(&(-kc));
    a.view_mut((h, h), (h, h)).copy_from(&(-dc));
    let mut b = DMatrix::zeros(n2, nu);
    b.view_mut((h, 0), (h, nu)).copy_from(&bu);
    let mut c = DMatrix::zeros(p, n2);
    c.view_mut((0, 0), (p, h)).copy_from(&cx);
    let row_major = |m: DMatrix<f64>| m.transpose().iter().copied().collect::<Vec<f64>>();
    Ok(StateSpace {
        a: row_major(a),
        b: row_major(b),
        c: row_major(c),
        d: vec![0.0; p * nu],
        n_states: n2,
        n_inputs: nu,
        n_outputs: p,
    })
}
