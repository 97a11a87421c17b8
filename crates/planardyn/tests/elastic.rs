//! Stiffness and vibration with compliances (`planardyn::elastic`, docs/stiffness.md) against
//! closed forms and independent computations; each test names its source.

mod common;

use common::yaml;
use nalgebra::{DMatrix, DVector, SymmetricEigen};
use planardyn::elastic::{self, Load, Output};
use planardyn::model::BodyId;
use planardyn::{Mechanism, Workspace};

/// Closed forms against the exact elastostatics: both are exact, so the difference is
/// rounding (relative ~1e-15 times the conditioning of the few-column solves); 1e-9 leaves room for conditioning without hiding an
/// error of a term (a missing geometric or beam term changes results at 1e-3 or more).
const CLOSED_FORM_TOL: f64 = 1e-9;

fn rel(a: f64, b: f64) -> f64 {
    (a - b).abs() / b.abs().max(f64::MIN_POSITIVE)
}

/// A 3-RPR robot with straight legs (one prismatic leg per base pivot; the library's
/// `3-RPR` has barrel and rod), base pivots on a circle of 0.5 m, platform attachments on a
/// circle of 0.1 m turned by 0.5 rad: a symmetric pose (120-degree symmetry).
fn three_rpr(leg_mass: f64, compliance: &str) -> Mechanism {
    let (rb, rp, turn) = (0.5_f64, 0.1_f64, 0.5_f64);
    let mut points = String::new();
    let mut bodies = String::new();
    let mut pairs = String::new();
    let mut coords = String::new();
    for i in 0..3 {
        let a = std::f64::consts::FRAC_PI_2 + 2.0 * std::f64::consts::PI * i as f64 / 3.0;
        let (ax, ay) = (rb * a.cos(), rb * a.sin());
        let (cx, cy) = (rp * (a + turn).cos(), rp * (a + turn).sin());
        // The slider point K halfway along the leg: on both the leg's guide and the rod.
        let (kx, ky) = (0.5 * (ax + cx), 0.5 * (ay + cy));
        let len = (cx - ax).hypot(cy - ay);
        let j = i + 1;
        points += &format!("  A{j}: [{ax}, {ay}]\n  C{j}: [{cx}, {cy}]\n  K{j}: [{kx}, {ky}]\n");
        bodies += &format!(
            "  cyl{j}: {{points: [A{j}, K{j}], mass: {leg_mass}, inertia: {i0}, com: A{j}}}\n  \
             rod{j}: {{points: [K{j}, C{j}], mass: {leg_mass}, inertia: {i0}, com: C{j}}}\n",
            i0 = leg_mass * 1e-2
        );
        pairs += &format!(
            "  - {{type: revolute, name: base{j}, at: A{j}, bodies: [ground, cyl{j}]}}\n  \
             - {{type: prismatic, name: leg{j}, at: K{j}, bodies: [cyl{j}, rod{j}], along: [A{j}, C{j}]}}\n  \
             - {{type: revolute, name: wrist{j}, at: C{j}, bodies: [rod{j}, platform]}}\n"
        );
        coords += &format!("  - {{name: L{j}, pair: leg{j}, value: {len}}}\n");
    }
    yaml(&format!(
        "name: 3-RPR\npoints:\n  P: [0, 0]\n{points}ground: [A1, A2, A3]\nbodies:\n{bodies}  \
         platform: {{points: [P, C1, C2, C3], mass: 2.0, inertia: 0.01, com: P}}\npairs:\n{pairs}\
         coordinates:\n{coords}{compliance}"
    ))
}

const LEG_STIFFNESS: [f64; 3] = [1.0e6, 2.0e6, 1.5e6];

fn leg_compliance() -> String {
    let drives: String = LEG_STIFFNESS
        .iter()
        .enumerate()
        .map(|(i, k)| format!("    - {{actuator: L{}, stiffness: {k}}}\n", i + 1))
        .collect();
    format!("compliance:\n  drives:\n{drives}")
}

/// Gosselin's inverse Jacobian of a 3-RPR: d rho_i = e_i . (dP + dphi perp(C_i - P)), e_i the
/// unit vector from A_i to C_i (C. Gosselin, "Stiffness mapping for parallel manipulators",
/// IEEE Trans. Robotics and Automation 6(3), 1990).
fn gosselin_jacobian(mech: &Mechanism) -> DMatrix<f64> {
    let xy = |name: &str| mech.points[mech.point_id(name).unwrap().0].1;
    let p = xy("P");
    DMatrix::from_fn(3, 3, |i, c| {
        let (a, cc) = (xy(&format!("A{}", i + 1)), xy(&format!("C{}", i + 1)));
        let len = (cc[0] - a[0]).hypot(cc[1] - a[1]);
        let e = [(cc[0] - a[0]) / len, (cc[1] - a[1]) / len];
        let r = [cc[0] - p[0], cc[1] - p[1]];
        [e[0], e[1], -e[0] * r[1] + e[1] * r[0]][c]
    })
}

