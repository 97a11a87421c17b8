//! Models shared by the integration tests, written inline so that each test states its data.
#![allow(dead_code)]

use planardyn::integrate::OdeSystem;
use planardyn::{loads, Format, Mechanism};
use std::convert::Infallible;

pub mod ode;

pub fn yaml(text: &str) -> Mechanism {
    loads(text, Format::Yaml, "<test>").unwrap_or_else(|e| panic!("{e}"))
}

/// Simple pendulum: a uniform bar of length l = 0.8 m, m = 2 kg, hinged at O, q the absolute
/// angle of O->A from the x axis.
pub const PENDULUM: &str = r#"
name: pendulum
gravity: [0, -9.81]
points: {O: [0, 0], A: [0.8, 0]}
ground: [O]
bodies:
  bar: {points: [O, A], uniform_bar: [O, A], mass: 2.0}
pairs:
  - {type: revolute, name: O, at: O, bodies: [ground, bar]}
coordinates:
  - {name: theta, pair: O, value: 0.0}
"#;

/// The four-bar of tests/data/benchmarks/four-bar-gravity.json.
pub const FOUR_BAR: &str = r#"
name: four-bar under gravity
gravity: [0.0, -9.81]
points:
  O: [0.0, 0.0]
  D: [1.0, 0.0]
  A: [0.25, 0.4330127018922193]
  B: [1.336926485022576, 0.9415309573722639]
ground: [O, D]
bodies:
  crank: {points: [O, A], mass: 0.5, inertia: 0.010416666666666666, com: [0.125, 0.21650635094610965]}
  coupler: {points: [A, B], mass: 1.2, inertia: 0.144, com: [0.793463242511288, 0.6872718296322415]}
  rocker: {points: [D, B], mass: 1.0, inertia: 0.08333333333333333, com: [1.168463242511288, 0.47076547868613194]}
pairs:
  - {type: revolute, name: O, at: O, bodies: [ground, crank]}
  - {type: revolute, at: A, bodies: [crank, coupler]}
  - {type: revolute, at: B, bodies: [coupler, rocker]}
  - {type: revolute, at: D, bodies: [ground, rocker]}
coordinates:
  - {name: theta1, pair: O, value: 1.0471975511965976}
"#;

/// Offset slider-crank: crank r = 0.1 m at O, rod l = 0.35 m, slider on a horizontal guide
/// at height e = 0.02 m, crank at 30 degrees; torque on the crank, spring and friction on
/// the slider.
pub const SLIDER_CRANK: &str = r#"
name: slider-crank
gravity: [0, -9.81]
points:
  O: [0, 0]
  A: [0.08660254037844387, 0.05]
  B: [0.43531445586169776, 0.02]
  G: [0.0, 0.02]
ground: [O, G]
bodies:
  crank: {points: [O, A], uniform_bar: [O, A], mass: 0.3}
  rod: {points: [A, B], uniform_bar: [A, B], mass: 0.6}
  slider: {points: [B], mass: 0.5, inertia: 0.001, com: B}
pairs:
  - {type: revolute, name: O, at: O, bodies: [ground, crank]}
  - {type: revolute, at: A, bodies: [crank, rod]}
  - {type: revolute, at: B, bodies: [rod, slider]}
  - {type: prismatic, name: guide, at: B, bodies: [ground, slider], axis: [1, 0]}
coordinates:
  - {name: phi, pair: O, value: 0.5235987755982988, qd0: 3.0}
drives:
  - {coordinate: phi, effort: 0.4}
loads:
  - {type: friction, pair: guide, viscous: 0.2}
  - {type: spring, between: [[slider, B], [ground, G]], stiffness: 30.0, rest_length: 0.35, damping: 0.1}
"#;

/// A boom lifted by a hydraulic cylinder: the input is the cylinder extension, a prismatic
/// pair between two mobile bodies (barrel -> rod).
pub const BOOM: &str = r#"
name: boom with cylinder
gravity: [0, -9.81]
points:
  O: [0, 0]
  A: [0.3, -0.2]
  B: [0.6, 0.3]
  C: [0.45, 0.05]
  T: [1.5, 0.6]
ground: [O, A]
bodies:
  boom: {points: [O, T, B], uniform_bar: [O, T], mass: 8.0}
  barrel: {points: [A, C], uniform_bar: [A, C], mass: 2.0}
  rod: {points: [C, B], uniform_bar: [C, B], mass: 1.0}
