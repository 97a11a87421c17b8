//! The gear and pin-in-slot pairs against closed forms: a gear train's ratios exact to
//! round-off, its equivalent inertia; the Scotch yoke's travel r cos(theta), its driving
//! torque and slot force from its one-coordinate Lagrangian; energy kept on passive and
//! driven runs; the row counts that mobility and structure see; located model errors.

mod common;
use common::*;
use planardyn::dynamics::{forward, inverse, reactions, ModelDrives};
use planardyn::kinematics::{assemble_into, velocity_analogues, Chart};
use planardyn::model::PairId;
use planardyn::{loads, Format, Mechanism, Workspace};

/// Round-off class of an O(1) evaluation: a few ulps times the handful of operations.
const ROUND_OFF: f64 = 1e-13;

/// Body coordinates and the velocity analogues U (3n x m, column j at u[j n..]) at q.
fn analogues(mech: &Mechanism, q: &[f64]) -> Workspace {
    let mut ws = Workspace::new(mech);
    assemble_into(mech, q, &mut ws).unwrap();
    velocity_analogues(&mut ws).unwrap();
    ws
}

fn energy(tr: &planardyn::simulate::Trajectory, k: usize) -> f64 {
    tr.kinetic[k] + tr.potential[k] - tr.work[k]
}

// Gear train (examples/models/gear-train.yaml): pinion r1 = 20 mm -> wheel r2 = 60 mm
// (external), wheel's r3 = 25 mm -> ring r4 = 45 mm (internal), pinion -> rack (below it).
const R1: f64 = 0.02;
const R2: f64 = 0.06;
const R3: f64 = 0.025;
const R4: f64 = 0.045;

#[test]
fn gear_train_ratios_are_exact_to_round_off() {
    let mech = shipped("gear-train.yaml");
    let x0 = mech.x0.clone();
    for theta in [0.0, 0.7, -2.5, 9.0] {
        let ws = analogues(&mech, &[theta]);
        let n = mech.n_x();
        // Bodies: pinion, wheel, ring, rack. Velocity analogues d(x)/d(theta):
        let wheel = -R1 / R2; // external: opposite sense
        let ring = wheel * (R3 / R4); // internal: same sense as the wheel
        let rack = R1; // sigma = +1: rack below the pinion, P -> Q along +x
        assert!((ws.u[2] - 1.0).abs() < ROUND_OFF, "pinion {}", ws.u[2]);
        assert!((ws.u[5] - wheel).abs() < ROUND_OFF, "wheel {} vs {wheel}", ws.u[5]);
        assert!((ws.u[8] - ring).abs() < ROUND_OFF, "ring {} vs {ring}", ws.u[8]);
        assert!((ws.u[9] - rack).abs() < ROUND_OFF, "rack {} vs {rack}", ws.u[9]);
        assert_eq!(ws.u.len(), n);
        // Positions: the rows are linear in the angles, so these hold exactly too.
        assert!((ws.x[5] - x0[5] - wheel * theta).abs() < ROUND_OFF * 10.0, "wheel angle");
        assert!((ws.x[8] - x0[8] - ring * theta).abs() < ROUND_OFF * 10.0, "ring angle");
        assert!((ws.x[9] - x0[9] - rack * theta).abs() < ROUND_OFF, "rack travel");
        assert!((ws.x[11] - x0[11]).abs() < ROUND_OFF, "the rack does not turn");
    }
}