#[test]
fn three_rpr_leg_stiffness_is_gosselins() {
    let mech = three_rpr(0.1, &leg_compliance());
    let mut ws = Workspace::new(&mech);
    let platform = Output { body: mech.body_id("platform").unwrap(), point: mech.point_id("P") };
    let s = elastic::stiffness(&mech, &mech.drawn_q(), platform, &Load::default(), &mut ws).unwrap();
    let j = gosselin_jacobian(&mech);
    let k = j.transpose() * DMatrix::from_diagonal(&DVector::from_column_slice(&LEG_STIFFNESS)) * &j;
    let ours = s.stiffness.expect("three freedoms");
    let scale = k.amax();
    for r in 0..3 {
        for c in 0..3 {
            assert!(
                (ours[r][c] - k[(r, c)]).abs() <= CLOSED_FORM_TOL * scale,
                "K[{r}][{c}] {} vs {}",
                ours[r][c],
                k[(r, c)]
            );
        }
    }
    assert_eq!(s.freedoms, 3);
}

#[test]
fn three_rpr_frequencies_with_massless_legs_are_eig_k_m_platform() {
    // Legs of 1e-9 kg (inertia 1e-11 kg m^2) against a 2 kg, 0.01 kg m^2 platform: they
    // shift omega^2 by ~1e-9 relative at most; 1e-7 bounds it.
    const MASSLESS_LEG_TOL: f64 = 1e-7;
    let mech = three_rpr(1e-9, &leg_compliance());
    let mut ws = Workspace::new(&mech);
    let modes = elastic::modes(&mech, &mech.drawn_q(), false, false, &mut ws).unwrap();
    let j = gosselin_jacobian(&mech);
    let k = j.transpose() * DMatrix::from_diagonal(&DVector::from_column_slice(&LEG_STIFFNESS)) * &j;
    // M_platform = diag(m, m, I) about P, the centre of mass: whitened by its square root.
    let m_inv_sqrt = DMatrix::from_diagonal(&DVector::from_column_slice(&[2.0f64, 2.0, 0.01].map(|v| 1.0 / v.sqrt())));
    let mut expected: Vec<f64> =
        SymmetricEigen::new(&m_inv_sqrt * k * &m_inv_sqrt).eigenvalues.iter().copied().collect();
    expected.sort_by(f64::total_cmp);
    assert_eq!(modes.omega2.len(), 3);
    for (w2, e) in modes.omega2.iter().zip(&expected) {
        assert!(rel(*w2, *e) < MASSLESS_LEG_TOL, "omega^2 {w2} vs {e}");
    }
}

/// A cantilever: a beam of length L along `angle`, hinged at A to the ground with its
/// coordinate held rigid (no drive compliance): clamped at A.
fn cantilever(angle: f64) -> Mechanism {
    let (len, c, s) = (0.8, angle.cos(), angle.sin());
    yaml(&format!(
        "name: cantilever\npoints: {{A: [0, 0], B: [{}, {}]}}\nground: [A]\n\
         bodies:\n  beam: {{points: [A, B], uniform_bar: [A, B], mass: 1.0}}\n\
         pairs:\n  - {{type: revolute, name: root, at: A, bodies: [ground, beam]}}\n\
         coordinates:\n  - {{name: q, pair: root, value: {angle}}}\n\
         compliance:\n  links:\n    - {{body: beam, EA: 2.0e7, EI: 150.0}}\n",
        len * c,
        len * s
    ))
}

#[test]
fn cantilever_tip_deflection_is_pl3_over_3ei_and_pl_over_ea() {
    // Euler-Bernoulli cantilever under a tip load (e.g. Gere & Goodno, Mechanics of
    // Materials, appendix G): transverse P L^3/(3EI), tip rotation P L^2/(2EI), axial P L/(EA).
    let (len, ea, ei, p) = (0.8_f64, 2.0e7, 150.0, 3.0);
    for angle in [0.0, 0.7] {
        let mech = cantilever(angle);
        let mut ws = Workspace::new(&mech);
        let tip = Output { body: BodyId(0), point: mech.point_id("B") };
        let (c, s) = (f64::cos(angle), f64::sin(angle));
        let transverse = Load { wrench: [-s * p, c * p, 0.0], preload: vec![], gravity: false };
        let d = elastic::deflection(&mech, &[angle], tip, &transverse, 1, &mut ws).unwrap();
        let along = -s * d.linear[0] + c * d.linear[1];
        assert!(rel(along, p * len.powi(3) / (3.0 * ei)) < CLOSED_FORM_TOL, "transverse {along}");
        assert!(rel(d.linear[2], p * len * len / (2.0 * ei)) < CLOSED_FORM_TOL, "rotation {}", d.linear[2]);
        let axial = Load { wrench: [c * p, s * p, 0.0], preload: vec![], gravity: false };
        let d = elastic::deflection(&mech, &[angle], tip, &axial, 1, &mut ws).unwrap();
        let stretch = c * d.linear[0] + s * d.linear[1];
        assert!(rel(stretch, p * len / ea) < CLOSED_FORM_TOL, "axial {stretch}");
    }
}

