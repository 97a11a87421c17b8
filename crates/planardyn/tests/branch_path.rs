//! The map of a mechanism with a class III triad (the shipped 3-RRR over its first two inputs,
//! the third held, and the 3-RPR over its first two leg lengths, whose triad's legs are
//! cylinders) on the branch of the drawing (`kinematics::BranchPath`, used by
//! `dynamics::map_rows`): each cell is the configuration reached from the drawing along the
//! straight path in the coordinates without leaving the drawing's assembly mode, and is missing
//! exactly where that path is blocked. Checked against an independent continuation (general
//! Newton on the whole J, steps a tenth as long, the triad's mode computed from the world
//! points at every step) and against the assembly the Python API gives
//! (`assemble_from`, `assemble(q, x_start=)`).

mod common;
use common::*;
use planardyn::dynamics::{map_rows, query::point_positions, MapGrid};
use planardyn::kinematics::{assemble_from, sigma_min, solve_position, Chart, Frame};
use planardyn::model::CoordinateKind;
use planardyn::Mechanism;
use std::f64::consts::PI;

/// The page's grid (web/src/map.js) at 40 x 40 (the page's 100 x 100 takes the reference
/// continuation too long for a test): cell centres over q +- pi for an angle, q +- L for a
/// displacement (`coordinateRange`).
const N: usize = 40;
/// The reference continuation's largest step (rad, or L for a displacement): a tenth of the
/// map's (0.1), so that between two steps the platform moves far less than the distance to
/// another assembly mode.
const FINE_STEP: f64 = 0.01;
/// The most a body may move in one of those steps (m / L, rad): a step that moves it further
/// is halved (near a fold), as is one that fails or changes side: a jump to another assembly
/// mode of the same side (near the triad's cusps) moves it as far however short the step.
const FINE_MOVE: f64 = 0.1;
/// The shortest step of the continuation (rad, or L): a path that needs a shorter one is
/// blocked (it ends at a fold within 1e-6 of the last point reached, a thousandth of
/// `BranchPath`'s MIN_STEP).
const FINE_MIN: f64 = 1e-6;
/// The same configuration reached two ways agrees to Newton's tolerance (POSITION_TOL 1e-14,
/// scaled) amplified by the conditioning near a fold; 1e-9 (m, rad) is the figure and
/// leaves that margin (the worst measured is printed).
const SAME: f64 = 1e-9;

/// A model with a class III triad whose legs' outer pairs are at the points `{outer}1..3`
/// (B_i, the 3-RRR's elbows; A_i, the 3-RPR's base pivots: its legs are the locked cylinders),
/// the inner ones at C1..3 on the platform, whose point is P.
struct Triad {
    mech: Mechanism,
    outer: &'static str,
}

/// The sign of the determinant of the triad's platform Jacobian, rows (e_i, (C_i - P) x e_i)
/// with e_i = C_i - B_i (leg i from its outer pair to the platform's), from the world points of
/// the model file: the triad's assembly mode side (it changes only through its type II
/// singularity).
fn triad_side(triad: &Triad, x: &[f64]) -> f64 {
    let mech = &triad.mech;
    let at = point_positions(mech, x);
    let p = |n: &str| {
        let i = mech.point_id(n).unwrap().0;
        [at[2 * i], at[2 * i + 1]]
    };
    let o = p("P");
    let rows: Vec<[f64; 3]> = (1..=3)
        .map(|i| {
            let (b, c) = (p(&format!("{}{i}", triad.outer)), p(&format!("C{i}")));
            let e = [c[0] - b[0], c[1] - b[1]];
            let l = [c[0] - o[0], c[1] - o[1]];
            [e[0], e[1], l[0] * e[1] - l[1] * e[0]]
        })
        .collect();
    let [a, b, c] = [rows[0], rows[1], rows[2]];
    (a[0] * (b[1] * c[2] - b[2] * c[1]) - a[1] * (b[0] * c[2] - b[2] * c[0]) + a[2] * (b[0] * c[1] - b[1] * c[0]))
        .signum()
}

/// Per coordinate the unit of its range and steps: 1 for an angle, L for a displacement.
fn units(mech: &Mechanism) -> Vec<f64> {
    mech.coordinates.iter().map(|c| if c.kind == CoordinateKind::Angle { 1.0 } else { mech.scale }).collect()
}

