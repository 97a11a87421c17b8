//! The closed-form kinematics of the user's chart (`kinematics::closed_form`) against the
//! general path (Newton on the block-triangular J, then U and c by solves with its factors), on
//! every shipped model that has one, at random configurations and rates: positions, U, xd, c,
//! A and zdd must agree to round-off, and the type II measure from the closed forms with the
//! SVD of J's blocks.
//!
//! Tolerance: the general path stops Newton at a scaled residual of 1e-14 and polishes it to
//! round-off, so its x is exact to about 1e-14 / sigma (sigma the type II measure, >= 0.05 where
//! the integrator uses the user's chart, [`MIN_SIGMA`]); U, c and A inherit that relative error,
//! amplified once more by 1/sigma. The measured worst differences over these models and states are quoted
//! with the bounds (printed with --nocapture).

use planardyn::dynamics::{dynamic_stages, forward, mass_matrix, ModelDrives};
use planardyn::kinematics::{assemble_from, assemble_into, sigma_min, velocity_analogues, Chart, ClosedForm};
use planardyn::model::CoordinateKind;
use planardyn::{KinematicsError, Mechanism, Workspace};
use std::path::{Path, PathBuf};

mod common;

/// Positions (scaled: lengths / L, angles in rad). Measured worst: 2.4e-13 (Watt six-bar).
const X_TOL: f64 = 1e-11;
/// U, xd, c, A, qdd, xdd relative to the largest entry of each. Measured worst: 1e-13 for U,
/// xd, c and A; 1.4e-11 for qdd (the four-bar under gravity, where b = U^T (f - M c) is a
/// difference of terms up to 10 times larger than itself).
const REL_TOL: f64 = 1e-10;
/// The type II measure from the closed forms against the SVD of each block of J
/// (`sigma_min`), relative: both are exact to round-off, about 1e-16 / sigma relative with
/// sigma >= 0.05 here.
const SIGMA_TOL: f64 = 1e-10;
/// The states compared: those where the integrator uses the user's chart.
const MIN_SIGMA: f64 = 0.05;
/// The Stephenson six-bar's triad measures 0.023 to 0.039 within 0.3 rad of the drawing, so
/// the integrator never takes its closed forms (they need 0.1); they are compared there, at
/// sigma >= 0.02, with the same tolerances.
const STEPHENSON_MIN_SIGMA: f64 = 0.02;

fn model_files(dir: &Path) -> Vec<PathBuf> {
    let mut out = Vec::new();
    for sub in [dir.to_path_buf(), dir.join("library")] {
        for e in std::fs::read_dir(&sub).unwrap() {
            let p = e.unwrap().path();
            if p.extension().is_some_and(|x| x == "yaml") {
                out.push(p);
            }
        }
    }
    out.sort();
    out
}

fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

/// Name relative to the models directory, e.g. `library/four-bar`.
fn name(dir: &Path, p: &Path) -> String {
    p.strip_prefix(dir).unwrap().with_extension("").to_string_lossy().into_owned()
}

/// xorshift64*: reproducible uniform numbers in [0, 1).
struct Rng(u64);
impl Rng {
    fn next(&mut self) -> f64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        (self.0.wrapping_mul(0x2545_f491_4f6c_dd1d) >> 11) as f64 / (1u64 << 53) as f64
    }
}

fn max_abs(v: &[f64]) -> f64 {
    v.iter().fold(0.0, |m: f64, x| m.max(x.abs()))
}

/// Largest difference relative to the largest entry of `a`.
fn rel_diff(a: &[f64], b: &[f64]) -> f64 {
    let d = a.iter().zip(b).fold(0.0, |m: f64, (x, y)| m.max((x - y).abs()));
    d / max_abs(a).max(f64::MIN_POSITIVE)
}

#[test]
fn shipped_models_with_closed_forms() {
    let (examples, package) = (root().join("examples/models"), root().join("python/planardyn/models"));
    let files = model_files(&examples);
    // The package ships the same files: what holds for one list holds for the other.
    let package_files = model_files(&package);
    assert_eq!(files.iter().map(|p| name(&examples, p)).collect::<Vec<_>>(), {
        package_files.iter().map(|p| name(&package, p)).collect::<Vec<_>>()
    });
    for (a, b) in files.iter().zip(&package_files) {
        assert_eq!(std::fs::read(a).unwrap(), std::fs::read(b).unwrap(), "{}", a.display());
    }
    let closed: Vec<String> = files
        .iter()
        .filter(|p| ClosedForm::new(&planardyn::load(p.to_str().unwrap()).unwrap()).is_some())
        .map(|p| name(&examples, p))
        .collect();
    // The other, the double parallelogram, has redundant pairs: it takes the general path, as
    // would sliders carrying the ground's point on their guide, RPP dyads and cylinders whose
    // rod does not hold the group's inner pair.
    assert_eq!(closed, CLOSED);
}

