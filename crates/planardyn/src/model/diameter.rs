//! The diameter of a point set (the largest distance between two of its points) in
//! O(n log n): the convex hull by Andrew's monotone chain, then rotating calipers over the
//! antipodal pairs of the hull (Shamos 1978; Preparata & Shamos, "Computational Geometry",
//! 4.2.3). Written here because it is 40 lines and the geometry crates that have it bring a
//! GIS stack; the all-pairs scan it replaces made loading quadratic in the number of points.

/// Largest distance between two of `points` (m); 0 for fewer than two distinct points.
/// Equal, bit for bit, to the maximum of `hypot` over all pairs: the farthest pair is a pair
/// of hull vertices, and its distance is computed by the same expression.
pub fn diameter(points: &[[f64; 2]]) -> f64 {
    let hull = convex_hull(points);
    let n = hull.len();
    let dist = |a: [f64; 2], b: [f64; 2]| (a[0] - b[0]).hypot(a[1] - b[1]);
    match n {
        0 | 1 => 0.0,
        2 => dist(hull[0], hull[1]),
        _ => {
            let mut best: f64 = 0.0;
            let mut j = 1;
            for i in 0..n {
                let next = (i + 1) % n;
                // Advance j while it moves away from the edge (i, next).
                while cross(hull[i], hull[next], hull[(j + 1) % n]) > cross(hull[i], hull[next], hull[j]) {
                    j = (j + 1) % n;
                }
                // With an edge parallel to (i, next), both ends of it are antipodal to i and
                // next, and rounding decides which one the strict comparison stops at: look
                // at the vertices on both sides of j too.
                for k in [j + n - 1, j, j + 1] {
                    best = best.max(dist(hull[i], hull[k % n])).max(dist(hull[next], hull[k % n]));
                }
            }
            best
        }
    }
}

/// (b - a) x (c - a): positive when a, b, c turn counter-clockwise.
fn cross(a: [f64; 2], b: [f64; 2], c: [f64; 2]) -> f64 {
    (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0])
}

/// Vertices of the convex hull, counter-clockwise, without collinear or repeated points.
fn convex_hull(points: &[[f64; 2]]) -> Vec<[f64; 2]> {
    let mut p: Vec<[f64; 2]> = points.to_vec();
    p.sort_by(|a, b| a[0].total_cmp(&b[0]).then(a[1].total_cmp(&b[1])));
    p.dedup();
    if p.len() < 3 {
        return p;
    }
    let mut hull = half_hull(p.iter());
    let mut upper = half_hull(p.iter().rev());
    // The last point of each chain is the first of the other.
    hull.pop();
    upper.pop();
    hull.extend(upper);
    hull
}

/// One chain of the monotone-chain hull: the points kept turning left, in the given order.
fn half_hull<'a>(points: impl Iterator<Item = &'a [f64; 2]>) -> Vec<[f64; 2]> {
    let mut chain: Vec<[f64; 2]> = Vec::new();
    for &q in points {
        while chain.len() >= 2 && cross(chain[chain.len() - 2], chain[chain.len() - 1], q) <= 0.0 {
            chain.pop();
        }
        chain.push(q);
    }
    chain
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    fn brute(points: &[[f64; 2]]) -> f64 {
        let mut l: f64 = 0.0;
        for (i, a) in points.iter().enumerate() {
            for b in &points[i + 1..] {
                l = l.max((a[0] - b[0]).hypot(a[1] - b[1]));
            }
        }
        l
    }

    #[test]
    fn known_sets() {
        // A unit square's diameter is its diagonal; collinear points their extremes.
        assert_eq!(diameter(&[[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]]), 2f64.sqrt());
        assert_eq!(diameter(&[[0.0, 0.0], [1.0, 0.0], [3.0, 0.0], [2.0, 0.0]]), 3.0);
        assert_eq!(diameter(&[[1.0, 2.0], [1.0, 2.0]]), 0.0);
        assert_eq!(diameter(&[]), 0.0);
        // A trapezoid with two parallel edges (found by the property test below): the
        // farthest pair (-0.2, 0)-(0.3, -0.2), 0.5385, is one of two tied antipodal pairs.
        let trapezoid = [[-0.2, 0.0], [-0.1, -0.2], [0.30000000000000004, -0.2], [0.2, 0.0]];
        assert_eq!(diameter(&trapezoid), brute(&trapezoid));
    }

    proptest! {
        // Bit-identical to the all-pairs scan, on general sets and on sets with many ties
        // (points on a small integer grid: collinear and repeated points).
        #[test]
        fn equals_all_pairs(pts in prop::collection::vec((-1e3f64..1e3, -1e3f64..1e3), 0..60),
                            grid in prop::collection::vec((-3i32..4, -3i32..4), 0..40)) {
            let a: Vec<[f64; 2]> = pts.iter().map(|&(x, y)| [x, y]).collect();
            prop_assert_eq!(diameter(&a), brute(&a));
            let g: Vec<[f64; 2]> = grid.iter().map(|&(x, y)| [x as f64 * 0.1, y as f64 * 0.1]).collect();
            prop_assert_eq!(diameter(&g), brute(&g));
        }
    }
}