#[test]
fn gear_train_accelerates_with_its_equivalent_inertia() {
    // J = I_p + I_w (r1/r2)^2 + I_r (r1 r3 / (r2 r4))^2 + m_rack r1^2 (kinetic energy of the
    // train per theta'^2 / 2); no gravity: theta'' = tau / J.
    let mech = shipped("gear-train.yaml");
    let (ip, iw, ir, mr) = (4.0e-05, 0.00108, 0.00081, 0.3);
    let j = ip + iw * (R1 / R2).powi(2) + ir * (R1 * R3 / (R2 * R4)).powi(2) + mr * R1 * R1;
    let mut ws = Workspace::new(&mech);
    assemble_into(&mech, &[0.4], &mut ws).unwrap();
    forward(&mech, 0.0, &[0.4], &[3.0], &mut ModelDrives(&mech), &mut ws).unwrap();
    assert!((ws.qdd[0] - 0.02 / j).abs() < 1e-12 * (0.02 / j), "qdd {} vs {}", ws.qdd[0], 0.02 / j);
    // Tooth force of the rack mesh (pressure angle 0): the rack's only horizontal force,
    // m_rack x'' = m_rack r1 theta''; the pinion (a) pushes the rack (b) along +x.
    let r = reactions(&mech, &mut ws);
    let rack_mesh = &r[6];
    assert!((rack_mesh[0] - mr * R1 * ws.qdd[0]).abs() < 1e-12, "rack tooth force {rack_mesh:?}");
    assert!(rack_mesh[1].abs() < 1e-15 && rack_mesh[2].abs() < 1e-15, "{rack_mesh:?}");
}

#[test]
fn gear_train_energy_balance_holds() {
    let mech = shipped("gear-train.yaml");
    let tr = run(&mech, "dop853", 0.5, 1e-11, None);
    assert!(tr.stats.energy_drift < 1e-9, "energy drift {} J", tr.stats.energy_drift);
    assert!(tr.work[tr.len() - 1] > 1e-3, "the drive did work");
}

// Scotch yoke (examples/models/scotch-yoke.yaml): crank r = 0.1 m, uniform bar 0.5 kg;
// yoke 1.2 kg on a horizontal guide; gravity -9.81 in y.
const R: f64 = 0.1;
const M_CRANK: f64 = 0.5;
const M_YOKE: f64 = 1.2;
const G: f64 = 9.81;

/// theta'' from the yoke's Lagrangian T = (J_O + m_y r^2 sin^2) theta'^2 / 2,
/// V = m_c g (r/2) sin(theta), with J_O = m_c r^2 / 3.
fn yoke_qdd(theta: f64, thetad: f64, tau: f64) -> f64 {
    let (s, c) = theta.sin_cos();
    let jo = M_CRANK * R * R / 3.0;
    (tau - M_YOKE * R * R * s * c * thetad * thetad - M_CRANK * G * R / 2.0 * c) / (jo + M_YOKE * R * R * s * s)
}

#[test]
fn scotch_yoke_travel_is_r_cos_theta() {
    let mech = shipped("scotch-yoke.yaml");
    let theta0 = mech.coordinates[0].value;
    for theta in [0.3, 1.2, 2.5, -0.8, 4.0] {
        let ws = analogues(&mech, &[theta]);
        // Yoke is body 1; its centre of mass moves with the pin's x.
        let travel = ws.x[3] - mech.x0[3];
        assert!((travel - R * (theta.cos() - theta0.cos())).abs() < 1e-14, "theta {theta}: {travel}");
        assert!((ws.u[3] + R * theta.sin()).abs() < 1e-14, "dx/dtheta {}", ws.u[3]);
        assert!((ws.x[4] - mech.x0[4]).abs() < 1e-15 && (ws.x[5] - mech.x0[5]).abs() < 1e-15);
    }
}