/// The shipped models made of input links (revolute, or sliders on the ground), class I groups
/// with a gear or slot pair (1R1G, 1P1G, 1P1S), RRR and RRP dyads and 6R triads only, the RRR
/// dyads' links and the triads' legs possibly cylinders (two bodies and a relative prismatic
/// input: the hydraulic boom, the 3-RPR).
const CLOSED: [&str; 22] = [
    "3-rrr",
    "andrews-squeezer",
    "five-bar-compliant",
    "five-bar-free-fall",
    "five-bar-robot",
    "five-bar",
    "four-bar-gravity",
    "gear-train",
    "geared-five-bar",
    "hydraulic-boom",
    "library/3-prr",
    "library/3-rpr",
    "library/3-rrr",
    "library/biglide",
    "library/five-bar-5r",
    "library/four-bar",
    "library/slider-crank-slider-driven",
    "library/slider-crank",
    "library/stephenson-six-bar",
    "library/watt-six-bar",
    "scotch-yoke",
    "slider-crank",
];

/// The general path's forward dynamics at (q, qd) from the drawing, and the same with the
/// closed forms on the general solution's branches; A is left in `ws.a` (not its factor).
fn both(
    mech: &Mechanism,
    cf: &mut ClosedForm,
    q: &[f64],
    qd: &[f64],
    min_sigma: f64,
) -> Option<(Workspace, Workspace)> {
    let mut drives = ModelDrives(mech);
    let mut general = Workspace::new(mech);
    assemble_into(mech, q, &mut general).ok()?;
    if sigma_min(mech, &Chart::Inputs, &general.x) < min_sigma {
        return None; // the integrator leaves the user's chart there
    }
    forward(mech, 0.0, q, qd, &mut drives, &mut general).unwrap();
    cf.set_reference(&general.x);
    let mut closed = Workspace::new(mech);
    cf.kinematic_stages(q, qd, &mut closed).unwrap();
    if !mech.friction.is_empty() {
        // The pairs' friction needs the reactions, solved with J at this point (as the
        // simulation's closed-form evaluations factor it: simulate::ode).
        let ws = &mut closed.frame;
        ws.sys.factor(mech, &ws.chart, &ws.x, &ws.trig).unwrap();
    }
    dynamic_stages(mech, 0.0, &mut drives, &mut closed).unwrap();
    for ws in [&mut general, &mut closed] {
        mass_matrix(mech, ws);
    }
    Some((general, closed))
}

#[test]
fn equals_the_general_path_at_random_states() {
    let dir = root().join("examples/models");
    let mut rng = Rng(0x9e37_79b9_7f4a_7c15);
    for model in CLOSED {
        let mech = planardyn::load(dir.join(format!("{model}.yaml")).to_str().unwrap()).unwrap();
        let min_sigma = if model == "library/stephenson-six-bar" { STEPHENSON_MIN_SIGMA } else { MIN_SIGMA };
        compare(model, &mech, &mut rng, min_sigma);
    }
}

/// An RRP dyad whose guide turns: a rod hinged to crank 1 at A and to a slider at P, the
/// slider on a guide through P of arm 2 (both turned about the ground by the inputs). `{ab}`
/// orders the prismatic pair's bodies: the guide fixed in arm 2 (arm first) or in the slider.
const TURNING_GUIDE: &str = "name: turning guide\ngravity: [0, -9.81]\n\
points: {O1: [0, 0], A: [0.1, 0.15], P: [0.55, 0.45], O2: [0.5, 0]}\nground: [O1, O2]\nbodies:\n  \
crank: {points: [O1, A], uniform_bar: [O1, A], mass: 1.0}\n  \
rod: {points: [A, P], uniform_bar: [A, P], mass: 0.5}\n  \
slider: {points: [P], mass: 0.3, inertia: 1.0e-3, com: P}\n  \
arm: {points: [O2, P], uniform_bar: [O2, P], mass: 0.8}\npairs:\n  \
- {type: revolute, name: crank_pivot, at: O1, bodies: [ground, crank]}\n  \
- {type: revolute, name: arm_pivot, at: O2, bodies: [ground, arm]}\n  \
- {type: revolute, at: A, bodies: [crank, rod]}\n  \
- {type: revolute, at: P, bodies: [rod, slider]}\n  \
- {type: prismatic, at: P, bodies: {ab}, axis: [0.1, 0.9]}\n\
coordinates:\n  - {name: theta, pair: crank_pivot, value: 0.98}\n  - {name: beta, pair: arm_pivot, value: 2.1}\n";

#[test]
fn rrp_on_a_turning_guide_either_way() {
    let mut rng = Rng(0x2545_f491_4f6c_dd1d);
    for (what, ab) in [("guide on the arm", "[arm, slider]"), ("guide on the slider", "[slider, arm]")] {
        let mech = common::yaml(&TURNING_GUIDE.replace("{ab}", ab));
        compare(what, &mech, &mut rng, MIN_SIGMA);
    }
}