/// The drawing continued to q along the straight path in the coordinates by plain Newton on
/// the whole J (`solve_position`, each step from the last solution) in steps of at most
/// FINE_STEP, each halved while it fails, leaves the drawing's triad side or moves a body by
/// more than FINE_MOVE, refused once a step below FINE_MIN does: a continuation that stays on
/// the branch, independent of `BranchPath`'s closed forms. (Halving, not refusing at once: near
/// a fold the branch itself moves the bodies by 1 / sigma per unit of q, beyond FINE_MOVE /
/// FINE_STEP = 10 at the 3-RPR's sigma ~ 0.01, while a step to another assembly mode moves them
/// as far however short it is.)
fn continued_on_branch(triad: &Triad, q: &[f64], frame: &mut Frame) -> Option<Vec<f64>> {
    let mech = &triad.mech;
    let (q0, side) = (mech.drawn_q(), triad_side(triad, &mech.x0));
    let span = q.iter().zip(&q0).zip(units(mech)).fold(0.0_f64, |a, ((q, z), u)| a.max((q - z).abs() / u));
    let h_max = if span > 0.0 { (FINE_STEP / span).min(1.0) } else { 1.0 };
    frame.x.copy_from_slice(&mech.x0);
    let (mut s, mut h) = (0.0_f64, h_max);
    while s < 1.0 {
        let s_new = (s + h).min(1.0);
        let z: Vec<f64> = q0.iter().zip(q).map(|(z, q)| z + (q - z) * s_new).collect();
        let last = frame.x.clone();
        let solved = solve_position(mech, &z, frame).is_ok();
        let moved = frame.x.chunks(3).zip(last.chunks(3)).fold(0.0_f64, |d, (a, b)| {
            d.max((a[0] - b[0]).abs().max((a[1] - b[1]).abs()) / mech.scale).max((a[2] - b[2]).abs())
        });
        if solved && triad_side(triad, &frame.x) == side && moved <= FINE_MOVE {
            (s, h) = (s_new, (2.0 * h).min(h_max));
        } else {
            frame.x.copy_from_slice(&last);
            h /= 2.0;
            if h * span < FINE_MIN {
                return None;
            }
        }
    }
    Some(frame.x.clone())
}

/// The map's rows over th1 (columns) and th2 (rows) in the page's order (the middle row, the
/// rows above, then those below, in two calls as the page makes them), with each cell's
/// configuration: per cell (sigma, x), None where missing.
fn map_with_poses(mech: &Mechanism, axes: [&[f64]; 2], rows: &[usize]) -> Vec<Option<(f64, Vec<f64>)>> {
    let q = mech.drawn_q();
    let mut out = vec![None; N * N];
    let mut poses = Vec::new();
    for part in [&rows[..N / 2], &rows[N / 2..]] {
        let grid = MapGrid::new(mech, [0, 1], axes, N / 2, part, &mech.x0).unwrap();
        let map = map_rows(mech, &q, &grid, |_, ws| {
            poses.push(ws.frame.x.clone());
            Some(sigma_min(mech, &Chart::Inputs, &ws.frame.x))
        });
        assert_eq!(map.x, mech.x0, "the branch's reference is handed on");
        let mut placed = poses.drain(..);
        for (r, &j) in part.iter().enumerate() {
            for i in 0..N {
                let s = map.values[r * N + i];
                out[j * N + i] = s.is_finite().then(|| (s, placed.next().unwrap()));
            }
        }
    }
    out
}

fn largest_difference(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).fold(0.0, |d, (a, b)| d.max((a - b).abs()))
}

/// The map's axes over the first two coordinates: N cell centres over each one's range.
fn axes(mech: &Mechanism) -> [Vec<f64>; 2] {
    let (q, unit) = (mech.drawn_q(), units(mech));
    let half = |k: usize| if mech.coordinates[k].kind == CoordinateKind::Angle { PI } else { unit[k] };
    [0, 1].map(|k| (0..N).map(|i| q[k] - half(k) + 2.0 * half(k) * (i as f64 + 0.5) / N as f64).collect())
}

