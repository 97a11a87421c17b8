//! A forward-dynamics evaluation, as the integrator makes it, allocates nothing: every buffer
//! is in the workspace (checked with a counting global allocator, this file only).

mod common;
use common::*;
use planardyn::dynamics::ModelDrives;
use planardyn::integrate::OdeSystem;
use planardyn::kinematics::{assemble_into, velocity_analogues, Chart};
use planardyn::simulate::ode::MechanismOde;
use planardyn::{Mechanism, Workspace};
use std::alloc::{GlobalAlloc, Layout, System};
use std::cell::Cell;

struct Counting;
thread_local! {
    // Per thread: the tests run in parallel, and the harness allocates on its own threads.
    static ALLOCATIONS: Cell<usize> = const { Cell::new(0) };
}

unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        // `try_with`: a thread's last allocations may come after its locals are gone.
        let _ = ALLOCATIONS.try_with(|n| n.set(n.get() + 1));
        unsafe { System.alloc(layout) }
    }
    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        unsafe { System.dealloc(ptr, layout) }
    }
}

#[global_allocator]
static GLOBAL: Counting = Counting;

/// The workspace assembled at `q` with its velocity analogues.
fn assembled(mech: &Mechanism, q: &[f64]) -> Workspace {
    let mut ws = Workspace::new(mech);
    assemble_into(mech, q, &mut ws).unwrap();
    velocity_analogues(&mut ws).unwrap();
    ws
}

/// Start `ode` at (q, qd) in `chart`, then count the allocations of ten
/// evaluations and acceptances at states that `vary` moves a little each step.
fn allocations(ode: &mut MechanismOde, chart: Chart, q: &[f64], qd: &[f64], vary: impl Fn(&mut [f64], usize)) -> usize {
    let m = q.len();
    let mut y = vec![0.0; 2 * m + 1];
    y[..m].copy_from_slice(q);
    y[m..2 * m].copy_from_slice(qd);
    ode.set_chart(chart, 0.0, &y).unwrap();
    let mut dy = vec![0.0; 2 * m + 1];
    let before = ALLOCATIONS.with(Cell::get);
    for step in 0..10 {
        vary(&mut y, step);
        let t = 1e-3 * step as f64;
        ode.rhs(t, &y, &mut dy).unwrap();
        ode.accept(t, &y).unwrap();
    }
    ALLOCATIONS.with(Cell::get) - before
}

#[test]
fn rhs_evaluation_does_not_allocate() {
    for mech in all_models() {
        let m = mech.dof();
        let (q, qd) = test_state(&mech);
        let mut drives = ModelDrives(&mech);
        let mut ode = MechanismOde::new(&mech, assembled(&mech, &q), &mut drives);
        // Away from the start, so that Newton runs.
        let vary = |y: &mut [f64], step: usize| {
            if step == 0 {
                y[..m].iter_mut().for_each(|v| *v += 1e-3);
            }
            y[0] += 1e-4 * step as f64;
        };
        assert_eq!(allocations(&mut ode, Chart::Inputs, &q, &qd, vary), 0, "{}: allocations in rhs/accept", mech.name);
    }
}

/// The same with the first coordinate driven by a table motion. (In the user's chart: an
/// evaluation in a partition chart allocates once, with or without motion.)
#[test]
fn prescribed_rhs_evaluation_does_not_allocate() {
    use planardyn::dynamics::{Motion, Prescribed};
    use planardyn::model::{MotionLaw, Spline};
    for mech in all_models() {
        let m = mech.dof();
        let (q, qd) = test_state(&mech);
        let mut drives = ModelDrives(&mech);
        let law = Spline::new(&[0.0, 0.5, 1.0, 1.5], &[q[0], q[0] + 0.01, q[0] + 0.03, q[0] + 0.02]).unwrap();
        let mut motion = Prescribed::from_model(&mech);
        motion.set(0, Motion::Law(MotionLaw::Table(law))).unwrap();
        motion.start(0.0, 1.0, &q).unwrap();
        let mut ode = MechanismOde::new(&mech, assembled(&mech, &q), &mut drives).with_motion(&mut motion);
        let vary = |y: &mut [f64], _: usize| y[m..2 * m].iter_mut().for_each(|v| *v *= 1.0 + 1e-6);
        assert_eq!(allocations(&mut ode, Chart::Inputs, &q, &qd, vary), 0, "{}: allocations in rhs/accept", mech.name);
    }
}