/// A rack driven along a ground guide turning a pinion on a ground pivot (the pinion a 1R1G
/// group meshing with the solved rack), and a slotted crank moving a pin on a ground guide (the
/// pin a 1P1S group in the solved slot): the roles of gear-train's rack and scotch-yoke's yoke
/// turned around.
const RACK_DRIVEN: &str = "name: rack-driven pinion\ngravity: [0, -9.81]\n\
points: {O: [0, 0], T: [0, 0.03], R1: [-0.1, -0.03], R2: [0.1, -0.03]}\nground: [O]\nbodies:\n  \
pinion: {points: [O, T], mass: 0.2, com: [0.004, 0.002], inertia: 1.0e-4}\n  \
rack: {points: [R1, R2], uniform_bar: [R1, R2], mass: 0.3}\npairs:\n  \
- {type: revolute, name: shaft, at: O, bodies: [ground, pinion]}\n  \
- {type: prismatic, name: guide, at: R1, bodies: [ground, rack], axis: [1.0, 0.0]}\n  \
- {type: gear, name: mesh, bodies: [pinion, rack], centers: [O], radii: [0.03], rack: [R1, R2]}\n\
coordinates:\n  - {name: s, pair: guide, value: 0.0}\n";

const SLOTTED_CRANK: &str = "name: slotted crank\ngravity: [0, -9.81]\n\
points: {O: [0, 0], E: [0.3, 0.3], P: [0.1, 0.1], G: [-0.2, 0.1]}\nground: [O]\nbodies:\n  \
crank: {points: [O, E], uniform_bar: [O, E], mass: 1.0}\n  \
pin: {points: [P, G], mass: 0.4, com: [0.12, 0.1], inertia: 2.0e-3}\npairs:\n  \
- {type: revolute, name: pivot, at: O, bodies: [ground, crank]}\n  \
- {type: slot, name: slot, at: P, bodies: [crank, pin], along: [O, E]}\n  \
- {type: prismatic, name: guide, at: G, bodies: [ground, pin], axis: [1.0, 0.0]}\n\
coordinates:\n  - {name: theta, pair: pivot, value: 0.7853981633974483}\n";

#[test]
fn class_one_groups_with_the_roles_turned_around() {
    let mut rng = Rng(0x5851_f42d_4c95_7f2d);
    for (what, text) in [("rack-driven pinion", RACK_DRIVEN), ("slotted crank", SLOTTED_CRANK)] {
        compare(what, &common::yaml(text), &mut rng, MIN_SIGMA);
    }
}

/// A PRP dyad: slider 1 on a guide through P fixed in the crank, slider 2 on a ground guide
/// through P, the two hinged at P. `{ab}` orders the crank's prismatic pair: the guide fixed
/// in the crank (crank first) or in slider 1.
const CROSSED_GUIDES: &str = "name: crossed guides\ngravity: [0, -9.81]\n\
points: {O: [0, 0], A: [0.2, 0.1], P: [0.5, 0.3]}\nground: [O]\nbodies:\n  \
crank: {points: [O, A, P], uniform_bar: [O, A], mass: 1.0}\n  \
slider1: {points: [P], mass: 0.3, inertia: 1.0e-3, com: P}\n  \
slider2: {points: [P], mass: 0.4, inertia: 2.0e-3, com: P}\npairs:\n  \
- {type: revolute, name: pivot, at: O, bodies: [ground, crank]}\n  \
- {type: prismatic, at: P, bodies: {ab}, axis: [0.8, 0.6]}\n  \
- {type: prismatic, at: P, bodies: [ground, slider2], axis: [0.1, 1.0]}\n  \
- {type: revolute, at: P, bodies: [slider1, slider2]}\n\
coordinates:\n  - {name: theta, pair: pivot, value: 0.4636476090008061}\n";

/// An RPR dyad (an oscillating cylinder): a rod hinged to the crank at A sliding in a cylinder
/// pivoted on the ground at B, along a guide through C off the line AB (its offset from A
/// 0.144 m, |AB| 0.42 to 0.78 m). `{ab}` orders the prismatic pair: the guide fixed in the
/// rod (rod first) or in the cylinder.
const OSCILLATING_CYLINDER: &str = "name: oscillating cylinder\ngravity: [0, -9.81]\n\
points: {O: [0, 0], A: [0.15, 0.1], B: [0.6, 0.0], C: [0.35, 0.12]}\nground: [O, B]\nbodies:\n  \
crank: {points: [O, A], uniform_bar: [O, A], mass: 1.0}\n  \
rod: {points: [A, C], uniform_bar: [A, C], mass: 0.5}\n  \
cylinder: {points: [B, C], uniform_bar: [B, C], mass: 0.8}\npairs:\n  \
- {type: revolute, name: pivot, at: O, bodies: [ground, crank]}\n  \
- {type: revolute, at: A, bodies: [crank, rod]}\n  \
- {type: revolute, at: B, bodies: [ground, cylinder]}\n  \
- {type: prismatic, at: C, bodies: {ab}, axis: [1.0, 0.1]}\n\
coordinates:\n  - {name: theta, pair: pivot, value: 0.5880026035475675}\n";