#[test]
fn scotch_yoke_torque_and_slot_force_match_the_closed_form() {
    let mech = shipped("scotch-yoke.yaml");
    let mut ws = Workspace::new(&mech);
    for (theta, thetad, thetadd) in [(0.3, 2.0, -1.0), (1.4, -5.0, 3.0), (3.5, 7.0, 0.0)] {
        let (s, c) = f64::sin_cos(theta);
        let jo = M_CRANK * R * R / 3.0;
        // tau = (J_O + m_y r^2 s^2) theta'' + m_y r^2 s c theta'^2 + m_c g (r/2) c
        //     = J_O theta'' - m_y r s x'' + m_c g (r/2) c, with x = r cos(theta).
        let tau = (jo + M_YOKE * R * R * s * s) * thetadd
            + M_YOKE * R * R * s * c * thetad * thetad
            + M_CRANK * G * R / 2.0 * c;
        assemble_into(&mech, &[theta], &mut ws).unwrap();
        inverse(&mech, &[theta], &[thetad], &[thetadd], &mut ws).unwrap();
        assert!((ws.tau[0] - tau).abs() < 1e-12, "theta {theta}: tau {} vs {tau}", ws.tau[0]);
        // Forward with the model's 0.5 N m: theta'' and the slot's normal force, the only
        // horizontal force on the yoke: the yoke (a) pushes the pin (b) with -m_y x''.
        forward(&mech, 0.0, &[theta], &[thetad], &mut ModelDrives(&mech), &mut ws).unwrap();
        let qdd = yoke_qdd(theta, thetad, 0.5);
        assert!((ws.qdd[0] - qdd).abs() < 1e-10 * qdd.abs().max(1.0), "qdd {} vs {qdd}", ws.qdd[0]);
        let xdd = -R * c * thetad * thetad - R * s * qdd;
        let slot = reactions(&mech, &mut ws)[1];
        assert!((slot[0] + M_YOKE * xdd).abs() < 1e-10, "slot force {slot:?} vs {}", -M_YOKE * xdd);
        assert!(slot[1].abs() < 1e-12 && slot[2] == 0.0, "normal to the vertical slot, no couple: {slot:?}");
    }
}

#[test]
fn scotch_yoke_keeps_its_energy() {
    let mech = shipped("scotch-yoke.yaml");
    let tr = run(&mech, "dop853", 1.0, 1e-11, None);
    assert!(tr.stats.energy_drift < 1e-9, "energy drift {} J", tr.stats.energy_drift);
    assert!(tr.stats.max_residual < 1e-11, "loop closure {}", tr.stats.max_residual);
}

#[test]
fn geared_five_bar_swings_with_its_energy() {
    let mech = shipped("geared-five-bar.yaml");
    assert_eq!(mech.dof(), 1);
    let tr = run(&mech, "dop853", 1.0, 1e-11, None);
    // Released from rest: E = V = g (sum of m y_com) in the drawing, from the file's points.
    let y = |p: &str| mech.points[mech.point_id(p).unwrap().0].1[1];
    let (c1, c2, p) = (y("C1"), y("C2"), y("P"));
    let v0 = 9.81 * (0.5 * c1 / 2.0 + 0.5 * c2 / 2.0 + 0.7 * (c1 + p) / 2.0 + 0.3 * p + 0.7 * (c2 + p) / 2.0);
    assert!((energy(&tr, 0) - v0).abs() < 1e-12, "E0 {} vs {v0}", energy(&tr, 0));
    assert!(tr.stats.energy_drift < 1e-9, "energy drift {} J", tr.stats.energy_drift);
    // The gear row holds along the run: theta2 - theta2_0 = -(r1/r2)(theta1 - theta1_0).
    let nx = mech.n_x();
    for k in 0..tr.len() {
        let x = &tr.x[k * nx..(k + 1) * nx];
        let (d1, d2) = (x[2] - mech.x0[2], x[5] - mech.x0[5]);
        assert!((d2 + 0.12 / 0.18 * d1).abs() < 1e-12, "gear row at output {k}");
    }
}

#[test]
fn a_slot_can_be_the_input() {
    // The yoke driven by the pin's travel along the slot: s = r sin(theta) (drawn 0.05 m).
    let text =
        std::fs::read_to_string(format!("{}/../../examples/models/scotch-yoke.yaml", env!("CARGO_MANIFEST_DIR")))
            .unwrap()
            .replace(
                "{name: theta, pair: crank_pivot, value: 0.5235987755982988, qd0: 2.0}",
                "{name: s, pair: pin, value: 0.05}",
            )
            .replace("{coordinate: theta, effort: 0.5}", "{coordinate: s, effort: 1.0}");
    let mech = loads(&text, Format::Yaml, "<yoke by slot>").unwrap();
    for s in [0.07, -0.03, 0.0] {
        let ws = analogues(&mech, &[s]);
        let theta: f64 = f64::asin(s / R);
        assert!((ws.x[2] - theta).abs() < 1e-12, "s {s}: crank angle {} vs {theta}", ws.x[2]);
        // d(theta)/ds = 1 / (r cos(theta)).
        assert!((ws.u[2] - 1.0 / (R * theta.cos())).abs() < 1e-9, "dtheta/ds {}", ws.u[2]);
    }
}