/// In a partition chart (components of x as coordinates, as near a type II singularity):
/// the state is those components, their rates from the user's via U.
#[test]
fn partition_chart_evaluation_does_not_allocate() {
    use planardyn::kinematics::select_partition;
    for mech in all_models() {
        let (q, qd) = test_state(&mech);
        let ws = assembled(&mech, &q);
        let idx = select_partition(&mech, &ws.x);
        let z: Vec<f64> = idx.iter().map(|&i| ws.x[i]).collect();
        let zd: Vec<f64> = idx.iter().map(|&i| (0..q.len()).map(|j| ws.u_col(j)[i] * qd[j]).sum()).collect();
        let mut drives = ModelDrives(&mech);
        let mut ode = MechanismOde::new(&mech, ws, &mut drives);
        let vary = |y: &mut [f64], step: usize| y[0] += 1e-6 * step as f64;
        let n = allocations(&mut ode, Chart::Partition(idx), &z, &zd, vary);
        assert_eq!(n, 0, "{}: allocations in rhs/accept in a partition chart", mech.name);
    }
}

/// With transmissions and pair friction the fixed point of friction and reactions runs in
/// the workspace's loss buffers, in the input and in a partition chart.
#[test]
fn evaluation_with_losses_does_not_allocate() {
    let drawing = SLIDER_CRANK
        .split("loads:")
        .next()
        .unwrap_or_default()
        .replace("{type: revolute, at: A,", "{type: revolute, name: A, at: A,");
    let mech = yaml(&format!(
        "{drawing}loads:\n  - {{type: friction, pair: O, mu: 0.15, pin_radius: 0.01}}\n  \
         - {{type: friction, pair: A, mu: 0.1, pin_radius: 0.008}}\n  \
         - {{type: friction, pair: guide, mu: 0.2, length: 0.04}}\n\
         actuators:\n  - {{coordinate: phi, gear_ratio: 10, efficiency: 0.9, rotor_inertia: 1.0e-4, coulomb: 0.005}}\n"
    ));
    let (q, qd) = test_state(&mech);
    let m = mech.dof();
    let vary = |y: &mut [f64], _: usize| y[m..2 * m].iter_mut().for_each(|v| *v *= 1.0 + 1e-6);
    let mut drives = ModelDrives(&mech);
    let mut ode = MechanismOde::new(&mech, assembled(&mech, &q), &mut drives);
    assert_eq!(allocations(&mut ode, Chart::Inputs, &q, &qd, vary), 0, "allocations with losses");
    let ws = assembled(&mech, &q);
    let idx = vec![6];
    let z: Vec<f64> = idx.iter().map(|&i| ws.x[i]).collect();
    let zd: Vec<f64> = idx.iter().map(|&i| ws.u_col(0)[i] * qd[0]).collect();
    let mut drives = ModelDrives(&mech);
    let mut ode = MechanismOde::new(&mech, ws, &mut drives);
    let vary = |y: &mut [f64], step: usize| y[0] += 1e-6 * step as f64;
    assert_eq!(allocations(&mut ode, Chart::Partition(idx), &z, &zd, vary), 0, "in a partition chart");
}

/// Two geared motors with rotors on the five-bar (a 2 x 2 motor system, `dynamics::gears`):
/// at rest (each gear's candidates motoring, back-driven and stuck, tried in turn until one is
/// consistent) and moving, in the input chart.
#[test]
fn geared_motors_branch_solves_do_not_allocate() {
    let motor = "gear_ratio: 30, efficiency: 0.7, backdrive_efficiency: 0.4, rotor_inertia: 2.0e-5, coulomb: 0.01";
    let mech = yaml(&format!(
        "{FIVE_BAR_FALL}drives:\n  - {{coordinate: theta1, effort: 0.3}}\n  - {{coordinate: theta2, effort: -0.2}}\n\
         actuators:\n  - {{coordinate: theta1, {motor}}}\n  - {{coordinate: theta2, {motor}}}\n"
    ));
    let (q, qd) = test_state(&mech);
    let m = mech.dof();
    for (qd, what) in [(vec![0.0; m], "at rest"), (qd, "moving")] {
        let mut drives = ModelDrives(&mech);
        let mut ode = MechanismOde::new(&mech, assembled(&mech, &q), &mut drives);
        // Positions only: at rest the rates stay 0, so every evaluation searches the modes.
        let vary = |y: &mut [f64], step: usize| y[0] += 1e-5 * step as f64;
        assert_eq!(allocations(&mut ode, Chart::Inputs, &q, &qd, vary), 0, "allocations with geared motors {what}");
    }
}