/// A disc of inertia I about its hinge O turned through a drive spring k (joint side), with a
/// motor of ratio n and rotor inertia J.
fn compliant_drive(extra: &str) -> Mechanism {
    yaml(&format!(
        "name: compliant drive\npoints: {{O: [0, 0], E: [0.2, 0]}}\nground: [O]\n\
         bodies:\n  disc: {{points: [O, E], mass: 3.0, inertia: 0.05, com: O}}\n\
         pairs:\n  - {{type: revolute, name: O, at: O, bodies: [ground, disc]}}\n\
         coordinates:\n  - {{name: q, pair: O, value: 0.0}}\n{extra}"
    ))
}

#[test]
fn compliant_drive_frequencies() {
    // Two-mass torsional oscillator (e.g. Rao, Mechanical Vibrations, 5th ed., sec. 5.3):
    // load I = 0.05 kg m^2 on its hinge (centre of mass at O), spring k = 800 N m/rad at the
    // joint, rotor J = 2e-4 kg m^2 behind a ratio n = 10 (joint side n^2 J = 0.02).
    let (k, i, n, j) = (800.0_f64, 0.05, 10.0, 2e-4);
    let rigid = compliant_drive(&format!("compliance:\n  drives: [{{actuator: q, stiffness: {k}}}]\n"));
    let mut ws = Workspace::new(&rigid);
    let held = elastic::modes(&rigid, &[0.0], false, false, &mut ws).unwrap();
    assert!(rel(held.omega()[0], (k / i).sqrt()) < CLOSED_FORM_TOL);
    let geared = compliant_drive(&format!(
        "actuators: [{{coordinate: q, gear_ratio: {n}, rotor_inertia: {j}}}]\n\
         compliance:\n  drives: [{{actuator: q, stiffness: {k}, damping: 0.4}}]\n"
    ));
    let held = elastic::modes(&geared, &[0.0], false, false, &mut ws).unwrap();
    assert_eq!(held.omega2.len(), 1);
    assert!(rel(held.omega()[0], (k / i).sqrt()) < CLOSED_FORM_TOL, "motor held: {:?}", held.omega());
    // Modal damping ratio c / (2 sqrt(k I)) of the single mode.
    assert!(rel(held.damping_ratio[0], 0.4 / (2.0 * (k * i).sqrt())) < CLOSED_FORM_TOL);
    let free = elastic::modes(&geared, &[0.0], true, false, &mut ws).unwrap();
    let nj = n * n * j;
    let expected = (k * (i + nj) / (i * nj)).sqrt();
    assert_eq!(free.omega2.len(), 2);
    // The rigid-body mode: omega^2 at rounding of k / (I + n^2 J) = 1.1e4.
    assert!(free.omega2[0].abs() < 1e-9 * k / (i + nj), "rigid mode {}", free.omega2[0]);
    assert!(rel(free.omega()[1], expected) < CLOSED_FORM_TOL, "rotor free: {:?} vs {expected}", free.omega());
}

#[test]
fn parallelogram_swings_at_its_exact_pendulum_frequency() {
    // Two equal cranks (uniform bars, m_c, l) hanging from O1, O2 and a coupler (m_b) between
    // their ends: the coupler translates, T = 1/2 (2 m_c l^2/3 + m_b l^2) thd^2,
    // V = -(m_c + m_b) g l cos th, so omega^2 = (m_c + m_b) g l / (2 m_c l^2/3 + m_b l^2).
    let (l, mc, mb, g) = (0.6_f64, 0.4, 1.5, 9.81);
    let mech = yaml(&format!(
        "name: parallelogram\ngravity: [0, -{g}]\n\
         points: {{O1: [0, 0], O2: [0.5, 0], A: [0, -{l}], B: [0.5, -{l}]}}\nground: [O1, O2]\n\
         bodies:\n  c1: {{points: [O1, A], uniform_bar: [O1, A], mass: {mc}}}\n  \
         c2: {{points: [O2, B], uniform_bar: [O2, B], mass: {mc}}}\n  \
         coupler: {{points: [A, B], mass: {mb}, inertia: 0.02, com: [0.25, -{l}]}}\n\
         pairs:\n  - {{type: revolute, name: O1, at: O1, bodies: [ground, c1]}}\n  \
         - {{type: revolute, at: A, bodies: [c1, coupler]}}\n  - {{type: revolute, at: B, bodies: [coupler, c2]}}\n  \
         - {{type: revolute, at: O2, bodies: [c2, ground]}}\n\
         coordinates:\n  - {{name: th, pair: O1, value: -1.5707963267948966}}\n"
    ));
    let mut ws = Workspace::new(&mech);
    let q = elastic::equilibrium(&mech, &[-1.4], &mut ws).unwrap();
    assert!((q[0] + std::f64::consts::FRAC_PI_2).abs() < 1e-12, "equilibrium {q:?}");
    let modes = elastic::small_oscillations(&mech, &q, &mut ws).unwrap();
    let expected = (mc + mb) * g * l / (2.0 * mc * l * l / 3.0 + mb * l * l);
    assert!(rel(modes.omega2[0], expected) < CLOSED_FORM_TOL, "{} vs {expected}", modes.omega2[0]);
}

