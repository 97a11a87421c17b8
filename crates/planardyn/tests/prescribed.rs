//! Prescribed motion: coordinates driven by a motion law get the efforts it needs (checked
//! against the power balance and against inverse dynamics of the same motion), free
//! coordinates integrate beside them with an energy balance that closes, and the model
//! file's `motion` entries are checked field by field.

mod common;
use common::*;
use planardyn::dynamics::{inverse, ModelDrives, Motion, MotionFunction, Prescribed};
use planardyn::simulate::{simulate, simulate_prescribed, Settings, Trajectory};
use planardyn::{loads, Format, Mechanism, Workspace};

/// The slider-crank of `common::slider_crank_at_speed`, its crank turned by `motion` instead
/// of a torque: tau omega = dT/dt + dV/dt exactly.
fn slider_crank(motion: &str) -> Mechanism {
    slider_crank_at_speed(
        &format!(
            "coordinates:\n  - {{name: phi, pair: O, value: 0.5235987755982988}}\ndrives:\n  - {{coordinate: phi, motion: {motion}}}\n"
        ),
        false,
    )
}

const OMEGA: f64 = std::f64::consts::TAU;

fn settings(mech: &Mechanism, t_end: f64, rtol: f64, t_eval: Vec<f64>) -> Settings {
    let mut s = Settings::for_model(mech).unwrap();
    s.t_end = t_end;
    s.options.rtol = rtol;
    s.options.atol = rtol * 1e-3;
    s.t_eval = Some(t_eval);
    s
}

fn energy(tr: &Trajectory, k: usize) -> f64 {
    tr.kinetic[k] + tr.potential[k]
}

/// The crank torque of the constant-speed run is the power balance's, tau = (dT/dt + dV/dt)
/// / omega, and inverse dynamics' for q = q0 + omega t, qd = omega, qdd = 0.
#[test]
fn constant_speed_crank_torque_closes_the_power_balance() {
    let mech = slider_crank(&format!("{{speed: {OMEGA}}}"));
    let h = 1e-4;
    // Triples t - h, t, t + h for a central difference of T + V at 20 times over one turn.
    let t_eval: Vec<f64> = (1..=20).flat_map(|k| [-h, 0.0, h].map(|d| 0.05 * k as f64 - 0.025 + d)).collect();
    let tr = simulate(&mech, &settings(&mech, 1.0, 1e-10, t_eval), &mut ModelDrives(&mech), None).unwrap();
    assert!(tr.success(), "{}", tr.message);
    let mut ws = Workspace::new(&mech);
    let mut peak = 0.0_f64;
    for k in (1..tr.len()).step_by(3) {
        let t = tr.t[k];
        // The motion itself, exactly: q = 30 deg + omega t.
        assert!((tr.q[k] - (0.5235987755982988 + OMEGA * t)).abs() < 1e-12, "q({t}) = {}", tr.q[k]);
        assert!((tr.qd[k] - OMEGA).abs() < 1e-12 && tr.qdd[k].abs() < 1e-9, "qd {} qdd {}", tr.qd[k], tr.qdd[k]);
        // Central difference of E = T + V: truncation E''' h^2 / 6 ~ 1e-8 W here (E''' is
        // O(omega^3 * 1 J)), far below the 1e-5 N m asked of the torque.
        let de_dt = (energy(&tr, k + 1) - energy(&tr, k - 1)) / (2.0 * h);
        let tau = tr.tau[k];
        assert!(
            (tau * OMEGA - de_dt).abs() < 1e-5 * OMEGA,
            "t = {t}: tau omega = {} W, dE/dt = {de_dt} W",
            tau * OMEGA
        );
        ws.x.copy_from_slice(&tr.x[k * mech.n_x()..(k + 1) * mech.n_x()]);
        inverse(&mech, &tr.q[k..k + 1], &[OMEGA], &[0.0], &mut ws).unwrap();
        // Both are the same equations at the same point: agreement to round-off.
        assert!((tau - ws.tau[0]).abs() < 1e-10 * (1.0 + tau.abs()), "t = {t}: {tau} vs inverse {}", ws.tau[0]);
        peak = peak.max(tau.abs());
    }
    // The motion is not trivial: the torque swings by a sizeable amount.
    assert!(peak > 0.1, "peak torque {peak} N m");
    // The work of the prescribed torque balances T + V to the integrator's accuracy.
    assert!(tr.stats.energy_drift < 1e-10, "energy balance {} J", tr.stats.energy_drift);
}