/// The flexible-joint model's evaluation (`elastic::FlexibleOde`: the mechanism without its
/// rotors, the springs' efforts as its drives, the rotors' equations) on the four-bar, whose
/// positions need Newton.
#[test]
fn flexible_joint_evaluation_does_not_allocate() {
    use planardyn::elastic::FlexibleOde;
    let mech = yaml(&format!(
        "{FOUR_BAR}drives:\n  - {{coordinate: theta1, effort: 0.02}}\n\
         actuators: [{{coordinate: theta1, gear_ratio: 20, rotor_inertia: 5.0e-5}}]\n\
         compliance:\n  drives: [{{actuator: theta1, stiffness: 1.0e3, damping: 0.5}}]\n"
    ));
    let (mut ode, mut y) = FlexibleOde::new(&mech).unwrap();
    let mut dy = vec![0.0; y.len()];
    ode.rhs(0.0, &y, &mut dy).unwrap();
    let before = ALLOCATIONS.with(Cell::get);
    for step in 0..10 {
        // Coupler and rotor apart: the spring works, and Newton moves the loop.
        y[0] += 1e-3;
        y[2] -= 2e-3 * step as f64;
        ode.rhs(1e-3 * step as f64, &y, &mut dy).unwrap();
    }
    assert_eq!(ALLOCATIONS.with(Cell::get) - before, 0, "allocations in the flexible-joint rhs");
    assert!(dy.iter().all(|v| v.is_finite()), "{dy:?}");
}

/// The approach to a change point, at each accepted step (`simulate::crossing::Approach`):
/// keeping the point and the nodes filled inside the step, the time left and the step limit.
/// Once its queues are full their oldest buffers are reused.
#[test]
fn approach_bookkeeping_does_not_allocate() {
    use planardyn::simulate::charts::Measures;
    use planardyn::simulate::crossing::Approach;
    let mech = yaml(FOUR_BAR);
    let (q, qd) = test_state(&mech);
    let mut drives = ModelDrives(&mech);
    let mut ode = MechanismOde::new(&mech, assembled(&mech, &q), &mut drives);
    let y: Vec<f64> = q.iter().chain(&qd).copied().chain([0.0]).collect();
    ode.set_chart(Chart::Inputs, 0.0, &y).unwrap();
    let mut approach = Approach::default();
    // A measure falling linearly to 0 at t = 1 s: a change point ahead, the grid defined.
    let step = |approach: &mut Approach, k: usize| {
        let t = 1e-2 * k as f64;
        approach.fill(&ode, t - 5e-3);
        let meas = Measures { sigma: 0.1 * (1.0 - t), passive: 0.1 * (1.0 - t) };
        approach.keep(&ode, t, &meas);
        approach.step_limit(t, &meas)
    };
    // Past the queues' length (a few dozen): from here on each point reuses the oldest's buffers.
    for k in 0..64 {
        step(&mut approach, k);
    }
    let mut limits = Vec::with_capacity(10);
    let before = ALLOCATIONS.with(Cell::get);
    for k in 64..74 {
        limits.push(step(&mut approach, k));
    }
    assert_eq!(ALLOCATIONS.with(Cell::get) - before, 0, "allocations in the approach's bookkeeping");
    // The limit is ahead of each step and before the point at 1 s.
    for (k, limit) in (64..74).zip(&limits) {
        let t = 1e-2 * k as f64;
        assert!(limit.is_some_and(|l| l > t && l < 1.0), "step {k}: {limit:?}");
    }
}