/// A 5R with elastic motors and slender distal links, loaded at P; `actuators` and `drives`
/// add actuators and drive compliances.
fn five_bar(actuators: &str, drives: &str) -> Mechanism {
    let text =
        std::fs::read_to_string(format!("{}/../../examples/models/five-bar.yaml", env!("CARGO_MANIFEST_DIR"))).unwrap();
    let rigid = text.split("\ndrives:").next().unwrap();
    yaml(&format!(
        "{rigid}\n{actuators}compliance:\n  drives:\n    - {{actuator: theta1, stiffness: 2.0e3}}\n    \
         - {{actuator: theta2, stiffness: 3.0e3}}\n{drives}  links:\n    - {{body: distal_left, EA: 1.0e6, EI: 20.0}}\n    \
         - {{body: distal_right, EA: 1.0e6, EI: 25.0}}\n"
    ))
}

/// The tangent compliance at the loaded equilibrium (geometric terms of the load, of the
/// element forces and of the preload included) against central differences of the
/// non-linear deflection in the load: truncation (h/W)^2 ~ 1e-10 and rounding
/// 1e-16 L / (h C) ~ 1e-9 relative; and the load changes the compliance by far more than
/// that, so that the test sees the geometric terms.
fn check_tangent_against_differences(mech: &Mechanism, preload: Vec<(usize, f64)>, gravity: bool) {
    const FD_TOL: f64 = 1e-7;
    let mut ws = Workspace::new(mech);
    let q = mech.drawn_q();
    let out = Output { body: mech.body_id("distal_left").unwrap(), point: mech.point_id("P") };
    let w = [40.0, -60.0, 0.0];
    let mut at = |w: [f64; 3]| {
        elastic::deflection(mech, &q, out, &Load { wrench: w, preload: preload.clone(), gravity }, 4, &mut ws).unwrap()
    };
    let c = at(w).tangent.compliance;
    let unloaded = at([0.0; 3]).tangent.compliance;
    let h = 1e-3;
    for k in 0..2 {
        let (mut plus, mut minus) = (w, w);
        plus[k] += h;
        minus[k] -= h;
        let (dp, dm) = (at(plus).nonlinear, at(minus).nonlinear);
        for i in 0..2 {
            let fd = (dp[i] - dm[i]) / (2.0 * h);
            let scale = c[i][i].abs().max(c[k][k].abs());
            assert!((fd - c[i][k]).abs() < FD_TOL * scale, "C[{i}][{k}] {} vs fd {fd}", c[i][k]);
            assert!((c[i][k] - unloaded[i][k]).abs() > 1e3 * FD_TOL * scale, "geometric term too small");
        }
    }
}

#[test]
fn tangent_compliance_is_the_derivative_of_the_loaded_equilibrium() {
    check_tangent_against_differences(&five_bar("", ""), vec![], false);
}

#[test]
fn gravity_enters_the_tangent_of_the_loaded_equilibrium() {
    // The 5R's own gravity (its model's 9.81 m/s^2 on 1.7 kg of links and end effector) added
    // to the wrench: the tangent compliance at the equilibrium under both is again the
    // derivative of that equilibrium in the wrench, and gravity changes it by far more than
    // the differences' error (the test sees its geometric term).
    let mech = five_bar("", "");
    check_tangent_against_differences(&mech, vec![], true);
    let mut ws = Workspace::new(&mech);
    let q = mech.drawn_q();
    let out = Output { body: mech.body_id("distal_left").unwrap(), point: mech.point_id("P") };
    let at = |gravity, ws: &mut Workspace| {
        let load = Load { wrench: [0.0; 3], preload: vec![], gravity };
        elastic::stiffness(&mech, &q, out, &load, ws).unwrap().compliance
    };
    let (with, without) = (at(true, &mut ws), at(false, &mut ws));
    let change = (with[1][1] - without[1][1]).abs() / without[1][1];
    assert!(change > 1e-4, "gravity's geometric term: {change:e}");
}

