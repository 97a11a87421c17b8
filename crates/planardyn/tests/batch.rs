//! Batch runs: a parallel batch equals a serial loop bit for bit, in input order; a failing
//! variant reports its own error and leaves the others untouched; edited specs are built by
//! the loader in parallel, then run.

mod common;
use common::*;
use planardyn::batch::{map_many, simulate_many, Overrides, Variant};
use planardyn::dynamics::ModelDrives;
use planardyn::error::{Setting, MIN_RTOL};
use planardyn::simulate::{simulate, Trajectory};
use planardyn::{Error, KinematicsError, ModelError};
use std::sync::Arc;

fn same(a: &Trajectory, b: &Trajectory) {
    assert_eq!(a.t, b.t);
    assert_eq!(a.q, b.q);
    assert_eq!(a.qd, b.qd);
    assert_eq!(a.tau, b.tau);
    assert_eq!(a.status, b.status);
}

/// Four-bar variants: start angles around the drawing, over 0.3 s.
fn variants(mech: &Arc<planardyn::Mechanism>, n: usize) -> Vec<Variant> {
    let q0 = mech.initial_state().0[0];
    (0..n)
        .map(|k| Variant {
            model: mech.clone(),
            overrides: Overrides { t_end: Some(0.3), q0: Some(vec![q0 + 0.02 * k as f64]), ..Overrides::default() },
        })
        .collect()
}

#[test]
fn parallel_batch_equals_serial_loop_in_order() {
    let mech = Arc::new(yaml(FOUR_BAR));
    let vs = variants(&mech, 12);
    let batch = simulate_many(&vs, Some(2)).unwrap();
    let serial = simulate_many(&vs, Some(1)).unwrap();
    for (k, (b, s)) in batch.iter().zip(&serial).enumerate() {
        let (b, s) = (b.as_ref().unwrap(), s.as_ref().unwrap());
        assert!(b.success(), "variant {k}: {}", b.message);
        same(b, s);
        // And the plain entry point, with the settings made by hand.
        let settings = vs[k].overrides.settings(&mech).unwrap();
        same(b, &simulate(&mech, &settings, &mut ModelDrives(&mech), None).unwrap());
    }
}

#[test]
fn a_failing_variant_does_not_stop_the_others() {
    let mech = Arc::new(shipped("five-bar.yaml"));
    let over = Overrides { t_end: Some(0.1), ..Overrides::default() };
    let mut vs = vec![Variant { model: mech.clone(), overrides: over }; 5];
    // Proximal links straight out (C1 C2 = 0.8 m > 2 x 0.35 m: the distal links cannot
    // meet), and a method that does not exist.
    vs[2].overrides.q0 = Some(vec![std::f64::consts::PI, 0.0]);
    vs[3].overrides.method = Some("euler".into());
    let out = simulate_many(&vs, None).unwrap();
    assert!(
        matches!(out[2], Err(Error::Kinematics(KinematicsError::AssemblyFailed { .. }))),
        "{:?}",
        out[2].as_ref().err()
    );
    assert!(matches!(out[3], Err(Error::Options(_))));
    for k in [0, 1, 4] {
        assert!(out[k].as_ref().unwrap().success());
    }
}

#[test]
fn edited_specs_are_built_in_parallel_then_run() {
    let base = yaml(FOUR_BAR);
    let mut heavy = base.spec.clone();
    heavy.bodies.0.get_mut("coupler").unwrap().mass = Some(2.4);
    let mut broken = base.spec.clone();
    broken.bodies.0.get_mut("coupler").unwrap().mass = Some(-1.0);
    let specs = [base.spec.clone(), heavy, broken];
    let built = map_many(&specs, Some(2), |spec| planardyn::build(spec.clone(), "<variant>")).unwrap();
    assert!(matches!(built[2], Err(ModelError::Invalid { .. })), "{:?}", built[2]);
    let over = Overrides { t_end: Some(0.2), ..Overrides::default() };
    let vs: Vec<Variant> = built[..2]
        .iter()
        .map(|mech| Variant { model: Arc::new(mech.clone().unwrap()), overrides: over.clone() })
        .collect();
    let out = simulate_many(&vs, Some(2)).unwrap();
    same(out[0].as_ref().unwrap(), &Variant { model: Arc::new(base), overrides: over.clone() }.simulate().unwrap());
    // The heavier coupler changes the motion.
    assert_ne!(out[0].as_ref().unwrap().q.last(), out[1].as_ref().unwrap().q.last());
}

