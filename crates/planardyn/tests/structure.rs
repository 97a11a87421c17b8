//! Structural analysis: rank, mobility, self-stresses, loops and Assur groups, against counts
//! derived by hand (Chebyshev-Grubler, Euler's p - n loops, Artobolevsky's classes) and the
//! statics of a parallelogram's self-stress.

mod common;
use common::*;
use planardyn::loader::analyse_spec;
use planardyn::model::{BodyId, PairId};
use planardyn::structure::{analyse, scaled_constraint_jacobian, Structure};
use planardyn::{Format, KinematicsError, Mechanism};

fn drawn(mech: &Mechanism) -> Structure {
    analyse(mech, &mech.x0).unwrap()
}

/// (class, order, kind, link names) of every group.
fn groups(s: &Structure) -> Vec<(usize, usize, String, Vec<String>)> {
    s.groups
        .iter()
        .map(|g| (g.class, g.order, g.kind.clone(), g.links.iter().map(|l| s.link_name(l)).collect()))
        .collect()
}

fn dyad(kind: &str, a: &str, b: &str) -> (usize, usize, String, Vec<String>) {
    (2, 2, kind.into(), vec![a.into(), b.into()])
}

fn names(s: &Structure, bodies: &[BodyId]) -> Vec<String> {
    bodies.iter().map(|b| s.bodies[b.0].clone()).collect()
}

/// (grubler, mobility, rank, loops) and the rank is full (no self-stress).
fn counts(s: &Structure) -> (i64, usize, usize, usize) {
    (s.grubler, s.mobility, s.rank, s.n_loops())
}

#[test]
fn four_bar_is_a_crank_and_an_rrr_dyad() {
    // n = 3, p = 4: 3*3 - 2*4 = 1, rank 8, one loop (4 - 3); coupler + rocker: pairs A
    // (to the crank), B (inner), D (to ground).
    let s = drawn(&yaml(FOUR_BAR));
    assert_eq!(counts(&s), (1, 1, 8, 1));
    assert_eq!((s.redundant, s.self_stresses.len(), s.actuation), (0, 0, 1));
    assert!(s.fully_actuated() && s.connected);
    assert_eq!(s.singular_values.len(), 8);
    assert!(s.singular_values[0] > 1e-3, "{:?}", s.singular_values);
    assert_eq!(names(&s, &s.input_links), ["crank"]);
    assert_eq!(groups(&s), [dyad("RRR", "coupler", "rocker")]);
    assert_eq!(s.groups[0].description, "class II dyad RRR, order 2: coupler, rocker");
    assert!(s.left_over.is_empty() && s.left_over_mobility == 0);
}

#[test]
fn five_bar_two_inputs_one_dyad() {
    // n = 4, p = 5: 12 - 10 = 2; one loop; the distal links form an RRR dyad.
    let s = drawn(&shipped("five-bar.yaml"));
    assert_eq!(counts(&s), (2, 2, 10, 1));
    assert_eq!(s.input_links.len(), 2);
    assert_eq!(s.groups.len(), 1);
    assert_eq!((s.groups[0].class, s.groups[0].order, s.groups[0].kind.as_str()), (2, 2, "RRR"));
}

#[test]
fn three_rrr_is_a_class_iii_triad() {
    // n = 7, p = 9: 21 - 18 = 3; loops 9 - 7 = 2. No two free links close with 3 pairs, so
    // the three distal links and the platform (ternary base link, 3 inner pairs) are one
    // group of 6 pairs, 12 - 12 = 0: class III, order 3 (the pairs at the proximal links).
    let s = drawn(&yaml(RRR3));
    assert_eq!(counts(&s), (3, 3, 18, 2));
    assert_eq!(names(&s, &s.input_links), ["prox1", "prox2", "prox3"]);
    assert_eq!(
        groups(&s),
        [(3, 3, "6R".into(), vec!["dist1".into(), "dist2".into(), "dist3".into(), "platform".into()])]
    );
    assert_eq!(s.groups[0].description, "class III triad 6R, order 3: dist1, dist2, dist3, platform");
}

#[test]
fn andrews_squeezer_is_a_crank_and_three_dyads() {
    // n = 7, p = 10: 21 - 20 = 1; loops 10 - 7 = 3. Crank b1; b2 + b3 (P, E, B); then b4 + b5
    // (E on b2, G, A) and b6 + b7 (E on b2, H, A): three class II dyads (the blocks of J are
    // 1, 2, 6, 6, 6 in tests/positions.rs).
    let s = drawn(&shipped("andrews-squeezer.yaml"));
    assert_eq!(counts(&s), (1, 1, 20, 3));
    assert_eq!(names(&s, &s.input_links), ["b1"]);
    assert_eq!(groups(&s), [dyad("RRR", "b2", "b3"), dyad("RRR", "b4", "b5"), dyad("RRR", "b6", "b7")]);
}