/// Every cell of the triad's 40 x 40 map against the fine continuation and `assemble_from`;
/// the number of cells present.
fn check_map(triad: &Triad) -> usize {
    let mech = &triad.mech;
    assert!(
        planardyn::kinematics::ClosedForm::new(mech).is_some_and(|c| !c.is_explicit()),
        "{} is placed by its triad's Newton: the branch path is the one tested",
        mech.name
    );
    let q = mech.drawn_q();
    let [a0, a1] = axes(mech);
    let rows: Vec<usize> = (N / 2..N).chain((0..N / 2).rev()).collect();
    let map = map_with_poses(mech, [&a0, &a1], &rows);
    let side = triad_side(triad, &mech.x0);
    let mut frame = Frame::new(mech);
    let (mut present, mut worst_fine, mut worst_api, mut api_other, mut api_beyond) = (0, 0.0_f64, 0.0_f64, 0, 0);
    for j in 0..N {
        for i in 0..N {
            let mut cell = q.clone();
            (cell[0], cell[1]) = (a0[i], a1[j]);
            let fine = continued_on_branch(triad, &cell, &mut frame);
            let at = &map[j * N + i];
            assert_eq!(at.is_some(), fine.is_some(), "cell ({j}, {i}) at {cell:?}: present in the map vs reached");
            let api = assemble_from(mech, &mech.x0, &cell, &mut frame).is_ok() && triad_side(triad, &frame.x) == side;
            let (Some((s, x)), Some(fine)) = (at, fine) else {
                api_beyond += usize::from(api);
                continue;
            };
            present += 1;
            // The drawing's mode at every cell shown: never filled from another branch.
            assert_eq!(triad_side(triad, x), side, "cell ({j}, {i})");
            let d = largest_difference(x, &fine);
            worst_fine = worst_fine.max(d);
            assert!(d <= SAME, "cell ({j}, {i}): x differs from the continuation's by {d:e}");
            assert!((s - sigma_min(mech, &Chart::Inputs, &fine)).abs() <= SAME, "cell ({j}, {i}): sigma {s}");
            // The Python API's assembly from the drawing (the same straight path, its own
            // steps): the same configuration wherever it stays in the drawing's mode.
            if api {
                let d = largest_difference(x, &frame.x);
                worst_api = worst_api.max(d);
                assert!(d <= SAME, "cell ({j}, {i}): x differs from assemble_from's by {d:e}");
            } else {
                api_other += 1;
            }
        }
    }
    println!(
        "{}: {present} of {} cells on the drawing's branch; x vs the fine continuation {worst_fine:.2e}, \
         vs assemble_from {worst_api:.2e} ({api_other} cells where assemble_from fails or leaves the mode; \
         {api_beyond} missing cells where it lands in the drawing's mode, past a fold)",
        mech.name,
        N * N
    );
    present
}

#[test]
fn a_triads_map_cell_is_the_drawing_continued_on_its_branch_and_missing_where_that_is_blocked() {
    let present = check_map(&Triad { mech: shipped("3-rrr.yaml"), outer: "B" });
    // Both kinds of cell are on this grid (181 present measured): a map neither all present
    // nor all missing.
    assert!(present > N * N / 20 && present < N * N / 2, "{present} cells present");
}

#[test]
fn a_3rpr_map_cell_is_the_drawing_continued_on_its_branch_and_missing_where_that_is_blocked() {
    // The triad's legs are cylinders (barrel and rod locked by the leg's prismatic input), its
    // coordinates displacements: the map's axes are L1 and L2 +- L, its steps 0.1 L.
    let present = check_map(&Triad { mech: shipped("library/3-rpr.yaml"), outer: "A" });
    // 148 present measured.
    assert!(present > N * N / 20 && present < N * N / 2, "{present} cells present");
}

#[test]
fn a_triads_map_cell_is_the_same_whatever_else_is_computed() {
    // Each cell on its own: a cell asked alone (a one-cell grid) equals, to the bit, the same
    // cell in the whole map, whatever the rows' order.
    let mech = shipped("3-rrr.yaml");
    let q = mech.drawn_q();
    let [a0, a1] = axes(&mech);
    let rows: Vec<usize> = (0..N).rev().collect();
    let grid = MapGrid::new(&mech, [0, 1], [&a0, &a1], 0, &rows, &mech.x0).unwrap();
    let whole = map_rows(&mech, &q, &grid, |_, ws| Some(sigma_min(&mech, &Chart::Inputs, &ws.frame.x)));
    let (mut present, mut missing) = (0, 0);
    for (r, &j) in rows.iter().enumerate().step_by(3) {
        for i in (0..N).step_by(3) {
            let (c0, c1) = ([a0[i]], [a1[j]]);
            let one = MapGrid::new(&mech, [0, 1], [&c0, &c1], 0, &[0], &mech.x0).unwrap();
            let alone = map_rows(&mech, &q, &one, |_, ws| Some(sigma_min(&mech, &Chart::Inputs, &ws.frame.x)));
            let (a, b) = (alone.values[0], whole.values[r * N + i]);
            assert!(a.to_bits() == b.to_bits() || (a.is_nan() && b.is_nan()), "cell ({j}, {i}): {a} vs {b}");
            if a.is_nan() {
                missing += 1;
            } else {
                present += 1;
            }
        }
    }
    assert!(present > 0 && missing > 0, "{present} present, {missing} missing among the sampled cells");
}