#[test]
fn prp_and_rpr_dyads_either_way() {
    let mut rng = Rng(0x2f69_3a0c_81d4_b5e7);
    for (what, text, ab) in [
        ("PRP, guide in the crank", CROSSED_GUIDES, "[crank, slider1]"),
        ("PRP, guide in the slider", CROSSED_GUIDES, "[slider1, crank]"),
        ("RPR, guide in the rod", OSCILLATING_CYLINDER, "[rod, cylinder]"),
        ("RPR, guide in the cylinder", OSCILLATING_CYLINDER, "[cylinder, rod]"),
    ] {
        let mech = common::yaml(&text.replace("{ab}", ab));
        let kinds: Vec<String> =
            planardyn::structure::analyse(&mech, &mech.x0).unwrap().groups.into_iter().map(|g| g.kind).collect();
        assert_eq!(kinds, [&what[..3]], "{what}");
        compare(what, &mech, &mut rng, MIN_SIGMA);
    }
}

#[test]
fn an_rpr_dyad_keeps_the_side_of_its_reference() {
    // The rod owns the guide, direction u (drawn (1, 0.1)); B sits ahead of A's foot on the
    // guide, u . (B - A) > 0. Near the drawing the closed form lands where Newton from the
    // drawing does. The fold is where u stands normal to A -> B: the rod turned about A by
    // beta0 + pi/2, beta0 the angle from u to A -> B. A predictor just short of it keeps the
    // side, one just past it does not.
    let mech = common::yaml(&OSCILLATING_CYLINDER.replace("{ab}", "[rod, cylinder]"));
    let mut cf = ClosedForm::new(&mech).unwrap();
    cf.set_reference(&mech.x0);
    let (q0, qd0) = mech.initial_state();
    let q1: Vec<f64> = q0.iter().map(|v| v + 0.05).collect();
    let mut ws = Workspace::new(&mech);
    cf.kinematic_stages(&q1, &qd0, &mut ws).unwrap();
    let mut general = Workspace::new(&mech);
    assemble_into(&mech, &q1, &mut general).unwrap();
    let d = ws.x.iter().zip(&general.x).fold(0.0_f64, |m, (a, b)| m.max((a - b).abs()));
    assert!(d < 1e-12, "closed form and Newton differ by {d:e}");
    let rod = mech.bodies.iter().position(|b| b.name == "rod").unwrap();
    let a = [0.15, 0.1];
    let beta0 = (-0.1_f64).atan2(0.45) - 0.1_f64.atan2(1.0);
    // The rod turned about A by delta.
    let turned = |delta: f64| {
        let mut x = mech.x0.clone();
        let phi = x[3 * rod + 2];
        let (r, (s0, c0)) = ([a[0] - x[3 * rod], a[1] - x[3 * rod + 1]], phi.sin_cos());
        let s = [c0 * r[0] + s0 * r[1], -s0 * r[0] + c0 * r[1]];
        let (s1, c1) = (phi + delta).sin_cos();
        x[3 * rod] = a[0] - (c1 * s[0] - s1 * s[1]);
        x[3 * rod + 1] = a[1] - (s1 * s[0] + c1 * s[1]);
        x[3 * rod + 2] = phi + delta;
        x
    };
    let fold = beta0 + 0.5 * std::f64::consts::PI;
    assert!(cf.keeps_branches(&mech.x0));
    assert!(cf.keeps_branches(&turned(fold - 1e-3)));
    assert!(!cf.keeps_branches(&turned(fold + 1e-3)));
    assert!(!cf.keeps_branches(&turned(fold - 1e-3 - std::f64::consts::PI)));
}