#[test]
fn slider_crank_dyad_reads_rrp() {
    // Crank input; rod + slider: crank pin R (outer), wrist pin R (inner), guide P (outer).
    let s = drawn(&shipped("library/slider-crank.yaml"));
    assert_eq!(counts(&s), (1, 1, 8, 1));
    assert_eq!(groups(&s), [dyad("RRP", "rod", "slider")]);
}

#[test]
fn relative_inputs_lock_a_leg_into_one_link() {
    // 3-RPR: each leg's prismatic input locks barrel and rod into one link; the three legs and
    // the platform are the class III triad of the 3-RRR, its pairs all revolute.
    let s = drawn(&shipped("library/3-rpr.yaml"));
    assert_eq!(counts(&s), (3, 3, 18, 2));
    assert!(s.input_links.is_empty());
    let relative: Vec<&str> = s.relative_inputs.iter().map(|k| s.pairs[k.0].as_str()).collect();
    assert_eq!(relative, ["leg1", "leg2", "leg3"]);
    let legs = ["barrel1+rod1", "barrel2+rod2", "barrel3+rod3", "platform"].map(String::from).to_vec();
    assert_eq!(groups(&s), [(3, 3, "6R".into(), legs)]);
}

#[test]
fn redundant_parallelogram_has_one_self_stress_through_every_pair() {
    // Three equal parallel cranks at x = 0, 0.5, 1 under one coupler: 3*4 - 2*6 = 0, yet
    // rank 11 and mobility 1. The self-stress: each crank a two-force member with force f_i
    // along it; the coupler's balance f1 + f2 + f3 = 0 and 0.15 f1 + 0.65 f2 + 1.15 f3 = 0
    // (moments about the origin) give f1 = f3 = -f2 / 2: the middle crank's pairs carry
    // twice the others' share.
    let mech = yaml(PARALLELOGRAM);
    let s = drawn(&mech);
    assert_eq!(counts(&s), (0, 1, 11, 2));
    assert_eq!((s.redundant, s.self_stresses.len()), (1, 1));
    let stress = &s.self_stresses[0];
    assert_eq!(stress.pairs, (0..6).map(PairId).collect::<Vec<_>>());
    let share = |k: usize| mech.pair_rows(PairId(k)).map(|r| stress.lambda[r].powi(2)).sum::<f64>().sqrt();
    for (k, want) in [(0, 1.0), (1, 2.0), (2, 1.0), (3, 1.0), (4, 2.0), (5, 1.0)] {
        assert!((share(k) / share(0) - want).abs() < 1e-9, "pair {k}: {} vs {want}", share(k) / share(0));
    }
    // Phi_x^T lambda = 0 (scaled entries O(1): rounding ~1e-15).
    let (rows, n) = (mech.n_pair_rows(), mech.n_x());
    let j = scaled_constraint_jacobian(&mech, &mech.x0);
    for c in 0..n {
        let v: f64 = (0..rows).map(|r| j[r * n + c] * stress.lambda[r]).sum();
        assert!(v.abs() < 1e-12, "column {c}: {v}");
    }
    // The input crank, then crank 2 + coupler (the first six rows that close); crank 3
    // repeats a constraint: 3*1 - 2*2 = -1.
    assert_eq!(groups(&s), [dyad("RRR", "crank2", "coupler")]);
    assert_eq!(s.left_over, [vec![mech.body_id("crank3").unwrap()]]);
    assert_eq!(s.left_over_mobility, -1);
    // The loader keeps the rank's independent rows.
    assert_eq!(mech.n_constraints, s.independent_rows.len());
}

/// Stephenson's chain with a binary link as the ground (links T1, T2 ternary, b1, b2, b4
/// binary; b4 the input).
const STEPHENSON_BINARY_GROUND: &str = r#"
name: Stephenson chain on a binary link
points:
  J5: [0.0, 0.0]
  J6: [2.0, 0.0]
  J7: [2.3, 1.1]
  J1: [0.2, 1.0]
  J3: [0.9, 0.4]
  J2: [1.1, 1.9]
  J4: [1.8, 1.3]
ground: [J5, J6]
bodies:
  T1: {points: [J5, J1, J3], uniform_bar: [J5, J1], mass: 1.0}
  T2: {points: [J7, J2, J4], uniform_bar: [J7, J2], mass: 1.0}
  b1: {points: [J1, J2], uniform_bar: [J1, J2], mass: 1.0}
  b2: {points: [J3, J4], uniform_bar: [J3, J4], mass: 1.0}
  b4: {points: [J6, J7], uniform_bar: [J6, J7], mass: 1.0}
pairs:
  - {type: revolute, name: J5, at: J5, bodies: [ground, T1]}
  - {type: revolute, name: J6, at: J6, bodies: [ground, b4]}
  - {type: revolute, name: J7, at: J7, bodies: [b4, T2]}
  - {type: revolute, name: J1, at: J1, bodies: [T1, b1]}
  - {type: revolute, name: J2, at: J2, bodies: [b1, T2]}
  - {type: revolute, name: J3, at: J3, bodies: [T1, b2]}
  - {type: revolute, name: J4, at: J4, bodies: [b2, T2]}