/// A table motion (the not-a-knot spline reproduces a cubic) gives inverse dynamics' torque
/// for that cubic, ends included: no stop is invented at either end.
#[test]
fn table_motion_follows_a_cubic_to_its_ends() {
    let q = |t: f64| [0.5 + 3.0 * t + 2.0 * t * t - 1.5 * t.powi(3), 3.0 + 4.0 * t - 4.5 * t * t, 4.0 - 9.0 * t];
    let times: Vec<f64> = (0..=8).map(|k| k as f64 / 8.0).collect();
    let values: Vec<String> = times.iter().map(|&t| format!("{}", q(t)[0])).collect();
    let tt: Vec<String> = times.iter().map(|t| t.to_string()).collect();
    let mech = slider_crank(&format!("{{table: {{t: [{}], q: [{}]}}}}", tt.join(", "), values.join(", ")));
    let tr = simulate(&mech, &settings(&mech, 1.0, 1e-10, vec![0.0, 0.3, 0.77, 1.0]), &mut ModelDrives(&mech), None)
        .unwrap();
    assert!(tr.success(), "{}", tr.message);
    let mut ws = Workspace::new(&mech);
    for k in 0..tr.len() {
        let [q0, qd0, qdd0] = q(tr.t[k]);
        assert!((tr.q[k] - q0).abs() < 1e-12 && (tr.qd[k] - qd0).abs() < 1e-11 && (tr.qdd[k] - qdd0).abs() < 1e-9);
        ws.x.copy_from_slice(&tr.x[k * mech.n_x()..(k + 1) * mech.n_x()]);
        inverse(&mech, &[q0], &[qd0], &[qdd0], &mut ws).unwrap();
        assert!((tr.tau[k] - ws.tau[0]).abs() < 1e-9 * (1.0 + ws.tau[0].abs()), "t = {}", tr.t[k]);
    }
}

/// The slider-crank with a mass riding on the slider, on its own guide and spring: the crank
/// at constant speed (prescribed), the mass's displacement s free.
const SHAKER: &str = r#"
name: shaker
gravity: [0, -9.81]
points:
  O: [0, 0]
  A: [0.08660254037844387, 0.05]
  B: [0.43531445586169776, 0.02]
  C: [0.53531445586169776, 0.02]
ground: [O]
bodies:
  crank: {points: [O, A], uniform_bar: [O, A], mass: 0.3}
  rod: {points: [A, B], uniform_bar: [A, B], mass: 0.6}
  slider: {points: [B], mass: 0.5, inertia: 0.001, com: B}
  rider: {points: [C], mass: 0.2, inertia: 0.0005, com: C}
pairs:
  - {type: revolute, name: O, at: O, bodies: [ground, crank]}
  - {type: revolute, at: A, bodies: [crank, rod]}
  - {type: revolute, at: B, bodies: [rod, slider]}
  - {type: prismatic, name: guide, at: B, bodies: [ground, slider], axis: [1, 0]}
  - {type: prismatic, name: ride, at: C, bodies: [slider, rider], axis: [1, 0]}
coordinates:
  - {name: phi, pair: O, value: 0.5235987755982988}
  - {name: s, pair: ride, value: 0.0, qd0: 0.3}
drives:
  - {coordinate: phi, motion: {speed: 6.283185307179586}}
loads:
  - {type: spring, between: [[slider, B], [rider, C]], stiffness: 80.0, rest_length: 0.1}
"#;

/// A mixed run: the free coordinate integrates while the crank follows its motion; the
/// crank torque is inverse dynamics' for the motion found (with zero effort on the free
/// coordinate), and T + V - W, W the crank torque's work, stays constant.
#[test]
fn mixed_run_closes_its_energy_balance() {
    let mech = yaml(SHAKER);
    let t_eval: Vec<f64> = (0..=40).map(|k| k as f64 * 0.05).collect();
    let tr = simulate(&mech, &settings(&mech, 2.0, 1e-10, t_eval), &mut ModelDrives(&mech), None).unwrap();
    assert!(tr.success(), "{}", tr.message);
    let mut ws = Workspace::new(&mech);
    let nx = mech.n_x();
    let (mut s_range, mut work_range) = ((f64::INFINITY, f64::NEG_INFINITY), (0.0_f64, 0.0_f64));
    for k in 0..tr.len() {
        let (q, qd, qdd) = (&tr.q[2 * k..2 * k + 2], &tr.qd[2 * k..2 * k + 2], &tr.qdd[2 * k..2 * k + 2]);
        assert!((q[0] - (0.5235987755982988 + OMEGA * tr.t[k])).abs() < 1e-12 && (qd[0] - OMEGA).abs() < 1e-12);
        ws.x.copy_from_slice(&tr.x[k * nx..(k + 1) * nx]);
        inverse(&mech, q, qd, qdd, &mut ws).unwrap();
        let scale = 1.0 + ws.tau[0].abs();
        assert!(
            (tr.tau[2 * k] - ws.tau[0]).abs() < 1e-8 * scale,
            "t = {}: crank {} vs {}",
            tr.t[k],
            tr.tau[2 * k],
            ws.tau[0]
        );
        // The free coordinate has no drive: inverse dynamics of its motion needs none.
        assert!(ws.tau[1].abs() < 1e-8 * scale, "t = {}: effort on s {}", tr.t[k], ws.tau[1]);
        s_range = (s_range.0.min(q[1]), s_range.1.max(q[1]));
        work_range = (work_range.0.min(tr.work[k]), work_range.1.max(tr.work[k]));
    }
    // The rider moves and the crank does work, both by visible amounts.
    assert!(s_range.1 - s_range.0 > 0.01, "s between {s_range:?} m");
    assert!(work_range.1 - work_range.0 > 0.05, "W between {work_range:?} J");
    // DOP853 at rtol 1e-10 over 2 s: the balance closes to the integrator's accuracy (2e-12 J measured).
    assert!(tr.stats.energy_drift < 1e-10, "energy balance {} J", tr.stats.energy_drift);
}

