//! Which closed-form pieces each coordinate moves: per coordinate j, the input links and the
//! Assur groups whose bodies' rates depend on z_j (its column u_j of U is zero elsewhere). The
//! closed form's velocity analogues then run each column over those pieces only, so U costs
//! the sum of the reaches, not m times all the groups: for N five-bars side by side that is
//! linear in N instead of quadratic (docs/benchmarks.md, *Cost against size*).
//!
//! Structural, from the decomposition: a group depends on the links its outer pairs join it
//! to and on a relative input inside it; found once per model, in the groups' solve order.

use super::system::next_supports_id;
use super::u_support::USupport;
use crate::model::{Link, Mechanism};
use crate::topology::assur::AssurGroup;

/// Per coordinate j, the cranks, sliders and groups (indices into the closed form's lists)
/// that move with z_j.
#[derive(Debug, Clone)]
pub struct ColumnReach {
    pub cranks: Vec<Vec<usize>>,
    pub sliders: Vec<Vec<usize>>,
    pub groups: Vec<Vec<usize>>,
    /// Identifies this zero pattern of U among all supports (`Frame::u_zeros_for`): U is
    /// cleared whole once when it changes, then each column is written on its reach only.
    pub zeros_id: u64,
    /// Per column, the bodies of its pieces as runs: where the closed form writes U.
    pub support: USupport,
}

impl ColumnReach {
    /// `cranks` and `sliders`: each input link's (body, coordinate); `groups`: the groups of
    /// the decomposition in solve order (the closed form's, one for one).
    pub fn new(mech: &Mechanism, cranks: &[(usize, usize)], sliders: &[(usize, usize)], groups: &[AssurGroup]) -> Self {
        let m = mech.dof();
        // The coordinates each body's rates depend on, ascending.
        let mut moved_by: Vec<Vec<usize>> = vec![Vec::new(); mech.n_bodies()];
        for &(body, k) in cranks.iter().chain(sliders) {
            moved_by[body] = vec![k];
        }
        // Relative inputs (a pair between two bodies): the group holding them depends on them.
        let mut relative: Vec<Vec<usize>> = vec![Vec::new(); mech.n_bodies()];
        for (k, c) in mech.coordinates.iter().enumerate() {
            let p = &mech.pairs[c.pair.0];
            if let (Link::Body(a), Link::Body(b)) = (p.a, p.b) {
                relative[a.0].push(k);
                relative[b.0].push(k);
            }
        }
        let mut reach = ColumnReach {
            cranks: vec![Vec::new(); m],
            sliders: vec![Vec::new(); m],
            groups: vec![Vec::new(); m],
            zeros_id: next_supports_id(),
            support: USupport::default(),
        };
        for (i, &(_, k)) in cranks.iter().enumerate() {
            reach.cranks[k].push(i);
        }
        for (i, &(_, k)) in sliders.iter().enumerate() {
            reach.sliders[k].push(i);
        }
        for (i, g) in groups.iter().enumerate() {
            let bodies: Vec<usize> = g.links.iter().flatten().map(|b| b.0).collect();
            let outer = g.outer_pairs.iter().flat_map(|k| [mech.pairs[k.0].a, mech.pairs[k.0].b]);
            let mut deps: Vec<usize> = outer
                .filter_map(|l| match l {
                    Link::Body(b) if !bodies.contains(&b.0) => Some(b.0),
                    _ => None,
                })
                .flat_map(|b| moved_by[b].iter().copied())
                .chain(bodies.iter().flat_map(|&b| relative[b].iter().copied()))
                .collect();
            deps.sort_unstable();
            deps.dedup();
            for &k in &deps {
                reach.groups[k].push(i);
            }
            for &b in &bodies {
                moved_by[b].clone_from(&deps);
            }
        }
        let mut columns: Vec<Vec<usize>> = vec![Vec::new(); m];
        for (j, col) in columns.iter_mut().enumerate() {
            col.extend(reach.cranks[j].iter().map(|&i| cranks[i].0));
            col.extend(reach.sliders[j].iter().map(|&i| sliders[i].0));
            col.extend(reach.groups[j].iter().flat_map(|&i| groups[i].links.iter().flatten().map(|b| b.0)));
            col.sort_unstable();
            col.dedup();
        }
        reach.support = USupport::new(&columns);
        reach
    }
}