/// A uniform bar (m, length L: centre of mass at l = L/2, I_O = m L^2/3) on a hinge O under
/// gravity g, drawn at `angle` from the x axis, its coordinate turned through a drive spring k.
fn spring_pendulum(angle: f64) -> Mechanism {
    let (len, c, s) = (0.5, angle.cos(), angle.sin());
    yaml(&format!(
        "name: spring pendulum\ngravity: [0, -9.81]\npoints: {{O: [0, 0], A: [{}, {}]}}\nground: [O]\n\
         bodies:\n  bar: {{points: [O, A], uniform_bar: [O, A], mass: 1.2}}\n\
         pairs:\n  - {{type: revolute, name: O, at: O, bodies: [ground, bar]}}\n\
         coordinates:\n  - {{name: q, pair: O, value: {angle}}}\n\
         compliance:\n  drives: [{{actuator: q, stiffness: 30.0}}]\n",
        len * c,
        len * s
    ))
}

#[test]
fn gravity_on_a_spring_pendulum_is_its_closed_form() {
    // V(th) = m g l sin th + 1/2 k (th - q)^2 (th from the x axis, gravity along -y): at a
    // pose q taken as the loaded equilibrium the stiffness is V'' = k - m g l sin q, so
    // omega^2 = (k - m g l sin q) / I_O (at q = pi/2 the inverted pendulum on a torsional
    // spring, (k - m g l) / I_O, stable for k > m g l) and the tip A at L gives
    // C = L^2 t t^T / V'' along t = (-sin q, cos q). From the spring unstrained at q, gravity
    // sags it to th* with k (th* - q) + m g l cos th* = 0 (solved here by scalar Newton), and
    // linearly by -m g l cos q / k.
    let (m, len, k, g) = (1.2_f64, 0.5_f64, 30.0_f64, 9.81_f64);
    let (l, i_o) = (len / 2.0, m * len * len / 3.0);
    let q = 0.6;
    let mech = spring_pendulum(q);
    let mut ws = Workspace::new(&mech);
    for th in [q, std::f64::consts::FRAC_PI_2, -std::f64::consts::FRAC_PI_2] {
        let w2 = elastic::modes(&mech, &[th], false, true, &mut ws).unwrap().omega2[0];
        assert!(rel(w2, (k - m * g * l * th.sin()) / i_o) < CLOSED_FORM_TOL, "at {th}: {w2}");
    }
    let plain = elastic::modes(&mech, &[q], false, false, &mut ws).unwrap().omega2[0];
    assert!(rel(plain, k / i_o) < CLOSED_FORM_TOL, "without gravity: {plain}");
    let tip = Output { body: BodyId(0), point: mech.point_id("A") };
    let compliance_at = |th: f64| {
        let t = [-th.sin(), th.cos()];
        let v2 = k - m * g * l * th.sin();
        std::array::from_fn::<_, 2, _>(|i| std::array::from_fn::<_, 2, _>(|j| len * len * t[i] * t[j] / v2))
    };
    let check = |c: &[[f64; 3]; 3], expected: [[f64; 2]; 2]| {
        for i in 0..2 {
            for j in 0..2 {
                let scale = len * len / k;
                assert!(
                    (c[i][j] - expected[i][j]).abs() < CLOSED_FORM_TOL * scale,
                    "C[{i}][{j}] {c:?} vs {expected:?}"
                );
            }
        }
    };
    let gravity = Load { wrench: [0.0; 3], preload: vec![], gravity: true };
    check(&elastic::stiffness(&mech, &[q], tip, &gravity, &mut ws).unwrap().compliance, compliance_at(q));
    let mut th = q;
    for _ in 0..50 {
        th -= (k * (th - q) + m * g * l * th.cos()) / (k - m * g * l * th.sin());
    }
    let d = elastic::deflection(&mech, &[q], tip, &gravity, 10, &mut ws).unwrap();
    let sag = [len * (th.cos() - q.cos()), len * (th.sin() - q.sin())];
    let linear = -m * g * l * q.cos() / k;
    for i in 0..2 {
        assert!((d.nonlinear[i] - sag[i]).abs() < CLOSED_FORM_TOL * len, "sag {:?} vs {sag:?}", d.nonlinear);
        let lin = len * linear * [-q.sin(), q.cos()][i];
        assert!((d.linear[i] - lin).abs() < CLOSED_FORM_TOL * len, "linear sag {:?} vs {lin}", d.linear);
    }
    assert!((d.nonlinear[2] - (th - q)).abs() < CLOSED_FORM_TOL, "rotation {} vs {}", d.nonlinear[2], th - q);
    check(&d.tangent.compliance, compliance_at(th));
}

