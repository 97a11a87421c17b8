//! Position analysis keeps the branch (assembly mode) the mechanism is drawn in, however far
//! the coordinates move from the drawing.

mod common;
use common::*;
use planardyn::kinematics::assemble;
use planardyn::kinematics::constraints::world_point;
use planardyn::model::Link;

#[test]
fn four_bar_stays_on_its_drawn_assembly_mode() {
    let mech = yaml(FOUR_BAR);
    let coupler = mech.body_id("coupler").unwrap();
    let (a, b) = (mech.point_id("A").unwrap(), mech.point_id("B").unwrap());
    let at = |id| mech.attachment(Link::Body(coupler), id).unwrap().s;
    let d = [1.0, 0.0];
    // Assembly mode: the side of the line A-D on which B lies (the sign of (B-A) x (D-A)).
    let side = |x: &[f64]| {
        let (pa, pb) = (world_point(Link::Body(coupler), at(a), x), world_point(Link::Body(coupler), at(b), x));
        ((pb[0] - pa[0]) * (d[1] - pa[1]) - (pb[1] - pa[1]) * (d[0] - pa[0])).signum()
    };
    let drawn = side(&mech.x0);
    // A full turn and more, both ways: the crank of this crank-rocker turns all the way.
    for q in [-1.0, -2.5, 4.0, 8.0, -7.0, 1.0471975511965976 + 2.0 * std::f64::consts::PI] {
        let x = assemble(&mech, &[q]).unwrap();
        assert_eq!(side(&x), drawn, "q = {q}: jumped to the other assembly mode");
    }
    // A full turn of the crank gives back the drawing (to the Newton tolerance).
    let x = assemble(&mech, &[1.0471975511965976 + 2.0 * std::f64::consts::PI]).unwrap();
    for (i, (v, v0)) in x.iter().zip(&mech.x0).enumerate() {
        let expected = if i == 2 { v0 + 2.0 * std::f64::consts::PI } else { *v0 };
        assert!((v - expected).abs() < 1e-10, "x[{i}] = {v} vs {expected}");
    }
}

#[test]
fn output_grid_ends_exactly_at_t_end() {
    let t = planardyn::simulate::grid(0.0, 0.3, 0.1);
    assert_eq!(t.len(), 4);
    assert_eq!(*t.last().unwrap(), 0.3);
}

/// The block-triangular form of J that the position solves use has exactly the mechanism's
/// structure as its diagonal blocks: each input link (its angle row alone, then its two pin
/// rows) and each Assur group, in an order they can be solved in. A class-II dyad is 2 bodies
/// (6 coordinates), the 3-RRR's class-III triad 4 bodies (12), Andrews' squeezer three dyads.
#[test]
fn block_triangular_form_is_the_assur_decomposition() {
    use planardyn::kinematics::{constraints::jacobian_pattern, Chart};
    use planardyn::linalg::BlockLu;
    for (file, blocks) in [
        ("four-bar-gravity.yaml", vec![1, 2, 6]),
        ("five-bar.yaml", vec![1, 2, 1, 2, 6]),
        ("3-rrr.yaml", vec![1, 2, 1, 2, 1, 2, 12]),
        ("andrews-squeezer.yaml", vec![1, 2, 6, 6, 6]),
    ] {
        let mech = shipped(file);
        let lu = BlockLu::new(&jacobian_pattern(&mech, &Chart::Inputs));
        assert_eq!(lu.block_sizes().collect::<Vec<_>>(), blocks, "{file}");
    }
}
