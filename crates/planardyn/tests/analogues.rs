//! Velocity and acceleration analogues against central finite differences of the position
//! solution, symmetry of w, and the convective term against its definition.

mod common;
use common::*;
use planardyn::kinematics::{acceleration_analogues, assemble_into, convective, velocity_analogues};
use planardyn::Workspace;

/// Central differences with step 1e-5 have truncation error ~h^2 * x''' ~ 1e-10 and
/// round-off ~1e-16/1e-5 = 1e-11 for O(1) coordinates; 1e-7 leaves a wide margin.
const FD_TOL_U: f64 = 1e-7;
/// w is a difference of u, itself solved to ~1e-15: round-off ~1e-10, truncation ~1e-10.
const FD_TOL_W: f64 = 1e-6;
const H: f64 = 1e-5;

fn analysed(mech: &planardyn::Mechanism, q: &[f64]) -> Workspace {
    let mut ws = Workspace::new(mech);
    assemble_into(mech, q, &mut ws).unwrap();
    velocity_analogues(&mut ws).unwrap();
    ws
}

#[test]
fn velocity_analogues_match_finite_differences() {
    for mech in all_models() {
        let (q, _) = test_state(&mech);
        let ws = analysed(&mech, &q);
        for j in 0..mech.dof() {
            let (mut qp, mut qm) = (q.clone(), q.clone());
            qp[j] += H;
            qm[j] -= H;
            let (xp, xm) = (analysed(&mech, &qp).frame.x, analysed(&mech, &qm).frame.x);
            for i in 0..mech.n_x() {
                let fd = (xp[i] - xm[i]) / (2.0 * H);
                assert!(
                    (fd - ws.u_col(j)[i]).abs() < FD_TOL_U,
                    "{}: u[{i}][{j}] = {} vs FD {fd}",
                    mech.name,
                    ws.u_col(j)[i]
                );
            }
        }
    }
}

#[test]
fn acceleration_analogues_match_finite_differences_and_are_symmetric() {
    for mech in all_models() {
        let (q, _) = test_state(&mech);
        let mut ws = analysed(&mech, &q);
        let w = acceleration_analogues(&mech, &mut ws);
        let (n, m) = (mech.n_x(), mech.dof());
        for k in 0..m {
            let (mut qp, mut qm) = (q.clone(), q.clone());
            qp[k] += H;
            qm[k] -= H;
            let (wp, wm) = (analysed(&mech, &qp), analysed(&mech, &qm));
            for j in 0..m {
                for i in 0..n {
                    let fd = (wp.u_col(j)[i] - wm.u_col(j)[i]) / (2.0 * H);
                    let wjk = w[(j * m + k) * n + i];
                    assert!((fd - wjk).abs() < FD_TOL_W, "{}: w[{i}][{j}{k}] = {wjk} vs FD {fd}", mech.name);
                    assert_eq!(wjk, w[(k * m + j) * n + i], "w_jk = w_kj");
                }
            }
        }
    }
}

#[test]
fn convective_term_is_the_contraction_of_w_with_the_rates() {
    for mech in all_models() {
        let (q, qd) = test_state(&mech);
        let mut ws = analysed(&mech, &q);
        let w = acceleration_analogues(&mech, &mut ws);
        convective(&mech, &qd, &mut ws);
        let (n, m) = (mech.n_x(), mech.dof());
        for i in 0..n {
            let expected: f64 = (0..m)
                .flat_map(|j| (0..m).map(move |l| (j, l)))
                .map(|(j, l)| qd[j] * qd[l] * w[(j * m + l) * n + i])
                .sum();
            // Both come from the same factorisation: agreement to round-off.
            assert!(
                (ws.c[i] - expected).abs() < 1e-10 * (1.0 + expected.abs()),
                "{}: c[{i}] = {} vs {expected}",
                mech.name,
                ws.c[i]
            );
        }
    }
}