#[test]
fn preload_of_a_redundant_drive_enters_the_tangent_and_the_stiffness() {
    // A third, redundant motor at the left elbow (a pair actuator), elastic, preloaded with
    // 50 N m against the two others: a self-stress, which changes the stiffness at the pose
    // (its geometric term) and the tangent along the loaded equilibria.
    let mech = five_bar("actuators: [{pair: elbow1}]\n", "    - {actuator: elbow1, stiffness: 1.5e3}\n");
    let elbow = mech.n_actuators() - 1;
    check_tangent_against_differences(&mech, vec![(elbow, 50.0)], false);
    let mut ws = Workspace::new(&mech);
    let out = Output { body: mech.body_id("distal_left").unwrap(), point: mech.point_id("P") };
    let q = mech.drawn_q();
    let plain = elastic::stiffness(&mech, &q, out, &Load::default(), &mut ws).unwrap();
    let loaded = Load { wrench: [0.0; 3], preload: vec![(elbow, 50.0)], gravity: false };
    let preloaded = elastic::stiffness(&mech, &q, out, &loaded, &mut ws).unwrap();
    let change = (preloaded.compliance[1][1] - plain.compliance[1][1]).abs() / plain.compliance[1][1];
    assert!(change > 1e-4, "the preload's geometric term: {change:e}");
}

#[test]
fn a_rigid_model_is_refused_with_the_fix() {
    let mech = yaml(common::PENDULUM);
    let mut ws = Workspace::new(&mech);
    let err = elastic::modes(&mech, &[0.0], false, false, &mut ws).unwrap_err().to_string();
    assert!(err.contains("compliance:"), "{err}");
}

/// A bar (1.2 kg, 0.5 m) hanging from O under gravity, started at -1.2 rad (hanging is -pi/2),
/// its rotor (J = 5e-5 kg m^2 behind n = 20) joined to it by a transmission spring k; no
/// motor torque.
fn flexible_pendulum(k: f64) -> Mechanism {
    driven_flexible_pendulum(k, 0.0, 0.0)
}

/// The same with a damper c (N m s/rad) beside the spring and a constant motor torque t_m
/// (N m, motor side).
fn driven_flexible_pendulum(k: f64, c: f64, t_m: f64) -> Mechanism {
    yaml(&format!(
        "name: flexible pendulum\ngravity: [0, -9.81]\npoints: {{O: [0, 0], A: [0.5, 0]}}\nground: [O]\n\
         bodies:\n  bar: {{points: [O, A], uniform_bar: [O, A], mass: 1.2}}\n\
         pairs:\n  - {{type: revolute, name: O, at: O, bodies: [ground, bar]}}\n\
         coordinates:\n  - {{name: q, pair: O, value: 0.0, q0: -1.2}}\n\
         actuators: [{{coordinate: q, gear_ratio: 20, rotor_inertia: 5.0e-5}}]\n\
         drives: [{{coordinate: q, effort: {t_m}}}]\n\
         compliance:\n  drives: [{{actuator: q, stiffness: {k}, damping: {c}}}]\n"
    ))
}

fn flexible_run(k: f64, t_end: f64) -> elastic::FlexibleRun {
    let options = planardyn::integrate::Options::tol(1e-12, 1e-14);
    let method = planardyn::integrate::Method::Dop853;
    elastic::simulate_flexible(&flexible_pendulum(k), t_end, 0.01, method, &options).unwrap()
}

#[test]
fn flexible_joint_run_conserves_its_energy() {
    // No damping and no motor torque: E = T + V + 1/2 n^2 J thetad^2 + 1/2 k (theta - q)^2 is
    // constant; dop853 at rtol 1e-12 over 2 s (~80 periods of the spring) keeps a 3 J energy
    // to ~1e-11 J; the usual bound of the energy checks is 1e-9 J.
    let run = flexible_run(1.0e3, 2.0);
    let e0 = run.energy[0];
    let drift = run.energy.iter().map(|e| (e - e0).abs()).fold(0.0, f64::max);
    assert!(drift < 1e-9, "energy drift {drift:e} J of {e0} J");
    // The spring works: the rotor lags the bar.
    let lag = run.q.iter().zip(&run.theta).map(|(q, th)| (q[0] - th[0]).abs()).fold(0.0, f64::max);
    assert!(lag > 1e-4, "lag {lag}");
}

