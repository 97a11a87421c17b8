//! Redundant constraints: a triple-crank parallelogram (three equal parallel cranks under one
//! coupler). Chebyshev-Grubler counts 3*4 - 2*6 = 0 degrees of freedom; it moves with 1.

mod common;
use common::*;
use planardyn::dynamics::{forward, mass_matrix, ModelDrives};
use planardyn::kinematics::{assemble_into, velocity_analogues};
use planardyn::Workspace;

#[test]
fn redundant_parallelogram_loads_with_a_warning_naming_the_pairs() {
    let mech = yaml(PARALLELOGRAM);
    assert_eq!(mech.n_constraints, 11, "rank of the 12 pair rows");
    assert_eq!(mech.warnings.len(), 1, "{:?}", mech.warnings);
    let w = &mech.warnings[0];
    assert!(w.contains("redundant constraints among pairs") && w.contains("counts 0") && w.contains("shows 1"), "{w}");
}

#[test]
fn redundant_parallelogram_has_the_closed_form_dynamics() {
    // Every crank turns by theta, the coupler translates on a circle of radius r = 0.3 m:
    // A = 3 m_k r^2 / 3 + m_c r^2, and gravity gives -(3 m_k r/2 + m_c r) g cos(theta).
    let mech = yaml(PARALLELOGRAM);
    let (r, mk, mc, g) = (0.3, 0.3, 1.0, 9.81);
    let mut ws = Workspace::new(&mech);
    for theta in [1.0471975511965976, 0.2, -1.3, 2.8] {
        assemble_into(&mech, &[theta], &mut ws).unwrap();
        velocity_analogues(&mut ws).unwrap();
        mass_matrix(&mech, &mut ws);
        let a = 3.0 * mk * r * r / 3.0 + mc * r * r;
        assert!((ws.a[0] - a).abs() < 1e-12, "A({theta}) = {} vs {a}", ws.a[0]);
        forward(&mech, 0.0, &[theta], &[0.0], &mut ModelDrives(&mech), &mut ws).unwrap();
        let qdd = -(3.0 * mk * r / 2.0 + mc * r) * g * theta.cos() / a;
        assert!((ws.qdd[0] - qdd).abs() < 1e-10, "qdd({theta}) = {} vs {qdd}", ws.qdd[0]);
        // The left-out constraint holds too: crank 3's pin coincides with the coupler's C.
        let c = mech.point_id("C").unwrap();
        let on_crank = mech.attachment(planardyn::model::Link::Body(mech.body_id("crank3").unwrap()), c).unwrap();
        let on_coupler = mech.attachment(planardyn::model::Link::Body(mech.body_id("coupler").unwrap()), c).unwrap();
        let (p3, pc) = (
            planardyn::kinematics::constraints::world_point(on_crank.link, on_crank.s, &ws.x),
            planardyn::kinematics::constraints::world_point(on_coupler.link, on_coupler.s, &ws.x),
        );
        assert!((p3[0] - pc[0]).hypot(p3[1] - pc[1]) < 1e-12, "gap at C: {p3:?} vs {pc:?}");
    }
}

#[test]
fn redundant_parallelogram_conserves_energy_and_stops_at_its_change_point() {
    // Hanging 30 degrees off the vertical, it swings between -60 and -120 degrees.
    let hanging = PARALLELOGRAM
        .replace("0.2598076211353316", "-0.2598076211353316")
        .replace("value: 1.0471975511965976", "value: -1.0471975511965976");
    let mech = yaml(&hanging);
    let tr = run(&mech, "dop853", 2.0, 1e-11, Some(planardyn::simulate::grid(0.0, 2.0, 1e-3)));
    assert!(tr.stats.energy_drift < 1e-9, "drift {}", tr.stats.energy_drift);
    let (lo, hi) = tr.q.iter().fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &v| (a.min(v), b.max(v)));
    // The start is exact; the far turning point (-120 degrees, by symmetry of the swing) is
    // sampled every 1 ms: qdd ~ 3 rad/s^2 there, so the sample misses it by < 1e-6 rad.
    assert!((hi + 1.0471975511965976).abs() < 1e-12, "start {hi}");
    assert!((lo + 2.0943951023931953).abs() < 1e-6, "turning point {lo}");
    // Released from +60 degrees it falls through 0, where all the pins line up with the
    // ground pivots: the constraints lose rank there (the coupler could also turn). The
    // integrator either steps across it on the parallelogram branch with the energy kept,
    // or stops there saying so; never a wrong answer or a bare step-size failure.
    let mech = yaml(PARALLELOGRAM);
    for rtol in [1e-9, 1e-11] {
        let mut s = planardyn::simulate::Settings::for_model(&mech).unwrap();
        s.t_end = 2.0;
        s.options.rtol = rtol;
        let tr = planardyn::simulate::simulate(&mech, &s, &mut ModelDrives(&mech), None).unwrap();
        assert!(tr.stats.min_passive_sigma < 1e-2, "rtol {rtol}: passed near the change point");
        if tr.success() {
            assert!(tr.stats.energy_drift < 1e-6, "rtol {rtol}: drift {}", tr.stats.energy_drift);
        } else {
            assert_eq!(tr.status, planardyn::simulate::Status::PassiveSingularity, "rtol {rtol}: {}", tr.message);
            let theta = tr.q[tr.len() - 1];
            assert!(theta.abs() < 1e-2, "rtol {rtol}: stopped at theta = {theta}");
        }
    }
}