// ------------------------------------------------------------------ inverse dynamics

use planardyn::batch::task::{SingularityKind, TaskError, TaskPath};
use planardyn::batch::{inverse_many, inverse_rows, Efforts, InverseVariant, Motion};
use planardyn::kinematics::Effector;

/// Forward dynamics at (q, qd) under given efforts: the consistency check of an inverse.
struct Given(Vec<f64>);
impl planardyn::dynamics::Drives for Given {
    fn efforts(&mut self, _t: f64, _q: &[f64], _qd: &[f64], tau: &mut [f64]) -> Result<(), String> {
        tau.copy_from_slice(&self.0);
        Ok(())
    }
}

fn qdd_under(mech: &planardyn::Mechanism, q: &[f64], qd: &[f64], tau: &[f64]) -> Vec<f64> {
    let mut ws = planardyn::Workspace::new(mech);
    planardyn::kinematics::assemble_into(mech, q, &mut ws).unwrap();
    planardyn::dynamics::forward(mech, 0.0, q, qd, &mut Given(tau.to_vec()), &mut ws).unwrap();
    ws.qdd.clone()
}

/// The five-bar's end effector P on a circle of radius r (m) through its drawn position,
/// once around in 1 s at constant angular speed, sampled every 2 ms; or on the straight
/// segment from the drawing to `to` (m) at constant speed.
fn five_bar_path(mech: &planardyn::Mechanism, circle: Option<f64>, to: [f64; 2]) -> TaskPath {
    let p0 = mech.points.iter().find(|(n, _)| n == "P").unwrap().1;
    let w = 2.0 * std::f64::consts::PI;
    let t: Vec<f64> = (0..=500).map(|i| i as f64 * 0.002).collect();
    let (mut x, mut xd, mut xdd) = (vec![], vec![], vec![]);
    for &ti in &t {
        let (c, s) = ((w * ti).cos(), (w * ti).sin());
        let (p, v, a) = match circle {
            Some(r) => {
                ([p0[0] + r * (c - 1.0), p0[1] + r * s], [-r * w * s, r * w * c], [-r * w * w * c, -r * w * w * s])
            }
            None => (
                [p0[0] + ti * (to[0] - p0[0]), p0[1] + ti * (to[1] - p0[1])],
                [to[0] - p0[0], to[1] - p0[1]],
                [0.0, 0.0],
            ),
        };
        x.extend(p);
        xd.extend(v);
        xdd.extend(a);
    }
    TaskPath { t, x, xd, xdd, point: "P".into(), body: None, q_start: None, singular_tol: 1e-3 }
}