#[test]
fn flexible_joint_energy_balance_counts_the_motors_work_and_the_dampers_loss() {
    // A constant motor torque 0.05 N m (n = 20: 1 N m at the joint) and a transmission damper
    // 0.5 N m s/rad: E(t) - E(0) = W(t) - D(t) with W and D integrated along the run; dop853 at
    // rtol 1e-12 over 2 s keeps it to ~1e-11 J; the usual bound of the energy checks is 1e-9 J.
    // Both terms are far above it (the balance sees them).
    let options = planardyn::integrate::Options::tol(1e-12, 1e-14);
    let mech = driven_flexible_pendulum(1.0e3, 0.5, 0.05);
    let run = elastic::simulate_flexible(&mech, 2.0, 0.01, planardyn::integrate::Method::Dop853, &options).unwrap();
    let residual = (0..run.t.len())
        .map(|i| (run.energy[i] - run.energy[0] - run.work[i] + run.dissipated[i]).abs())
        .fold(0.0, f64::max);
    assert!(residual < 1e-9, "energy balance {residual:e} J");
    let (w, d) = (run.work.last().unwrap(), run.dissipated.last().unwrap());
    assert!(w.abs() > 1e-3 && *d > 1e-6, "work {w} J, loss {d} J");
}

#[test]
fn flexible_joint_run_tends_to_the_rigid_one_like_one_over_k() {
    // The rigid model's A holds n^2 J on the coordinate (`dynamics::transmission`); the
    // flexible run differs by the spring's deflection and its fast oscillation, both ~1/k:
    // each tenfold stiffer spring divides the largest difference over 1 s by about ten (here
    // by more than 6.7: 1/k or faster).
    let times: Vec<f64> = (0..=100).map(|j| 0.01 * j as f64).collect();
    let rigid = common::run(&flexible_pendulum(1.0), "dop853", 1.0, 1e-12, Some(times.clone()));
    let diffs: Vec<f64> = [1.0e3, 1.0e4, 1.0e5]
        .iter()
        .map(|&k| {
            let run = flexible_run(k, 1.0);
            assert_eq!(run.t, times);
            run.q.iter().zip(&rigid.q).map(|(q, r)| (q[0] - r).abs()).fold(0.0, f64::max)
        })
        .collect();
    assert!(diffs[0] < 1e-1, "{diffs:?}");
    assert!(diffs[1] < diffs[0] / 6.7 && diffs[2] < diffs[1] / 6.7, "{diffs:?}");
}

/// C (s I - A)^-1 B + D of a state-space model at a real s (outputs x inputs).
fn transfer(ss: &elastic::StateSpace, s: f64) -> DMatrix<f64> {
    let (n, nu, p) = (ss.n_states, ss.n_inputs, ss.n_outputs);
    let a = DMatrix::from_row_slice(n, n, &ss.a);
    let b = DMatrix::from_row_slice(n, nu, &ss.b);
    let c = DMatrix::from_row_slice(p, n, &ss.c);
    let x = (DMatrix::identity(n, n) * s - a).lu().solve(&b).unwrap();
    c * x + DMatrix::from_row_slice(p, nu, &ss.d)
}

#[test]
fn compliant_state_space_is_the_flexible_joint_pendulums() {
    // Spong's flexible joint linearised about the bar at rest at q under gravity (the motor
    // holding it): I q'' + V'' q + k (q - th) + c (q' - th') = 0 and
    // n^2 J th'' + k (th - q) + c (th' - q') = n t_m, V'' = -m g l sin q. Laplace: with
    // kc = k + c s, q / t_m = n kc / ((I s^2 + kc + V'') (n^2 J s^2 + kc) - kc^2), and the tip A
    // at L moves by L (-sin q, cos q) dq. The model's transfer function C (sI - A)^-1 B at
    // s = 0 (the static gain), 3 and 40 1/s must equal it, and its undamped A's eigenvalues be
    // +-i omega of `modes` (free rotors, gravity). All exact: CLOSED_FORM_TOL.
    let (m, len, g, n, j) = (1.2_f64, 0.5_f64, 9.81_f64, 20.0_f64, 5.0e-5_f64);
    let (i, l, nj) = (m * len * len / 3.0, len / 2.0, n * n * j);
    let (k, c, q) = (1.0e3, 0.3, -1.2_f64);
    let v2 = -m * g * l * q.sin();
    let mech = driven_flexible_pendulum(k, c, 0.0);
    let mut ws = Workspace::new(&mech);
    let tip = Output { body: BodyId(0), point: mech.point_id("A") };
    let ss = elastic::linearize_compliant(&mech, &[q], true, &[tip], &mut ws).unwrap();
    assert_eq!((ss.n_states, ss.n_inputs, ss.n_outputs), (4, 1, 3));
    for s in [0.0, 3.0, 40.0] {
        let kc = k + c * s;
        let gq = n * kc / ((i * s * s + kc + v2) * (nj * s * s + kc) - kc * kc);
        let tf = transfer(&ss, s);
        let expected = [gq, -len * q.sin() * gq, len * q.cos() * gq];
        for (r, e) in expected.iter().enumerate() {
            assert!((tf[(r, 0)] - e).abs() < CLOSED_FORM_TOL * gq.abs().max(len * gq.abs()), "s {s}: {tf} vs {e}");
        }
    }
    let undamped = flexible_pendulum(k);
    let ss = elastic::linearize_compliant(&undamped, &[q], true, &[], &mut ws).unwrap();
    let a = DMatrix::from_row_slice(4, 4, &ss.a);
    let mut eig: Vec<f64> = a.complex_eigenvalues().iter().map(|e| e.im.abs()).collect();
    eig.sort_by(f64::total_cmp);
    let omega = elastic::modes(&undamped, &[q], true, true, &mut ws).unwrap().omega();
    for (pair, w) in eig.chunks(2).zip(&omega) {
        for e in pair {
            assert!(rel(*e, *w) < CLOSED_FORM_TOL, "eigenvalues {eig:?} vs omega {omega:?}");
        }
    }
    let err = elastic::linearize_compliant(&spring_pendulum(0.3), &[0.3], false, &[], &mut ws).unwrap_err();
    assert!(err.to_string().contains("rotor_inertia"), "{err}");
}

