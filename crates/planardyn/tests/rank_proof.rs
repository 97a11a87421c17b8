//! The loader's rank test (`kinematics::rank_proof`: a sparse elimination and two proofs, the
//! SVD only where they do not settle it) gives the SVD's answer: the same rank, the same
//! independent rows and as many self-stresses as `structure::analyse` (the SVD of Phi_x), on
//! every shipped model, on chains of parallelograms (redundant constraints), at and near a
//! change point, and at random perturbations of all of these from 1e-14 to 1e-2.

mod common;
use common::*;
use planardyn::kinematics::assemble;
use planardyn::kinematics::rank_proof::{independent_rows, proven_rank};
use planardyn::structure::analyse;
use planardyn::Mechanism;

/// How often the proofs decided and how often the SVD had to.
#[derive(Default, Debug)]
struct Count {
    proven: usize,
    svd: usize,
}

/// The rank test at x against the SVD's; the count of who decided.
fn check(mech: &Mechanism, x: &[f64], label: &str, count: &mut Count) {
    let svd = analyse(mech, x).unwrap();
    let got = independent_rows(mech, x);
    assert_eq!(got.rank, svd.rank, "{label}: rank");
    assert_eq!(got.rows, svd.independent_rows, "{label}: independent rows");
    assert_eq!(got.stresses.len(), svd.self_stresses.len(), "{label}: self-stresses");
    if svd.self_stresses.len() == 1 {
        // A one-dimensional null space: the stress is unique up to sign, so are its pairs.
        assert_eq!(got.stresses[0], svd.self_stresses[0].pairs, "{label}: the stress's pairs");
    }
    match proven_rank(mech, x) {
        Some(p) => {
            assert_eq!(p, got, "{label}");
            count.proven += 1;
        }
        None => count.svd += 1,
    }
}

/// x plus `eps` times a pseudo-random vector of entries in [-1, 1) (m and rad).
fn perturbed(x: &[f64], eps: f64, seed: &mut u64) -> Vec<f64> {
    x.iter()
        .map(|v| {
            *seed = seed.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
            v + eps * (((*seed >> 11) as f64 / (1u64 << 53) as f64) * 2.0 - 1.0)
        })
        .collect()
}

/// The perturbations tried around each configuration: from below the rank tolerance
/// (RANK_TOL = 1e-9, relative) to far above it, through the band where the SVD decides.
const EPS: [f64; 8] = [1e-14, 1e-12, 1e-10, 1e-9, 1e-8, 1e-6, 1e-4, 1e-2];

fn check_around(mech: &Mechanism, x: &[f64], label: &str, count: &mut Count) {
    check(mech, x, label, count);
    let mut seed = 2026;
    for eps in EPS {
        for k in 0..2 {
            check(mech, &perturbed(x, eps, &mut seed), &format!("{label} + {eps:e} ({k})"), count);
        }
    }
}

/// n triple-crank parallelograms in a row: 2n + 1 cranks of 1 m hung at (i / 2, 0), coupler i
/// joining the tips of cranks 2i - 2, 2i - 1 and 2i, each window the triple crank of
/// [`PARALLELOGRAM`]: n redundant constraints (Chebyshev-Grubler 1 - n, mobility 1). The
/// cranks' direction is rounded to multiples of 2^-40 (as benchmarks/families.py does), so
/// that every window is an exact parallelogram.
fn parallelograms(n: usize) -> Mechanism {
    let q = 2f64.powi(40);
    let angle = -std::f64::consts::FRAC_PI_2 + 0.5;
    let (c, s) = ((angle.cos() * q).round() / q, (angle.sin() * q).round() / q);
    let (mut points, mut bodies, mut pairs) = (String::new(), String::new(), String::new());
    for i in 0..=2 * n {
        let x = i as f64 / 2.0;
        points += &format!("  O{i}: [{x:?}, 0.0]\n  A{i}: [{:?}, {s:?}]\n", x + c);
        bodies += &format!("  rod{i}: {{points: [O{i}, A{i}], uniform_bar: [O{i}, A{i}], mass: 1.0}}\n");
        pairs += &format!("  - {{type: revolute, name: g{i}, at: O{i}, bodies: [ground, rod{i}]}}\n");
    }
    for i in 1..=n {
        let (a, m, b) = (2 * i - 2, 2 * i - 1, 2 * i);
        bodies += &format!("  coupler{i}: {{points: [A{a}, A{b}, A{m}], uniform_bar: [A{a}, A{b}], mass: 1.0}}\n");
        for k in [a, m, b] {
            pairs += &format!("  - {{type: revolute, at: A{k}, bodies: [rod{k}, coupler{i}]}}\n");
        }
    }
    let ground: Vec<String> = (0..=2 * n).map(|i| format!("O{i}")).collect();
    yaml(&format!(
        "name: parallelograms\ngravity: [0, -9.81]\npoints:\n{points}ground: [{}]\nbodies:\n{bodies}pairs:\n{pairs}\
         coordinates:\n  - {{name: theta, pair: g0, value: {angle:?}}}\n",
        ground.join(", ")
    ))
}

#[test]
fn every_shipped_model_gets_the_svds_rank_and_the_proofs_decide_at_its_drawing() {
    let mut count = Count::default();
    for mech in every_model() {
        let mut at_drawing = Count::default();
        check(&mech, &mech.x0, &mech.name, &mut at_drawing);
        assert_eq!(at_drawing.svd, 0, "{}: the drawing is far from singular, the proofs must settle it", mech.name);
        check_around(&mech, &mech.x0, &mech.name, &mut count);
    }
    eprintln!("shipped models and perturbations: {count:?}");
}

#[test]
fn parallelogram_chains_have_one_local_self_stress_per_window() {
    let mut count = Count::default();
    for n in 1..=6 {
        let mech = parallelograms(n);
        let label = format!("{n} parallelograms");
        assert_eq!(mech.n_constraints, mech.n_pair_rows() - n, "{label}");
        let proven = proven_rank(&mech, &mech.x0).expect("an exact parallelogram chain is far from the threshold");
        // Each stress stays within its window (6 pairs, as the triple crank's one stress).
        for (k, s) in proven.stresses.iter().enumerate() {
            assert!(s.len() <= 6, "{label}: stress {k} over {} pairs: {:?}", s.len(), s);
        }
        check_around(&mech, &mech.x0, &label, &mut count);
    }
    eprintln!("parallelogram chains: {count:?}");
}

#[test]
fn at_and_near_a_change_point_the_rank_is_the_svds() {
    // The triple-crank parallelogram at theta = 0: every pin on the ground line, where the
    // coupler could also turn (rank 10 instead of 11): drawn exactly (cranks and coupler along
    // +x), and assembled at theta -> 0 (the assembly at 0 itself lands 1e-8 off the line, where
    // the SVD sees rank 12). The drawings within ~1e-6 of it are where the proofs give way.
    let mech = yaml(PARALLELOGRAM);
    let mut count = Count::default();
    let change_point = [0.15, 0.0, 0.0, 0.65, 0.0, 0.0, 1.15, 0.0, 0.0, 0.8, 0.0, 0.0];
    check_around(&mech, &change_point, "change point", &mut count);
    assert_eq!(independent_rows(&mech, &change_point).rank, 10, "the change point's rank");
    for theta in [1e-1, 1e-3, 1e-5, 1e-7, 1e-9, 1e-11, 0.0] {
        let x = assemble(&mech, &[theta]).unwrap();
        check_around(&mech, &x, &format!("theta {theta:e}"), &mut count);
    }
    assert!(count.svd > 0 && count.proven > 0, "{count:?}");
    eprintln!("change point: {count:?}");
}