/// A motion given as a function (as from Python): the same run as the model's `speed`.
struct Turn(f64);
impl MotionFunction for Turn {
    fn motion(&mut self, t: f64) -> Result<[f64; 3], String> {
        Ok([self.0 + OMEGA * t, OMEGA, 0.0])
    }
}

#[test]
fn motion_function_matches_the_speed_law() {
    let mech = yaml(&SHAKER.replace("  - {coordinate: phi, motion: {speed: 6.283185307179586}}\n", "  []\n"));
    let mech_speed = yaml(SHAKER);
    let t_eval = vec![0.0, 0.5, 1.0];
    let s = settings(&mech, 1.0, 1e-10, t_eval);
    let mut turn = Turn(0.5235987755982988);
    let mut motion = Prescribed::from_model(&mech);
    motion.set(0, Motion::Function(&mut turn)).unwrap();
    let tr = simulate_prescribed(&mech, &s, &mut ModelDrives(&mech), &mut motion, None).unwrap();
    let reference = simulate(&mech_speed, &s, &mut ModelDrives(&mech_speed), None).unwrap();
    assert!(tr.success() && reference.success());
    for (a, b) in tr.q.iter().chain(&tr.tau).zip(reference.q.iter().chain(&reference.tau)) {
        assert!((a - b).abs() < 1e-12 * (1.0 + b.abs()), "{a} vs {b}");
    }
}

/// The falling five-bar (its benchmark file) for 1 s, every step output, with its first
/// crank driven at `speed` (rad/s) from its start.
fn falling_five_bar_with_crank_at(speed: f64) -> Trajectory {
    let text = std::fs::read_to_string(format!(
        "{}/../../examples/models/five-bar-free-fall.yaml",
        env!("CARGO_MANIFEST_DIR")
    ))
    .unwrap()
    .replace(
        "  - {coordinate: theta1, effort: 0.0}   # N m, zero: the fall is passive",
        &format!("  - {{coordinate: theta1, motion: {{speed: {speed}}}}}"),
    );
    let mech = loads(&text, Format::Yaml, "<five-bar, crank driven>").unwrap();
    let mut s = Settings::for_model(&mech).unwrap();
    s.t_end = 1.0;
    s.t_eval = None;
    simulate(&mech, &s, &mut ModelDrives(&mech), None).unwrap()
}

/// A crank held still (speed 0) while the rest of the five-bar falls: the free four-bar
/// passes its own type II singularities, integrated in a partition chart there, and its
/// energy stays that of the benchmark (the holding torque does no work).
#[test]
fn held_crank_lets_the_free_part_cross_its_singularities() {
    let tr = falling_five_bar_with_crank_at(0.0);
    assert!(tr.success(), "{:?} {}", tr.status, tr.message);
    assert!(tr.stats.chart_switches > 0, "no chart switch: min sigma {}", tr.stats.min_sigma);
    assert!(tr.q.chunks(2).all(|q| (q[0] - 2.0943951023931953).abs() < 1e-7), "theta1 left its hold");
    assert!(tr.work.iter().all(|w| w.abs() < 1e-9), "work of a still crank");
    assert!(tr.stats.energy_drift < 5e-8, "energy balance {} J", tr.stats.energy_drift);
}

fn load_err(drive: &str) -> String {
    let text = SHAKER.replace("  - {coordinate: phi, motion: {speed: 6.283185307179586}}", drive);
    loads(&text, Format::Yaml, "shaker.yaml").err().map(|e| e.to_string()).unwrap_or_default()
}