coordinates:
  - {name: q, pair: J6, value: 0.0}
"#;

#[test]
fn stephenson_chain_on_a_binary_link_is_a_class_iv_group() {
    // n = 5, p = 7: 15 - 14 = 1, loops 7 - 5 = 2. With b4 locked, T1-b1-T2-b2 is a closed
    // four-link contour joined to the fixed links at J5 and J7: class IV, order 2
    // (Artobolevsky).
    let s = drawn(&yaml(STEPHENSON_BINARY_GROUND));
    assert_eq!(counts(&s), (1, 1, 14, 2));
    assert_eq!(names(&s, &s.input_links), ["b4"]);
    let g = &s.groups[..];
    assert_eq!(g.len(), 1);
    let outer: Vec<&str> = g[0].outer_pairs.iter().map(|k| s.pairs[k.0].as_str()).collect();
    assert_eq!((g[0].class, g[0].order, g[0].kind.as_str(), outer), (4, 2, "6R", vec!["J5", "J7"]));
    assert_eq!(g[0].description, "class IV group 6R, order 2: T1, T2, b1, b2");
}

#[test]
fn loops_close_and_count_pairs_minus_bodies() {
    // Each loop walks link, pair, link, ... and its last pair joins the last link back to
    // the first; a connected mechanism has p - (n + 1) + 1 = p - n of them.
    for mech in [yaml(FOUR_BAR), yaml(RRR3), shipped("andrews-squeezer.yaml"), yaml(PARALLELOGRAM)] {
        let s = drawn(&mech);
        assert_eq!(s.n_loops(), mech.pairs.len() - mech.n_bodies(), "{}", mech.name);
        for lp in &s.loops {
            assert_eq!(lp.links.len(), lp.pairs.len());
            assert_eq!(*lp.pairs.last().unwrap(), lp.closing_pair);
            for (i, &k) in lp.pairs.iter().enumerate() {
                let (a, b) = (lp.links[i], lp.links[(i + 1) % lp.links.len()]);
                let p = &mech.pairs[k.0];
                assert!((p.a, p.b) == (a, b) || (p.a, p.b) == (b, a), "{}: {lp:?}", mech.name);
            }
        }
    }
}

#[test]
fn a_model_the_loader_refuses_is_analysed_from_its_drawing() {
    // A four-bar with a second coordinate on the rocker: mobility 1 but 2 coordinates. The
    // rocker is then locked to the ground too, and the coupler alone, joined at A and B,
    // is over-constrained: 3*1 - 2*2 = -1.
    let text = FOUR_BAR
        .replace("{type: revolute, at: B,", "{type: revolute, name: B, at: B,")
        .replace("coordinates:\n", "coordinates:\n  - {name: extra, pair: B, value: 0.0}\n");
    let err = planardyn::loads(&text, Format::Yaml, "<test>").unwrap_err();
    assert!(err.to_string().contains("coordinates"), "{err}");
    let s = analyse_spec(&text, Format::Yaml, "<test>").unwrap();
    assert_eq!(counts(&s), (1, 1, 8, 1));
    assert_eq!((s.redundant, s.actuation, s.fully_actuated()), (0, 2, false));
    assert_eq!(names(&s, &s.input_links), ["crank"]);
    assert_eq!(s.relative_inputs, [PairId(2)]);
    assert!(s.groups.is_empty());
    assert_eq!(s.left_over_mobility, -1);
}

#[test]
fn links_a_missing_coordinate_leaves_free_are_left_over() {
    // The 3-RRR with two coordinates: the third proximal link, the distal links and the
    // platform are free to move with the pairs that touch them: 3*5 - 2*7 = 1.
    let text = RRR3.replace("  - {name: th3, pair: R3, value: 1.7769252074235635}\n", "");
    let s = analyse_spec(&text, Format::Yaml, "<test>").unwrap();
    assert_eq!(counts(&s), (3, 3, 18, 2));
    assert_eq!(names(&s, &s.input_links), ["prox1", "prox2"]);
    assert!(s.groups.is_empty());
    let left: Vec<String> = s.left_over.iter().map(|l| s.link_name(l)).collect();
    assert_eq!(left, ["dist1", "dist2", "prox3", "dist3", "platform"]);
    assert_eq!(s.left_over_mobility, 1);
}

#[test]
fn bad_coordinates_are_an_error_not_a_panic() {
    let mech = yaml(FOUR_BAR);
    let mut x = mech.x0.clone();
    assert!(matches!(analyse(&mech, &x[..5]), Err(KinematicsError::BadArgument { name: "x", .. })));
    x[4] = f64::NAN;
    assert!(matches!(analyse(&mech, &x), Err(KinematicsError::BadArgument { name: "x", .. })));
}
