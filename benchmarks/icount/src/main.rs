// Instructions per forward-dynamics evaluation, the two cases of crates/planardyn/benches/
// forward_dynamics.rs, counted by callgrind (deterministic, unlike wall time on a shared
// machine): `icount MODEL N same|alt` makes N evaluations; run.sh subtracts N = 0.
// `icount MODEL N sigma` instead takes the type II measure from the closed forms N times.
use planardyn::dynamics::ModelDrives;
use planardyn::integrate::OdeSystem;
use planardyn::kinematics::{assemble_into, sigma_min, velocity_analogues, Chart, ClosedForm};
use planardyn::simulate::ode::MechanismOde;
use planardyn::Workspace;
use std::hint::black_box;

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let (path, n, alt): (&str, usize, bool) = (&args[1], args[2].parse().unwrap(), args[3] == "alt");
    let mech = planardyn::load(path).unwrap();
    let m = mech.dof();
    let (q0, qd0) = mech.initial_state();
    if args[3] == "sigma" {
        let mut closed = ClosedForm::new(&mech).unwrap();
        closed.kinematic_stages(&q0, &qd0, &mut Workspace::new(&mech)).unwrap();
        for _ in 0..n {
            black_box(black_box(&closed).sigma());
        }
        return;
    }
    let mut ws = Workspace::new(&mech);
    assemble_into(&mech, &q0, &mut ws).unwrap();
    velocity_analogues(&mut ws).unwrap();
    let mut drives = ModelDrives(&mech);
    let mut ode = MechanismOde::new(&mech, ws, &mut drives);
    let mut y0 = vec![0.0; 2 * m + 1];
    y0[..m].copy_from_slice(&q0);
    y0[m..2 * m].fill(1.0);
    ode.set_chart(Chart::Inputs, 0.0, &y0).unwrap();
    // As the integrator after its first accepted step: clear of folds, the closed forms apply.
    ode.limit_correction(sigma_min(&mech, &Chart::Inputs, ode.anchor_x()));
    let mut y = y0.clone();
    y[..m].iter_mut().for_each(|v| *v += 1e-3);
    let mut y2 = y.clone();
    y2[..m].iter_mut().for_each(|v| *v += 1e-3);
    let mut dy = vec![0.0; 2 * m + 1];
    ode.rhs(0.0, &y, &mut dy).unwrap();
    for k in 0..n {
        let yk = if alt && k % 2 == 1 { &y2 } else { &y };
        ode.rhs(0.0, black_box(yk), &mut dy).unwrap();
    }
    black_box(&dy);
}