#[test]
fn model_file_errors_name_the_field_and_the_fix() {
    let cases = [
        ("  - {coordinate: phi, effort: 1.0, motion: {speed: 1.0}}", "drives[0]: give exactly one of"),
        (
            "  - {coordinate: phi, motion: {speed: 1.0, table: {t: [0, 1], q: [0, 1]}}}",
            "drives[0].motion: give exactly one of `speed`",
        ),
        ("  - {coordinate: phi, motion: {}}", "drives[0].motion: give exactly one of `speed`"),
        (
            "  - {coordinate: phi, motion: {table: {t: [0, 1, 2], q: [0, 1]}}}",
            "drives[0].motion.table: `t` and `q` must have the same length",
        ),
        (
            "  - {coordinate: phi, motion: {table: {t: [0, 1, 1], q: [0, 1, 2]}}}",
            "drives[0].motion.table.t[2]: times must increase strictly",
        ),
        ("  - {coordinate: phi, motion: {speed: .nan}}", "drives[0].motion.speed: NaN is not a finite number"),
        ("  - {coordinate: phi, motion: {rpm: 60}}", "rpm"),
        ("  - {coordinate: crank, motion: {speed: 1.0}}", "unknown coordinate 'crank'"),
        ("  - {coordinate: phi, motion: {speed: 1.0}}\n  - {coordinate: phi, effort: 1.0}", "already has a drive"),
    ];
    for (drive, want) in cases {
        let got = load_err(drive);
        assert!(got.starts_with("shaker.yaml: ") && got.contains(want), "{drive}\n  got: {got}\n  want: {want}");
    }
}

/// A table that does not cover the run is refused before it starts, naming the fix.
#[test]
fn table_shorter_than_the_run_is_refused() {
    let mech = slider_crank("{table: {t: [0, 0.5, 1], q: [0, 1, 2]}}");
    let s = settings(&mech, 2.0, 1e-8, vec![0.0, 2.0]);
    let e = simulate(&mech, &s, &mut ModelDrives(&mech), None).unwrap_err().to_string();
    assert!(
        e.contains("the motion table of 'phi' covers t = 0 to 1 s") && e.contains("extend the table or shorten t_end"),
        "{e}"
    );
}

/// As above with the crank turning (0.5 rad/s): in the partition chart the prescribed row of
/// G is D_p,x U, not a unit row, and h carries the convective terms; the crank still follows
/// its motion and T + V - W, W its torque's work, still closes.
#[test]
fn turning_crank_with_the_free_part_in_a_partition_chart() {
    let tr = falling_five_bar_with_crank_at(0.5);
    assert!(tr.success(), "{:?} {}", tr.status, tr.message);
    let worst = (0..tr.len()).map(|k| (tr.q[2 * k] - (2.0943951023931953 + 0.5 * tr.t[k])).abs()).fold(0.0, f64::max);
    let work = tr.work.iter().fold(0.0_f64, |a, w| a.max(w.abs()));
    // Measured: 25 partition steps, the crank within 7e-13 rad of its motion, |W| up to 0.1 J,
    // the balance closed to 4e-9 J (rtol 1e-9, the model default).
    assert!(worst < 1e-9, "the crank is {worst} rad off its motion");
    assert!(work > 0.05, "largest |W| {work} J");
    assert!(tr.stats.partition_steps > 0, "never in a partition chart: min sigma {}", tr.stats.min_sigma);
    assert!(tr.stats.energy_drift < 5e-8, "energy balance {} J", tr.stats.energy_drift);
}

/// Both cranks of the five-bar turned into a type II singularity: the efforts the motion
/// needs grow without bound there, and the run's message says so and what to change.
#[test]
fn motion_into_a_singularity_is_reported_as_such() {
    let mech = shipped("five-bar.yaml");
    let mut motion = Prescribed::from_model(&mech);
    for (k, w) in [(0, 30f64.to_radians()), (1, -30f64.to_radians())] {
        motion.set(k, Motion::Law(planardyn::model::MotionLaw::Speed(w))).unwrap();
    }
    let mut s = Settings::for_model(&mech).unwrap();
    s.t_end = 1.0;
    s.t_eval = None;
    let tr = simulate_prescribed(&mech, &s, &mut ModelDrives(&mech), &mut motion, None).unwrap();
    assert!(!tr.success() && tr.t.last().is_some_and(|&t| t > 0.8), "{:?} at {:?}", tr.status, tr.t.last());
    assert!(
        tr.message.contains("the coordinates driven by motion are near a singularity of their own"),
        "{}",
        tr.message
    );
    assert!(tr.message.contains("Change the motion so that it avoids this configuration"), "{}", tr.message);
}
