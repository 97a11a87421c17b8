//! Alternative charts: other sets of m pair coordinates of the same mechanism whose structure
//! decomposes into closed-form groups (`closed_form`), to integrate in near a type II
//! singularity of the user's coordinates instead of a body-coordinate partition. A five-bar's
//! two crank angles leave the triangle of its distal links, singular where that is flat; the
//! angles at one ground pivot and its elbow leave the other side's triangle (an RRR dyad on a
//! crank on a crank), singular elsewhere: some choice is well conditioned where the user's is not.
//!
//! Where no candidate applies (no closed form, more pair sets than [`MAX_CANDIDATES`], a
//! prismatic coordinate), the partition stays the fallback (`simulate::charts`).

use super::closed_form::ClosedForm;
use super::constraints::{pair_coordinate, Chart};
use super::frame::Frame;
use super::singularity::sigma_min_with;
use super::system::System;
use crate::model::{Link, Mechanism, PairKind};
use itertools::Itertools;

/// The most pair sets tried: each costs an Assur decomposition once per prepared model.
const MAX_CANDIDATES: usize = 64;

/// One alternative chart (`Chart::Pairs`), its closed forms and its J's analysis (for its measure).
#[derive(Debug, Clone)]
struct Candidate {
    chart: Chart,
    closed: ClosedForm,
    sys: System,
    /// Its pair coordinates' values at the point measured.
    z: Vec<f64>,
}

impl Candidate {
    /// The chart's measure at the solution x: its closed forms place x again at x's values of
    /// its pair coordinates, on x's branches, and give the smallest singular value of each
    /// block of its J in closed form (`ClosedForm::sigma`: the dyads' secular equations solved
    /// to round-off, the input links' constants), the exact measure's value to round-off
    /// (`closed_form_measure_is_the_exact_one`) at a few thousand instructions for its SVDs'
    /// 23 k (five-bar: `best` 45 k -> 8 k a call).
    /// Where they do not place it (round-off at a fold of this chart, or a triad's Newton), the
    /// SVDs give it.
    fn measure(&mut self, mech: &Mechanism, x: &[f64], frame: &mut Frame) -> f64 {
        let Chart::Pairs(pairs) = &self.chart else { unreachable!("an alternative chart is Chart::Pairs") };
        self.z.iter_mut().zip(pairs).for_each(|(z, &i)| *z = pair_coordinate(&mech.pairs[i], x));
        self.closed.set_reference(x);
        match self.closed.positions(&self.z, frame) {
            Ok(()) => self.closed.sigma(),
            Err(_) => sigma_min_with(&mut self.sys, mech, &self.chart, x),
        }
    }
}

/// The alternative charts of a mechanism, analysed once.
#[derive(Debug, Clone, Default)]
pub struct AltCharts {
    candidates: Vec<Candidate>,
}

/// Every set of m indices out of 0..n, in lexicographic order (none past `max` sets).
fn subsets(n: usize, m: usize, max: usize) -> Vec<Vec<usize>> {
    let sets: Vec<_> = (0..n).combinations(m).take(max + 1).collect();
    if m == 0 || sets.len() > max {
        return Vec::new();
    }
    sets
}

/// Whether the pairs turn their bodies one after the other from the ground (each joins a
/// body turned before, or the ground, to a new one), as the closed forms' cranks and cranks on
/// cranks need: a check before the Assur decomposition of the sets that cannot pass it.
fn chained(mech: &Mechanism, pairs: &[usize]) -> bool {
    let mut placed = vec![false; mech.n_bodies()];
    let is_placed = |placed: &[bool], l: Link| match l {
        Link::Ground => true,
        Link::Body(b) => placed[b.0],
    };
    let mut left: Vec<usize> = pairs.to_vec();
    while !left.is_empty() {
        let before = left.len();
        left.retain(|&i| {
            let p = &mech.pairs[i];
            match (is_placed(&placed, p.a), is_placed(&placed, p.b), p.a, p.b) {
                (true, false, _, Link::Body(b)) | (false, true, Link::Body(b), _) => {
                    placed[b.0] = true;
                    false
                }
                _ => true,
            }
        });
        if left.len() == before {
            return false;
        }
    }
    true
}

impl AltCharts {
    /// The sets of m revolute pairs other than the user's coordinates' whose chart has closed forms.
    pub fn new(mech: &Mechanism) -> Self {
        let user: Vec<usize> = mech.coordinates.iter().map(|c| c.pair.0).collect();
        let revolute: Vec<usize> =
            (0..mech.pairs.len()).filter(|&i| mech.pairs[i].kind == PairKind::Revolute).collect();
        let candidates = subsets(revolute.len(), mech.dof(), MAX_CANDIDATES)
            .into_iter()
            .map(|s| s.iter().map(|&i| revolute[i]).collect::<Vec<_>>())
            .filter(|pairs| {
                let mut sorted = user.clone();
                sorted.sort_unstable();
                *pairs != sorted && chained(mech, pairs)
            })
            .filter_map(|pairs| {
                let closed = ClosedForm::new(&mech.with_pair_coordinates(&pairs))?;
                let chart = Chart::Pairs(pairs);
                let sys = System::for_chart(mech, &chart);
                Some(Candidate { chart, closed, sys, z: vec![0.0; mech.dof()] })
            })
            .collect();
        AltCharts { candidates }
    }

    /// Whether there is any.
    pub fn is_empty(&self) -> bool {
        self.candidates.is_empty()
    }