pairs:
  - {type: revolute, at: O, bodies: [ground, boom]}
  - {type: revolute, at: A, bodies: [ground, barrel]}
  - {type: prismatic, name: cyl, at: C, bodies: [barrel, rod], along: [A, B]}
  - {type: revolute, at: B, bodies: [rod, boom]}
coordinates:
  - {name: s, pair: cyl, value: 0.0, qd0: 0.05}
drives:
  - {coordinate: s, effort: 250.0}
"#;

/// Symmetric 3-RRR parallel robot: base radius 0.5 m, platform radius 0.1 m, proximal and
/// distal links 0.3 m (uniform bars, 1 kg/m), a 0.5 kg platform; inputs the base angles.
pub const RRR3: &str = r#"
name: 3-RRR
gravity: [0, 0]
points:
  A1: [3.061616997868383e-17, 0.5]
  B1: [-0.2236067977499789, 0.3]
  C1: [6.123233995736766e-18, 0.1]
  A2: [-0.4330127018922194, -0.24999999999999986]
  B2: [-0.1480042222603422, -0.34364916731037076]
  C2: [-0.08660254037844389, -0.049999999999999975]
  A3: [0.4330127018922192, -0.2500000000000002]
  B3: [0.3716110200103211, 0.043649167310370635]
  C3: [0.08660254037844384, -0.050000000000000044]
  P: [0.0, 0.0]
ground: [A1, A2, A3]
bodies:
  prox1: {points: [A1, B1], uniform_bar: [A1, B1], mass: 0.3}
  dist1: {points: [B1, C1], uniform_bar: [B1, C1], mass: 0.3}
  prox2: {points: [A2, B2], uniform_bar: [A2, B2], mass: 0.3}
  dist2: {points: [B2, C2], uniform_bar: [B2, C2], mass: 0.3}
  prox3: {points: [A3, B3], uniform_bar: [A3, B3], mass: 0.3}
  dist3: {points: [B3, C3], uniform_bar: [B3, C3], mass: 0.3}
  platform: {points: [P, C1, C2, C3], mass: 0.5, inertia: 0.0025, com: P}
pairs:
  - {type: revolute, name: R1, at: A1, bodies: [ground, prox1]}
  - {type: revolute, at: B1, bodies: [prox1, dist1]}
  - {type: revolute, at: C1, bodies: [dist1, platform]}
  - {type: revolute, name: R2, at: A2, bodies: [ground, prox2]}
  - {type: revolute, at: B2, bodies: [prox2, dist2]}
  - {type: revolute, at: C2, bodies: [dist2, platform]}
  - {type: revolute, name: R3, at: A3, bodies: [ground, prox3]}
  - {type: revolute, at: B3, bodies: [prox3, dist3]}
  - {type: revolute, at: C3, bodies: [dist3, platform]}
coordinates:
  - {name: th1, pair: R1, value: -2.4118649973628266}
  - {name: th2, pair: R2, value: -0.31746989496963157}
  - {name: th3, pair: R3, value: 1.7769252074235635}
drives:
  - {coordinate: th1, effort: 0.2}
  - {coordinate: th2, table: {t: [0, 0.5, 1], effort: [0, -0.3, 0.1]}}
"#;

/// The 5R of tests/data/benchmarks/five-bar-free-fall.json.
pub const FIVE_BAR_FALL: &str = r#"
name: five-bar free fall
gravity: [0.0, -9.81]
points:
  A1: [-0.1, 0.0]
  A2: [0.1, 0.0]
  C1: [-0.2, 0.17320508075688773]
  C2: [0.2, 0.17320508075688773]
  P: [0.0, 0.32320508075688775]
ground: [A1, A2]
bodies:
  proximal_left: {points: [A1, C1], mass: 0.2, inertia: 0.0006666666666666669, com: [-0.15000000000000002, 0.08660254037844387]}
  proximal_right: {points: [A2, C2], mass: 0.2, inertia: 0.0006666666666666669, com: [0.15000000000000002, 0.08660254037844387]}
  distal_left:
    points: [C1, P]
    parts:
      - {uniform_bar: [C1, P], mass: 0.25}
      - {point_mass: P, mass: 0.1}
  distal_right: {points: [C2, P], mass: 0.25, inertia: 0.0013020833333333333, com: [0.1, 0.24820508075688774]}
pairs:
  - {type: revolute, name: A1, at: A1, bodies: [ground, proximal_left]}
  - {type: revolute, at: C1, bodies: [proximal_left, distal_left]}
  - {type: revolute, at: P, bodies: [distal_left, distal_right]}
  - {type: revolute, at: C2, bodies: [distal_right, proximal_right]}
  - {type: revolute, name: A2, at: A2, bodies: [ground, proximal_right]}