/// At 60 random states about the drawing that assemble clear of singularities (of at most 240
/// drawn; the parallel robots reach about half of them): the closed forms against the general
/// path.
fn compare(model: &str, mech: &Mechanism, rng: &mut Rng, min_sigma: f64) {
    let mut cf = ClosedForm::new(mech).unwrap();
    let (q0, _) = mech.initial_state();
    // Angles within 0.6 rad of the drawing's, displacements within 0.1 L.
    let span: Vec<f64> =
        mech.coordinates.iter().map(|c| if c.kind == CoordinateKind::Angle { 1.2 } else { 0.2 * mech.scale }).collect();
    let (mut compared, mut worst) = (0, [0.0_f64; 8]);
    for _ in 0..240 {
        if compared == 60 {
            break;
        }
        let q: Vec<f64> = q0.iter().zip(&span).map(|(v, s)| v + s * (rng.next() - 0.5)).collect();
        let qd: Vec<f64> = q0.iter().map(|_| 6.0 * (rng.next() - 0.5)).collect();
        let Some((g, c)) = both(mech, &mut cf, &q, &qd, min_sigma) else { continue };
        compared += 1;
        let dx =
            g.x.iter()
                .zip(&c.x)
                .enumerate()
                .fold(0.0_f64, |m, (i, (a, b))| m.max((a - b).abs() / if i % 3 == 2 { 1.0 } else { mech.scale }));
        let figures = [dx, rel_diff(&g.u, &c.u), rel_diff(&g.xd, &c.xd), rel_diff(&g.c, &c.c), rel_diff(&g.a, &c.a)];
        let sigma = sigma_min(mech, &Chart::Inputs, &g.x);
        let more = [rel_diff(&g.qdd, &c.qdd), rel_diff(&g.xdd, &c.xdd), (cf.sigma() - sigma).abs() / sigma];
        for (w, f) in worst.iter_mut().zip(figures.iter().chain(&more)) {
            *w = w.max(*f);
        }
        assert_eq!((c.q.as_slice(), c.qd.as_slice()), (q.as_slice(), qd.as_slice()));
    }
    eprintln!(
        "{model}: {compared} states; worst x, U, xd, c, A, qdd, xdd, sigma: {:?}",
        worst.map(|w| format!("{w:.1e}"))
    );
    assert!(compared >= 30, "{model}: only {compared} of 240 random states assembled clear of singularities");
    assert!(worst[0] < X_TOL, "{model}: positions differ by {:e} (scaled)", worst[0]);
    for (what, w) in ["U", "xd", "c", "A", "qdd", "xdd"].iter().zip(&worst[1..7]) {
        assert!(*w < REL_TOL, "{model}: {what} differs by {w:e} relative");
    }
    assert!(worst[7] < SIGMA_TOL, "{model}: the type II measure differs by {:e} relative", worst[7]);
}

#[test]
fn keeps_the_branch_of_its_reference() {
    // The five-bar's dyad on its other branch: P mirrored in the line AB. From either
    // reference the closed form stays on that reference's branch at a nearby q.
    let mech = planardyn::load(root().join("examples/models/five-bar.yaml").to_str().unwrap()).unwrap();
    let mut cf = ClosedForm::new(&mech).unwrap();
    let (q0, qd0) = mech.initial_state();
    let mut ws = Workspace::new(&mech);
    cf.set_reference(&mech.x0);
    cf.kinematic_stages(&q0, &qd0, &mut ws).unwrap();
    let here = ws.x.clone();
    let q1: Vec<f64> = q0.iter().map(|v| v + 0.02).collect();
    cf.kinematic_stages(&q1, &qd0, &mut ws).unwrap();
    let near = ws.x.clone();
    // Newton from the drawing's branch lands on the same solution.
    let mut general = Workspace::new(&mech);
    assemble_into(&mech, &q1, &mut general).unwrap();
    let d = near.iter().zip(&general.x).fold(0.0_f64, |m, (a, b)| m.max((a - b).abs()));
    assert!(d < 1e-12 * mech.scale.max(1.0), "closed form and Newton differ by {d:e}");
    assert!(near.iter().zip(&here).all(|(a, b)| (a - b).abs() < 0.1));
}

#[test]
fn reports_coordinates_where_a_dyad_does_not_assemble() {
    // Five-bar cranks turned apart until the dyad's two links cannot reach: no configuration,
    // the error a Newton solve that does not converge gives, never NaN positions.
    let mech = planardyn::load(root().join("examples/models/five-bar.yaml").to_str().unwrap()).unwrap();
    let mut cf = ClosedForm::new(&mech).unwrap();
    let mut ws = Workspace::new(&mech);
    let (q0, qd0) = mech.initial_state();
    let apart = [q0[0] + 1.5, q0[1] - 1.5];
    match cf.kinematic_stages(&apart, &qd0, &mut ws) {
        Err(KinematicsError::AssemblyFailed { residual, .. }) => assert!(residual > 0.0),
        other => panic!("expected AssemblyFailed, got {other:?}"),
    }
    assert!(assemble_into(&mech, &apart, &mut Workspace::new(&mech)).is_err());
}