#[test]
fn one_row_pairs_count_one_row() {
    let mech = shipped("gear-train.yaml");
    // 3 revolute + 1 prismatic (2 rows each), 3 gears (1 row each).
    assert_eq!(mech.n_pair_rows(), 11);
    assert_eq!(mech.n_constraints, 11);
    assert_eq!(mech.pair_rows(PairId(3)), 6..8);
    assert_eq!(mech.pair_rows(PairId(4)), 8..9);
    assert_eq!(mech.pair_rows(PairId(6)), 10..11);
    assert_eq!((0..11).map(|r| mech.row_pair(r).0).collect::<Vec<_>>(), [0, 0, 1, 1, 2, 2, 3, 3, 4, 5, 6]);
    let structure = planardyn::structure::analyse(&mech, &mech.x0).unwrap();
    assert_eq!((structure.rank, structure.mobility), (11, 1));
    let yoke = shipped("scotch-yoke.yaml");
    assert_eq!((yoke.n_pair_rows(), yoke.dof()), (5, 1));
    // The Jacobian pattern of the pair rows: a gear row touches the angles only.
    let pattern = planardyn::kinematics::constraints::jacobian_pattern(&mech, &Chart::Inputs);
    assert_eq!(pattern[8], vec![2, 5]);
}

/// The message and path of a refused model.
fn refused(text: &str) -> (String, String) {
    match loads(text, Format::Yaml, "m.yaml") {
        Err(e) => (e.to_string(), e.path().to_string()),
        Ok(_) => panic!("accepted:\n{text}"),
    }
}

fn gear_train() -> String {
    std::fs::read_to_string(format!("{}/../../examples/models/gear-train.yaml", env!("CARGO_MANIFEST_DIR"))).unwrap()
}

#[test]
fn gear_pair_errors_name_the_field_and_the_fix() {
    let (msg, path) = refused(&gear_train().replace("radii: [0.02, 0.06]", "radii: [0.02, 0.05]"));
    assert_eq!(path, "pairs[4].radii");
    assert!(msg.contains("do not touch") && msg.contains("change `radii`"), "{msg}");
    let (msg, path) = refused(
        &gear_train()
            .replace("{name: theta, pair: pinion_shaft, value: 0.0}", "{name: theta, pair: mesh1, value: 0.0}"),
    );
    assert_eq!(path, "coordinates[0].pair");
    assert!(msg.contains("no relative coordinate") && msg.contains("revolute pair of one of its gears"), "{msg}");
    let (msg, path) =
        refused(&gear_train().replace("centers: [O1, O2], radii", "carrier: rack, centers: [O1, O2], radii"));
    assert_eq!(path, "pairs[4].centers[0]");
    assert!(msg.contains("does not carry centre 'O1'"), "{msg}");
    let (msg, path) = refused(&gear_train().replace("radii: [0.02], rack", "radii: [0.03], rack"));
    assert_eq!(path, "pairs[6].radii");
    assert!(msg.contains("rack's pitch line"), "{msg}");
    let (msg, path) =
        refused(&gear_train().replace("centers: [O1], radii: [0.02], rack", "centers: [O1, O2], radii: [0.02], rack"));
    assert_eq!(path, "pairs[6].centers");
    assert!(msg.contains("[A]"), "{msg}");
    let (msg, path) =
        refused(&gear_train().replace("drives:", "loads:\n  - {type: friction, pair: mesh2, viscous: 0.1}\ndrives:"));
    assert_eq!(path, "loads[0].pair");
    assert!(msg.contains("no relative motion"), "{msg}");
}