coordinates:
  - {name: theta1, pair: A1, value: 2.0943951023931953}
  - {name: theta2, pair: A2, value: 1.0471975511965976}
"#;

/// All inline models with their names, for tests that run on every mechanism.
pub fn all_models() -> Vec<Mechanism> {
    [PENDULUM, FOUR_BAR, SLIDER_CRANK, BOOM, RRR3, FIVE_BAR_FALL].iter().map(|s| yaml(s)).collect()
}

/// A state away from the drawing for each model: q0 + 0.1 (m or rad scaled) and some rates.
pub fn test_state(mech: &Mechanism) -> (Vec<f64>, Vec<f64>) {
    let (q0, _) = mech.initial_state();
    let q = q0.iter().enumerate().map(|(k, v)| v + 0.05 * (k as f64 + 1.0)).collect();
    let qd = (0..q0.len()).map(|k| 0.7 - 0.4 * k as f64).collect();
    (q, qd)
}

/// A shipped model file from examples/models.
pub fn shipped(name: &str) -> Mechanism {
    let path = format!("{}/../../examples/models/{name}", env!("CARGO_MANIFEST_DIR"));
    planardyn::load(&path).unwrap_or_else(|e| panic!("{e}"))
}

/// Simulate with the model's drives, tight tolerances, and optional output times.
pub fn run(
    mech: &Mechanism,
    method: &str,
    t_end: f64,
    rtol: f64,
    t_eval: Option<Vec<f64>>,
) -> planardyn::simulate::Trajectory {
    let mut s = planardyn::simulate::Settings::for_model(mech).unwrap();
    s.method = method.parse().unwrap();
    s.t_end = t_end;
    s.options.rtol = rtol;
    s.options.atol = rtol * 1e-2;
    s.t_eval = t_eval;
    let tr = planardyn::simulate::simulate(mech, &s, &mut planardyn::dynamics::ModelDrives(mech), None).unwrap();
    assert!(tr.success(), "{}: {:?} {}", mech.name, tr.status, tr.message);
    tr
}

/// Three parallel cranks on one coupler: one redundant constraint (a self-stress).
pub const PARALLELOGRAM: &str = r#"
name: triple-crank parallelogram
gravity: [0, -9.81]
points:
  O1: [0, 0]
  O2: [0.5, 0]
  O3: [1.0, 0]
  A: [0.15, 0.2598076211353316]
  B: [0.65, 0.2598076211353316]
  C: [1.15, 0.2598076211353316]
ground: [O1, O2, O3]
bodies:
  crank1: {points: [O1, A], uniform_bar: [O1, A], mass: 0.3}
  crank2: {points: [O2, B], uniform_bar: [O2, B], mass: 0.3}
  crank3: {points: [O3, C], uniform_bar: [O3, C], mass: 0.3}
  coupler: {points: [A, C, B], uniform_bar: [A, C], mass: 1.0}
pairs:
  - {type: revolute, name: O1, at: O1, bodies: [ground, crank1]}
  - {type: revolute, name: O2, at: O2, bodies: [ground, crank2]}
  - {type: revolute, name: O3, at: O3, bodies: [ground, crank3]}
  - {type: revolute, name: A, at: A, bodies: [crank1, coupler]}
  - {type: revolute, name: B, at: B, bodies: [crank2, coupler]}
  - {type: revolute, name: C, at: C, bodies: [crank3, coupler]}
coordinates:
  - {name: theta, pair: O1, value: 1.0471975511965976}
"#;

/// Arithmetic-geometric mean, for the complete elliptic integral K(k) = pi / (2 agm(1, k')).
pub fn agm(mut a: f64, mut b: f64) -> f64 {
    // Quadratic convergence: 8 iterations reach round-off from any k' in (0, 1].
    for _ in 0..8 {
        (a, b) = ((a + b) / 2.0, (a * b).sqrt());
    }
    a
}

/// Every shipped model file (examples/models and its library) and the inline models.
pub fn every_model() -> Vec<Mechanism> {
    let dir = format!("{}/../../examples/models", env!("CARGO_MANIFEST_DIR"));
    let mut names: Vec<String> = std::fs::read_dir(&dir)
        .unwrap()
        .chain(std::fs::read_dir(format!("{dir}/library")).unwrap())
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|x| x == "yaml"))
        .map(|p| p.strip_prefix(&dir).unwrap().to_string_lossy().trim_start_matches('/').to_string())
        .collect();
    names.sort();
    assert!(names.len() >= 20, "{names:?}");
    names.iter().map(|n| shipped(n)).chain(all_models()).collect()
}