/// One parallelogram of unit rods (A02 at N = 1): rods 0 and 1 hinged to the ground 1 m
/// apart, the coupler joining their tops; theta the first rod's angle from the ground.
const PARALLELOGRAM: &str = "name: parallelogram\ngravity: [0, -9.81]\n\
points: {O0: [0, 0], A0: [0, 1], O1: [1, 0], A1: [1, 1]}\nground: [O0, O1]\nbodies:\n  \
rod0: {points: [O0, A0], uniform_bar: [O0, A0], mass: 1.0}\n  \
rod1: {points: [O1, A1], uniform_bar: [O1, A1], mass: 1.0}\n  \
coupler1: {points: [A0, A1], uniform_bar: [A0, A1], mass: 1.0}\npairs:\n  \
- {type: revolute, name: ground_rod0, at: O0, bodies: [ground, rod0]}\n  \
- {type: revolute, name: ground_rod1, at: O1, bodies: [ground, rod1]}\n  \
- {type: revolute, at: A0, bodies: [rod0, coupler1]}\n  \
- {type: revolute, at: A1, bodies: [coupler1, rod1]}\n\
coordinates:\n  - {name: theta, pair: ground_rod0, value: 1.5707963267948966}\n";

#[test]
fn a_predictor_past_a_fold_is_recognised() {
    // On the parallelogram branch (every rod at angle theta, the coupler level) the dyad of the
    // coupler and rod 1 folds where the rods lie flat, theta = 0: its joint P crosses the line
    // from A (rod 0's top) to B (rod 1's pivot), A = B there. A predicted point on that branch
    // past theta = 0 is on the other side of the kept branch; one short of it is not.
    let mech = common::yaml(PARALLELOGRAM);
    let mut cf = ClosedForm::new(&mech).unwrap();
    let mut ws = Workspace::new(&mech);
    assemble_into(&mech, &[0.3], &mut ws).unwrap();
    cf.set_reference(&ws.x);
    assert!(cf.keeps_branches(&ws.x));
    let on_branch = |theta: f64| {
        let mut x = ws.x.clone();
        (x[2], x[5], x[8]) = (theta, theta, 0.0);
        x
    };
    assert!(cf.keeps_branches(&on_branch(1e-3)));
    assert!(!cf.keeps_branches(&on_branch(-1e-3)));
    // The closed form at -1e-3 keeps the side: P at the circles' other intersection, the
    // coupler turned over by about pi, which is why such a step takes Newton.
    cf.kinematic_stages(&[-1e-3], &[0.0], &mut ws).unwrap();
    assert!((ws.x[8].abs() - std::f64::consts::PI).abs() < 1e-2, "coupler angle {}", ws.x[8]);
}

#[test]
fn an_rrp_predictor_past_its_fold_is_recognised() {
    // The slider-crank's rod (body 1 of its RRP dyad) at direction alpha from the guide's axis
    // (x); its fold is where the rod stands normal to the guide (alpha = +-pi/2). A predicted
    // rod just past the normal, or mirrored about it (pi - alpha), puts the wrist behind the
    // crank pin along the guide; one just short of the normal does not.
    let mech = planardyn::load(root().join("examples/models/slider-crank.yaml").to_str().unwrap()).unwrap();
    let mut cf = ClosedForm::new(&mech).unwrap();
    cf.set_reference(&mech.x0);
    let rod = mech.bodies.iter().position(|b| b.name == "rod").unwrap();
    // The rod's direction A -> B in the drawing (A = (0.04, 0.0693), B = (0.3319, 0)).
    let alpha0 = (-0.06928203230275509_f64).atan2(0.33189039038652846 - 0.04);
    // The rod turned to direction alpha (its body angle moves with it).
    let turned = |alpha: f64| {
        let mut x = mech.x0.clone();
        x[3 * rod + 2] += alpha - alpha0;
        x
    };
    assert!(cf.keeps_branches(&mech.x0));
    let half = 0.5 * std::f64::consts::PI;
    assert!(cf.keeps_branches(&turned(-half + 1e-3)));
    assert!(!cf.keeps_branches(&turned(-half - 1e-3)));
    assert!(!cf.keeps_branches(&turned(std::f64::consts::PI - alpha0)));
}

#[test]
fn a_triad_keeps_the_branch_of_its_reference() {
    // The 3-RRR's platform has another assembly mode at the drawn inputs, turned by 1.28 rad
    // about its (unmoved) centre: Newton on the triad from the drawing's platform turned by
    // 1 rad lands on it. From a reference on either mode, the closed form at nearby inputs
    // stays on that mode: equal to the general path's Newton continued from it.
    let mech = planardyn::load(root().join("examples/models/3-rrr.yaml").to_str().unwrap()).unwrap();
    let platform = 3 * mech.bodies.iter().position(|b| b.name == "platform").unwrap();
    let mut cf = ClosedForm::new(&mech).unwrap();
    let (q0, qd0) = mech.initial_state();
    let mut ws = Workspace::new(&mech);
    let mut turned = mech.x0.clone();
    turned[platform + 2] += 1.0;
    cf.set_reference(&turned);
    cf.kinematic_stages(&q0, &qd0, &mut ws).unwrap();
    let other = ws.x.clone();
    let mut general = Workspace::new(&mech);
    assemble_from(&mech, &other, &q0, &mut general).unwrap();
    let d = other.iter().zip(&general.x).fold(0.0_f64, |m, (a, b)| m.max((a - b).abs()));
    assert!(d < 1e-12, "the other mode is not a solution: Newton moves it by {d:e}");
    assert!((other[platform + 2] - mech.x0[platform + 2] - 1.2810446253588).abs() < 1e-9, "{}", other[platform + 2]);
    let q1: Vec<f64> = q0.iter().map(|v| v + 0.02).collect();
    for reference in [&mech.x0, &other] {
        cf.set_reference(reference);
        cf.kinematic_stages(&q1, &qd0, &mut ws).unwrap();
        assemble_from(&mech, reference, &q1, &mut general).unwrap();
        let d = ws.x.iter().zip(&general.x).fold(0.0_f64, |m, (a, b)| m.max((a - b).abs()));
        assert!(d < 1e-12, "closed form and Newton differ by {d:e}");
        assert!(ws.x.iter().zip(reference).all(|(a, b)| (a - b).abs() < 0.1));
    }
}