#[test]
fn coordinate_motions_in_a_batch_equal_the_serial_rows_and_invert_the_forward_dynamics() {
    let mech = Arc::new(shipped("five-bar.yaml"));
    let runs: Vec<Trajectory> = variants(&Arc::new(yaml(FOUR_BAR)), 1).iter().map(|v| v.simulate().unwrap()).collect();
    let tr = run(&mech, "dop853", 0.3, 1e-10, Some((0..=30).map(|i| i as f64 * 0.01).collect()));
    let four = Arc::new(yaml(FOUR_BAR));
    let vs = vec![
        InverseVariant {
            model: mech.clone(),
            motion: Motion::Coordinates { q: tr.q.clone(), qd: tr.qd.clone(), qdd: tr.qdd.clone() },
        },
        InverseVariant {
            model: four.clone(),
            motion: Motion::Coordinates { q: runs[0].q.clone(), qd: runs[0].qd.clone(), qdd: runs[0].qdd.clone() },
        },
        // Rows of the wrong length: reported for this variant only.
        InverseVariant {
            model: mech.clone(),
            motion: Motion::Coordinates { q: vec![1.0; 3], qd: vec![0.0; 3], qdd: vec![0.0; 3] },
        },
    ];
    let out = inverse_many(&vs, Some(2)).unwrap();
    let Ok(Efforts::Coordinates(tau)) = &out[0] else { panic!("{:?}", out[0]) };
    assert_eq!(tau, &inverse_rows(&mech, &tr.q, &tr.qd, &tr.qdd).unwrap());
    assert_eq!(out, inverse_many(&vs, Some(1)).unwrap());
    // Forward then inverse returns the model's drive efforts (a constant and a table).
    let err = tau.iter().zip(&tr.tau).fold(0.0_f64, |m, (a, b)| m.max((a - b).abs()));
    assert!(err < 1e-8, "inverse of the simulated motion differs from its drives by {err} N m");
    let Ok(Efforts::Coordinates(tau4)) = &out[1] else { panic!("{:?}", out[1]) };
    assert!(tau4.iter().zip(&runs[0].tau).all(|(a, b)| (a - b).abs() < 1e-8), "the passive four-bar needs no effort");
    assert!(matches!(out[2], Err(TaskError::Core(Error::Kinematics(KinematicsError::BadArgument { .. })))));
}

#[test]
fn task_paths_in_a_batch_follow_the_path_and_report_failures_in_place() {
    let mech = Arc::new(shipped("five-bar.yaml"));
    let circle = five_bar_path(&mech, Some(0.05), [0.0; 2]);
    let mut heavy = mech.spec.clone();
    heavy.bodies.0.get_mut("distal_right").unwrap().mass = Some(1.4);
    let task = |model: Arc<planardyn::Mechanism>, path: &TaskPath| InverseVariant {
        model,
        motion: Motion::Task(path.clone()),
    };
    let mut wrong_point = circle.clone();
    wrong_point.point = "Q".into();
    let mut far = circle.clone();
    far.x.iter_mut().skip(1).step_by(2).for_each(|y| *y += 1.0);
    let vs = vec![
        task(mech.clone(), &circle),
        // Straight down through the type II singularity (distal links aligned near y = 0.15 m).
        task(mech.clone(), &five_bar_path(&mech, None, [0.014, 0.1])),
        // Up to 1 m above the base: it stops at the edge of the workspace, a type I singularity.
        task(mech.clone(), &five_bar_path(&mech, None, [0.014, 1.0])),
        task(mech.clone(), &wrong_point),
        task(Arc::new(planardyn::build(heavy, "<variant>").unwrap()), &circle),
        // The circle 1 m higher: its first point is out of reach.
        task(mech.clone(), &far),
    ];
    let out = inverse_many(&vs, Some(2)).unwrap();
    assert_eq!(out, inverse_many(&vs, Some(1)).unwrap());
    assert!(
        matches!(&out[1], Err(e @ TaskError::Singular { kind: SingularityKind::TypeII, .. }) if e.to_string().contains("type II")),
        "{:?}",
        out[1]
    );
    // The type I singularity: P stretched out of reach, (x, y) = (0.014, 0.577) m.
    assert!(
        matches!(&out[2], Err(TaskError::Singular { kind: SingularityKind::TypeI, x, .. }) if (x[1] - 0.577).abs() < 2e-3),
        "{:?}",
        out[2]
    );
    assert!(
        matches!(&out[5], Err(TaskError::OutOfReach { message, .. }) if message.contains("first point")),
        "{:?}",
        out[5]
    );
    assert!(
        matches!(&out[3], Err(TaskError::Core(Error::Kinematics(KinematicsError::BadArgument { name: "point", got, .. }))) if got == "\"Q\"")
    );
    let (Ok(Efforts::Task(sol)), Ok(Efforts::Task(heavier))) = (&out[0], &out[4]) else { panic!("{:?}", out[0]) };
    for i in (0..circle.t.len()).step_by(50) {
        let row = i * 2..i * 2 + 2;
        // The point is on the path: P at the solved q, from the positions alone.
        let x = planardyn::kinematics::assemble(&mech, &sol.q[row.clone()]).unwrap();
        let p = Effector::new(&mech, "P", None).unwrap().pose(&x);
        assert!(
            (p[0] - circle.x[2 * i]).abs() < 1e-12 && (p[1] - circle.x[2 * i + 1]).abs() < 1e-12,
            "sample {i}: {p:?}"
        );
        // The efforts produce the accelerations.
        let qdd = qdd_under(&mech, &sol.q[row.clone()], &sol.qd[row.clone()], &sol.tau[row.clone()]);
        assert!(
            qdd.iter().zip(&sol.qdd[row.clone()]).all(|(a, b)| (a - b).abs() < 1e-8 * (1.0 + b.abs())),
            "sample {i}"
        );
        // Same kinematics, heavier right distal link: the same q, other efforts.
        assert_eq!(heavier.q[row.clone()], sol.q[row.clone()]);
        assert!(sol.sigma_i[i] > 1e-3 && sol.sigma_ii[i] > 1e-3 && sol.condition[i] >= 1.0);
    }
    assert_ne!(heavier.tau, sol.tau);
}