    /// The candidate whose own measure (`group_sigma`) is largest at x, and that measure: each
    /// from its closed forms ([`Candidate::measure`]), `frame` their scratch.
    pub fn best(&mut self, mech: &Mechanism, x: &[f64], frame: &mut Frame) -> Option<(Chart, f64)> {
        // The winner's chart alone is cloned: no allocation per candidate.
        self.candidates
            .iter_mut()
            .map(|c| (c.measure(mech, x, frame), &c.chart))
            .max_by(|a, b| a.0.total_cmp(&b.0))
            .map(|(sigma, chart)| (chart.clone(), sigma))
    }

    /// The closed forms of the chart of `pairs`, if it is one of these.
    pub fn closed_form(&self, pairs: &[usize]) -> Option<&ClosedForm> {
        self.candidates.iter().find(|c| matches!(&c.chart, Chart::Pairs(p) if p == pairs)).map(|c| &c.closed)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::kinematics::constraints::pair_coordinate;
    use crate::kinematics::{convective, solve_position, velocity_analogues, Frame};

    /// The five-bar's alternative charts are the angles at one ground pivot and its elbow
    /// (pairs 0 and 1: a crank, a crank on it, an RRR dyad; pairs 3 and 4 the other side's), and
    /// their closed forms give the Newton path's positions, U and convective term to 1e-12 at a
    /// point 0.05 rad from the drawing in each angle, with rates (1.3, -0.7) rad/s (the Newton
    /// path's own tolerance, POSITION_TOL, is 1e-12 scaled; U and c then follow to round-off).
    #[test]
    fn five_bar_alternative_charts_are_newtons_to_round_off() {
        let path = format!("{}/../../examples/models/five-bar-free-fall.yaml", env!("CARGO_MANIFEST_DIR"));
        let mech = crate::load(&path).unwrap();
        let alt = AltCharts::new(&mech);
        let sets: Vec<_> = alt
            .candidates
            .iter()
            .map(|c| match &c.chart {
                Chart::Pairs(p) => p.clone(),
                other => panic!("an alternative chart is Chart::Pairs, not {other:?}"),
            })
            .collect();
        assert_eq!(sets, vec![vec![0, 1], vec![3, 4]]);
        for pairs in sets {
            let z: Vec<f64> = pairs.iter().map(|&i| pair_coordinate(&mech.pairs[i], &mech.x0) + 0.05).collect();
            let zd = [1.3, -0.7];
            let mut newton = Frame::new(&mech);
            newton.chart = Chart::Pairs(pairs.clone());
            solve_position(&mech, &z, &mut newton).unwrap();
            velocity_analogues(&mut newton).unwrap();
            convective(&mech, &zd, &mut newton);
            let mut closed = Frame::new(&mech);
            let mut form = alt.closed_form(&pairs).unwrap().clone();
            form.kinematic_stages(&z, &zd, &mut closed).unwrap();
            for (name, a, b) in [("x", &newton.x, &closed.x), ("U", &newton.u, &closed.u), ("c", &newton.c, &closed.c)]
            {
                let worst = a.iter().zip(b.iter()).map(|(p, q)| (p - q).abs()).fold(0.0, f64::max);
                assert!(worst < 1e-12, "pairs {pairs:?}: {name} {worst:e} from Newton's");
            }
        }
    }

    /// Each candidate's measure from its closed forms is the exact one (an SVD of each block of
    /// its J) to 1e-12 at the five-bar's configurations 0.15 rad apart in each of the user's
    /// angles over +-1.2 rad around the drawing (where they assemble: over 200, with measures
    /// from below 0.01 to above 0.3): the chart `best` picks is as well conditioned as its
    /// exact measure says. The secular equation is solved to 4 eps and the input links'
    /// measures are constants, so the two differ by round-off only.
    #[test]
    fn closed_form_measure_is_the_exact_one() {
        let path = format!("{}/../../examples/models/five-bar-free-fall.yaml", env!("CARGO_MANIFEST_DIR"));
        let mech = crate::load(&path).unwrap();
        let mut alt = AltCharts::new(&mech);
        let mut frame = Frame::new(&mech);
        let q0 = [0, 1].map(|k| pair_coordinate(&mech.pairs[mech.coordinates[k].pair.0], &mech.x0));
        let (mut points, mut least, mut most) = (0, f64::INFINITY, 0.0_f64);
        for i in -8..=8 {
            for j in -8..=8 {
                let z = [q0[0] + 0.15 * f64::from(i), q0[1] + 0.15 * f64::from(j)];
                let mut newton = Frame::new(&mech);
                if solve_position(&mech, &z, &mut newton).is_err() {
                    continue;
                }
                points += 1;
                for c in &mut alt.candidates {
                    let closed = c.measure(&mech, &newton.x, &mut frame);
                    let exact = sigma_min_with(&mut c.sys, &mech, &c.chart, &newton.x);
                    assert!((closed - exact).abs() < 1e-12, "{:?} at {z:?}: {closed} closed, {exact} exact", c.chart);
                    (least, most) = (least.min(exact), most.max(exact));
                }
            }
        }
        assert!(points > 200 && least < 0.01 && most > 0.3, "{points} points, measures {least} ... {most}");
    }

    #[test]
    fn subsets_are_every_choice_in_order() {
        assert_eq!(subsets(4, 2, 64), vec![vec![0, 1], vec![0, 2], vec![0, 3], vec![1, 2], vec![1, 3], vec![2, 3]]);
        assert!(subsets(40, 3, 64).is_empty());
    }
}