#[test]
fn a_predictor_past_a_triads_singularity_is_recognised() {
    // The 3-RRR with every input turned by t from the drawing passes a type II singularity of
    // its triad near t = 0.84 (the distal links' lines meet in a point): the measure falls
    // from 0.033 at t = 0.75 to 0.003 at 0.85 and rises again. From the reference at 0.75,
    // the first-order predictor x + U dq to 0.78 keeps the side of the singularity, one to
    // 0.90 does not, nor does the solution the general path's continuation finds there.
    let mech = planardyn::load(root().join("examples/models/3-rrr.yaml").to_str().unwrap()).unwrap();
    let mut cf = ClosedForm::new(&mech).unwrap();
    let (q0, _) = mech.initial_state();
    let at = |t: f64| -> Workspace {
        let mut ws = Workspace::new(&mech);
        assemble_into(&mech, &q0.iter().map(|v| v + t).collect::<Vec<_>>(), &mut ws).unwrap();
        velocity_analogues(&mut ws).unwrap();
        ws
    };
    let (before, near, past) = (at(0.75), at(0.85), at(0.90));
    assert!(sigma_min(&mech, &Chart::Inputs, &near.x) < 0.01);
    cf.set_reference(&before.x);
    assert!(cf.keeps_branches(&before.x));
    let n = before.x.len();
    let predicted = |dt: f64| -> Vec<f64> {
        (0..n).map(|i| before.x[i] + dt * (0..3).map(|j| before.u[j * n + i]).sum::<f64>()).collect()
    };
    assert!(cf.keeps_branches(&predicted(0.03)));
    assert!(!cf.keeps_branches(&predicted(0.15)));
    assert!(!cf.keeps_branches(&past.x));
    // The closed-form measure there, 0.003, equals the block SVD's within 1e-8 relative: both
    // are exact to about 1e-16 / sigma^2 relative (the secular equation's M is lambda = sigma^2
    // from a singular point).
    cf.set_reference(&near.x);
    let mut ws = Workspace::new(&mech);
    cf.kinematic_stages(&q0.iter().map(|v| v + 0.85).collect::<Vec<_>>(), &[0.0; 3], &mut ws).unwrap();
    let sigma = sigma_min(&mech, &Chart::Inputs, &near.x);
    assert!((cf.sigma() - sigma).abs() < 1e-8 * sigma, "{} against {sigma}", cf.sigma());
}

/// A boom lifted by a cylinder whose rod is bent: the boom's eye R is off the guide's line
/// (G -> E), so the arm G -> R of the locked barrel + rod turns in the barrel's frame as the
/// input grows. `{ab}` orders the prismatic pair's bodies (the guide fixed in the barrel or in
/// the rod) and `{eye}` puts R on the rod (it slides with the input) or on the barrel (the rod
/// only rides along: its block in J is then its own, and the model takes the general path).
const BENT_CYLINDER: &str = "name: bent cylinder\ngravity: [0, -9.81]\n\
points: {O: [0, 0], R: [1.5, 0.4], G: [0.9, -0.5], E: [1.2, 0.1], K: [1.05, -0.2]}\nground: [O, G]\nbodies:\n  \
boom: {points: [O, R], uniform_bar: [O, R], mass: 5.0}\n  \
barrel: {points: [G, E, K, R], uniform_bar: [G, E], mass: 2.0}\n  \
rod: {points: [K, R], uniform_bar: [K, R], mass: 1.0}\npairs:\n  \
- {type: revolute, name: boom_pivot, at: O, bodies: [ground, boom]}\n  \
- {type: revolute, name: barrel_pivot, at: G, bodies: [ground, barrel]}\n  \
- {type: prismatic, name: cylinder, at: K, bodies: {ab}, axis: [0.3, 0.6]}\n  \
- {type: revolute, at: R, bodies: [{eye}, boom]}\n\
coordinates:\n  - {name: extension, pair: cylinder, value: 0.7}\n";