/// The one rule of each numeric setting, in the core for every caller (the Python API, the
/// batch runner and the CLI check through it too): a bad value is an `Error::Setting` naming
/// the setting, its value as given and the fix; the glues map t_end's to ArgumentError
/// (`argument = 't_end'`), the others to SimulationError. A run made from the overrides and
/// one made from hand-written settings are refused the same way.
#[test]
fn a_bad_setting_is_refused_naming_it() {
    let mech = shipped("five-bar.yaml");
    let bad = [f64::NAN, f64::INFINITY, 0.0, -1.0];
    let cases: Vec<(Setting, Overrides)> = bad
        .iter()
        .flat_map(|&v| {
            [
                (Setting::TEnd, Overrides { t_end: Some(v), ..Overrides::default() }),
                (Setting::Rtol, Overrides { rtol: Some(v), ..Overrides::default() }),
                (Setting::Atol, Overrides { atol: Some(v), ..Overrides::default() }),
                (Setting::Dt, Overrides { dt: Some(v), ..Overrides::default() }),
                (Setting::OutputDt, Overrides { output_dt: Some(v), ..Overrides::default() }),
            ]
        })
        .chain([
            (Setting::MaxSteps, Overrides { max_steps: Some(0), ..Overrides::default() }),
            (Setting::MaxSteps, Overrides { max_steps: Some(1_000_000_000_001), ..Overrides::default() }),
            (Setting::Rtol, Overrides { rtol: Some(MIN_RTOL / 2.0), ..Overrides::default() }),
            (Setting::Dt, Overrides { method: Some("rk4".into()), ..Overrides::default() }),
        ])
        .collect();
    for (setting, over) in cases {
        let e = over.settings(&mech).unwrap_err();
        let Error::Setting(s) = &e else { panic!("{over:?}: {e:?}") };
        assert_eq!(s.setting, setting, "{e}");
        // The message names the setting and its value, and says what it must be.
        let name = setting.name();
        assert!(e.to_string().starts_with(&format!("invalid option: {name} = {} ", s.value)), "{e}");
        assert!(s.rule.contains("must be") || s.rule.contains("use") || s.rule.contains("set"), "{e}");
    }
    // As a caller wrote them: t_end = NaN, inf, 0, -1 (the Display of each f64).
    for t_end in bad {
        let e = Overrides { t_end: Some(t_end), ..Overrides::default() }.settings(&mech).unwrap_err();
        assert!(matches!(&e, Error::Setting(s) if s.value == t_end.to_string()), "{e:?}");
    }
    // Hand-written settings are checked by the same rule.
    let mut s = Overrides::default().settings(&mech).unwrap();
    s.options.atol = 0.0;
    let e = simulate(&mech, &s, &mut ModelDrives(&mech), None).unwrap_err();
    assert!(matches!(&e, Error::Setting(s) if s.setting == Setting::Atol), "{e:?}");
}
