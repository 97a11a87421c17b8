// Instructions per forward-dynamics evaluation, the two cases of crates/planardyn/benches/
// forward_dynamics.rs, counted by callgrind (deterministic, unlike wall time on a shared
// machine): `icount MODEL N same|alt` makes N evaluations; run.sh subtracts N = 0.
// `icount MODEL N sigma` instead takes the type II measure from the closed forms N times;
// `icount four-bar-gravity.yaml N limit-same|limit-alt` makes N evaluations of the hand-coded
// closed-form four-bar (four_bar_limit.rs) at the same states, checked against planardyn's.
use planardyn::dynamics::ModelDrives;
use planardyn::integrate::OdeSystem;
use planardyn::kinematics::ClosedForm;
use planardyn::Workspace;
use std::hint::black_box;

mod four_bar_limit;
#[path = "../../../crates/planardyn/tests/common/ode.rs"]
mod ode;

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let (path, n, case): (&str, usize, &str) = (&args[1], args[2].parse().unwrap(), &args[3]);
    let alt = case.ends_with("alt");
    let mech = planardyn::load(path).unwrap();
    let m = mech.dof();
    let (q0, qd0) = mech.initial_state();
    if case == "sigma" {
        let mut closed = ClosedForm::new(&mech).unwrap();
        closed.kinematic_stages(&q0, &qd0, &mut Workspace::new(&mech)).unwrap();
        for _ in 0..n {
            black_box(black_box(&closed).sigma());
        }
        return;
    }
    let mut drives = ModelDrives(&mech);
    let (mut ode, y0) = ode::at_drawing(&mech, &mut drives);
    let mut y = y0.clone();
    y[..m].iter_mut().for_each(|v| *v += 1e-3);
    let mut y2 = y.clone();
    y2[..m].iter_mut().for_each(|v| *v += 1e-3);
    let mut dy = vec![0.0; 2 * m + 1];
    ode.rhs(0.0, &y, &mut dy).unwrap();
    if case.starts_with("limit") {
        let limit = four_bar_limit::FourBar::new();
        four_bar_limit::check(&limit, &y, &dy);
        ode.rhs(0.0, &y2, &mut dy).unwrap();
        four_bar_limit::check(&limit, &y2, &dy);
        for k in 0..n {
            let yk = if alt && k % 2 == 1 { &y2 } else { &y };
            black_box(&limit).rhs(black_box(yk), &mut dy);
        }
        black_box(&dy);
        return;
    }
    for k in 0..n {
        let yk = if alt && k % 2 == 1 { &y2 } else { &y };
        ode.rhs(0.0, black_box(yk), &mut dy).unwrap();
    }
    black_box(&dy);
}