#[test]
fn relative_input_on_a_bent_cylinder_every_way() {
    let mut rng = Rng(0x1234_5678_9abc_def1);
    for ab in ["[barrel, rod]", "[rod, barrel]"] {
        let mech = common::yaml(&BENT_CYLINDER.replace("{ab}", ab).replace("{eye}", "rod"));
        compare(&format!("bent cylinder {ab}"), &mech, &mut rng, MIN_SIGMA);
        let riding = common::yaml(&BENT_CYLINDER.replace("{ab}", ab).replace("{eye}", "barrel"));
        assert!(ClosedForm::new(&riding).is_none());
    }
}

#[test]
fn triad_of_bent_cylinders() {
    // The 3-RPR with its guides turned off the legs' lines A_i -> C_i (0.3, -0.2 and 0.25 rad):
    // each wrist C_i then slides across its leg as the input grows, so the rates' and the
    // Coriolis terms of the sliding act on the leg's turning too (along the line they do not);
    // leg 2's pair ordered rod first (the guide fixed in the rod).
    let text = std::fs::read_to_string(root().join("examples/models/library/3-rpr.yaml")).unwrap();
    let turned = |axis: [f64; 2], by: f64| {
        let (s, c) = f64::sin_cos(by);
        format!("axis: [{}, {}]", c * axis[0] - s * axis[1], s * axis[0] + c * axis[1])
    };
    let mut text = text
        .replace("bodies: [barrel2, rod2]", "bodies: [rod2, barrel2]")
        .replace("barrel2: {points: [A2, E2]", "barrel2: {points: [A2, E2, K2]");
    for (axis, by) in [
        ([-0.11551861091413643, -0.9933053158684234], 0.3),
        ([0.917986942713249, 0.3966106062726791], -0.2),
        ([-0.8024683317991123, 0.5966947095957446], 0.25),
    ] {
        text = text.replace(&format!("axis: [{}, {}]", axis[0], axis[1]), &turned(axis, by));
    }
    assert_eq!((text.matches("rod2, barrel2").count(), text.matches("E2, K2").count()), (1, 1));
    let mech = common::yaml(&text);
    compare("3-RPR with bent cylinders", &mech, &mut Rng(0x0bad_cafe_f00d_1234), MIN_SIGMA);
}

#[test]
fn reports_coordinates_where_a_triad_does_not_assemble() {
    // The 3-RRR's first crank turned 2 rad from the drawing, the others -2 rad: its distal
    // link cannot reach the platform, so the triad's Newton does not converge. The error is the
    // general path's (which does not assemble there either), never NaN positions.
    let mech = planardyn::load(root().join("examples/models/3-rrr.yaml").to_str().unwrap()).unwrap();
    let mut cf = ClosedForm::new(&mech).unwrap();
    let mut ws = Workspace::new(&mech);
    let (q0, qd0) = mech.initial_state();
    let apart = [q0[0] + 2.0, q0[1] - 2.0, q0[2] - 2.0];
    match cf.kinematic_stages(&apart, &qd0, &mut ws) {
        Err(KinematicsError::AssemblyFailed { residual, .. }) => assert!(residual > 1e-3, "{residual}"),
        other => panic!("expected AssemblyFailed, got {other:?}"),
    }
    assert!(assemble_into(&mech, &apart, &mut Workspace::new(&mech)).is_err());
}

#[test]
fn first_closed_form_step_after_a_newton_point() {
    // As the integrator: the chart's first point takes Newton, then (clear of folds) the
    // evaluations take the closed forms, the first with the second-order predictor from that
    // Newton point (where the groups' geometry was never evaluated). Each model's first two
    // evaluations 1 mrad on succeed and give the general path's accelerations.
    use planardyn::integrate::OdeSystem;
    let dir = root().join("examples/models");
    for model in ["3-rrr", "library/3-rpr", "hydraulic-boom", "five-bar"] {
        let mech = planardyn::load(dir.join(format!("{model}.yaml")).to_str().unwrap()).unwrap();
        let m = mech.dof();
        let mut drives = ModelDrives(&mech);
        let (mut ode, mut y) = common::ode::at_drawing(&mech, &mut drives);
        let mut dy = vec![0.0; 2 * m + 1];
        for step in 1..=2 {
            y[..m].iter_mut().for_each(|v| *v += 1e-3);
            ode.rhs(0.0, &y, &mut dy).unwrap_or_else(|e| panic!("{model}, evaluation {step}: {e}"));
            let mut general = Workspace::new(&mech);
            assemble_into(&mech, &y[..m], &mut general).unwrap();
            forward(&mech, 0.0, &y[..m], &y[m..2 * m], &mut ModelDrives(&mech), &mut general).unwrap();
            let d = rel_diff(&general.qdd, &dy[m..2 * m]);
            assert!(d < REL_TOL, "{model}, evaluation {step}: qdd differs by {d:e} relative");
        }
    }
}
