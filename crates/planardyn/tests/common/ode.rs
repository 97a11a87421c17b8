//! A model's ODE as the integrator holds it after its first accepted step: the drawing
//! assembled, every coordinate rate 1, the user's chart, clear of folds (so the closed forms
//! apply). One setup for the closed-form tests, the criterion bench (`benches/
//! forward_dynamics.rs`) and the instruction counts (`benchmarks/icount`), which include this
//! file by path.

use planardyn::dynamics::Drives;
use planardyn::kinematics::{assemble_into, sigma_min, velocity_analogues, Chart};
use planardyn::simulate::ode::MechanismOde;
use planardyn::{Mechanism, Workspace};

/// The ODE and its state y = [q of the drawing, 1, ..., 1, 0].
pub fn at_drawing<'a>(mech: &'a Mechanism, drives: &'a mut dyn Drives) -> (MechanismOde<'a>, Vec<f64>) {
    let m = mech.dof();
    let (q0, _) = mech.initial_state();
    let mut ws = Workspace::new(mech);
    assemble_into(mech, &q0, &mut ws).unwrap();
    velocity_analogues(&mut ws).unwrap();
    let mut ode = MechanismOde::new(mech, ws, drives);
    let mut y = vec![0.0; 2 * m + 1];
    y[..m].copy_from_slice(&q0);
    y[m..2 * m].fill(1.0);
    ode.set_chart(Chart::Inputs, 0.0, &y).unwrap();
    ode.limit_correction(sigma_min(mech, &Chart::Inputs, ode.anchor_x()));
    (ode, y)
}