/// The offset slider-crank of [`SLIDER_CRANK`] without dissipation (its spring undamped),
/// for prescribed motions: named pins O, A, B and guide, `rider` a body on a guide `ride` of
/// the slider (or nothing), and `rest` the loads after its spring, the coordinates and the
/// drives.
pub fn slider_crank_at_speed(rest: &str, rider: bool) -> Mechanism {
    let (body, pair) = if rider {
        (
            "  rider: {points: [C], mass: 0.2, inertia: 0.0005, com: C}\n",
            "  - {type: prismatic, name: ride, at: C, bodies: [slider, rider], axis: [1, 0]}\n",
        )
    } else {
        ("", "")
    };
    yaml(&format!(
        r#"
name: slider-crank at constant speed
gravity: [0, -9.81]
points:
  O: [0, 0]
  A: [0.08660254037844387, 0.05]
  B: [0.43531445586169776, 0.02]
  G: [0.0, 0.02]
  C: [0.53531445586169776, 0.02]
ground: [O, G]
bodies:
  crank: {{points: [O, A], uniform_bar: [O, A], mass: 0.3}}
  rod: {{points: [A, B], uniform_bar: [A, B], mass: 0.6}}
  slider: {{points: [B], mass: 0.5, inertia: 0.001, com: B}}
{body}pairs:
  - {{type: revolute, name: O, at: O, bodies: [ground, crank]}}
  - {{type: revolute, name: A, at: A, bodies: [crank, rod]}}
  - {{type: revolute, name: B, at: B, bodies: [rod, slider]}}
  - {{type: prismatic, name: guide, at: B, bodies: [ground, slider], axis: [1, 0]}}
{pair}loads:
  - {{type: spring, between: [[slider, B], [ground, G]], stiffness: 30.0, rest_length: 0.35}}
{rest}"#
    ))
}

/// A point of [`power_balance_along`]: its index and time, the rate and acceleration, the
/// drive powers with and without the losses, and the workspace of the model with them.
pub struct Swept<'w> {
    pub k: usize,
    pub t: f64,
    pub qd: f64,
    pub qdd: f64,
    pub p: f64,
    pub p0: f64,
    pub ws: &'w planardyn::Workspace,
}

/// Inverse dynamics of a one-coordinate model with losses (`with`) and without (`without`)
/// along q(t) = q0 + w t + a sin(f t), at t = k / n for k = 0..=n. At every point the drive
/// power is the lossless one plus the dissipated power, by the principle of virtual power (the
/// same motion, the same dT/dt + dV/dt), within rtol * max(|p|, floor); `each` checks the rest.
pub fn power_balance_along(
    with: &Mechanism,
    without: &Mechanism,
    [q0, w, a, f]: [f64; 4],
    n: usize,
    (rtol, floor): (f64, f64),
    mut each: impl FnMut(Swept),
) {
    use planardyn::{dynamics::inverse, Workspace};
    let (mut ws, mut ws0) = (Workspace::new(with), Workspace::new(without));
    for k in 0..=n {
        let t = k as f64 / n as f64;
        let q = q0 + w * t + a * (f * t).sin();
        let qd = w + a * f * (f * t).cos();
        let qdd = -a * f * f * (f * t).sin();
        inverse(with, &[q], &[qd], &[qdd], &mut ws).unwrap();
        inverse(without, &[q], &[qd], &[qdd], &mut ws0).unwrap();
        let (p, p0) = (ws.tau[0] * qd, ws0.tau[0] * qd);
        assert!((p - p0 - ws.dissipated).abs() <= rtol * p.abs().max(floor), "t {t}: {p} {p0} {}", ws.dissipated);
        each(Swept { k, t, qd, qdd, p, p0, ws: &ws });
    }
}

/// The harmonic oscillator y'' = -y as y = (y, y') (the integrators' tests).
pub struct Oscillator;

impl OdeSystem for Oscillator {
    type Error = Infallible;
    fn dim(&self) -> usize {
        2
    }
    fn rhs(&mut self, _t: f64, y: &[f64], dy: &mut [f64]) -> Result<(), Infallible> {
        dy[0] = y[1];
        dy[1] = -y[0];
        Ok(())
    }
}