/// A slider on a compliant prismatic guide along x (lateral stiffness k_l at the pair point K,
/// tilt stiffness k_t), its slide held (the coordinate without a drive spring), carrying P at d
/// along the guide from K; `pairs` the compliance entry.
fn compliant_slider(pairs: &str) -> Mechanism {
    yaml(&slider_text(pairs))
}

fn slider_text(pairs: &str) -> String {
    format!(
        "name: slider\npoints: {{K: [0, 0], G: [1, 0], P: [0.4, 0]}}\nground: [K, G]\n\
         bodies:\n  slider: {{points: [K, P], mass: 2.0, inertia: 0.03, com: P}}\n\
         pairs:\n  - {{type: prismatic, name: guide, at: K, bodies: [ground, slider], along: [K, G]}}\n\
         coordinates:\n  - {{name: s, pair: guide, value: 0.0}}\n\
         compliance:\n  pairs: [{pairs}]\n"
    )
}

#[test]
fn a_compliant_prismatic_pair_is_a_lateral_and_a_tilt_spring() {
    // The slider's copy of K is offset from the guide by F / k_l under a lateral force at K,
    // and a moment turns it by M / k_t about K (the offset is measured at K, so the two do not
    // couple there); at P, d along the guide: C_yy = 1/k_l + d^2/k_t, C_yphi = d/k_t,
    // C_phiphi = 1/k_t, and nothing along the held slide (x).
    let (kl, kt, d) = (2.0e5_f64, 3.0e3_f64, 0.4_f64);
    let mech = compliant_slider(&format!("{{pair: guide, stiffness: {kl}, tilt_stiffness: {kt}}}"));
    let mut ws = Workspace::new(&mech);
    let at_p = Output { body: BodyId(0), point: mech.point_id("P") };
    let s = elastic::stiffness(&mech, &[0.0], at_p, &Load::default(), &mut ws).unwrap();
    let expected = [[0.0, 0.0, 0.0], [0.0, 1.0 / kl + d * d / kt, d / kt], [0.0, d / kt, 1.0 / kt]];
    for i in 0..3 {
        for j in 0..3 {
            let err = (s.compliance[i][j] - expected[i][j]).abs();
            assert!(err < CLOSED_FORM_TOL * (1.0 / kt), "C[{i}][{j}] {:?} vs {expected:?}", s.compliance);
        }
    }
    assert_eq!((s.freedoms, s.stiffness.is_none()), (2, true));
    let at_k = Output { body: BodyId(0), point: mech.point_id("K") };
    let c = elastic::stiffness(&mech, &[0.0], at_k, &Load::default(), &mut ws).unwrap().compliance;
    assert!(rel(c[1][1], 1.0 / kl) < CLOSED_FORM_TOL && c[1][2].abs() < CLOSED_FORM_TOL / kt, "{c:?}");
}

#[test]
fn pair_compliance_errors_name_the_field_and_the_fix() {
    let err = |text: &str| planardyn::loads(text, planardyn::Format::Yaml, "<test>").unwrap_err().to_string();
    let e = err(&slider_text("{pair: guide, stiffness: 1.0e5}"));
    assert!(e.contains("compliance.pairs[0].tilt_stiffness") && e.contains("N m/rad"), "{e}");
    let revolute = "compliance:\n  pairs: [{pair: O, stiffness: 1.0e5, tilt_stiffness: 1.0}]\ncoordinates:";
    let e = err(&common::PENDULUM.replace("coordinates:", revolute));
    assert!(e.contains("compliance.pairs[0].tilt_stiffness") && e.contains("turns freely"), "{e}");
}
