//! The class II dyad PRP: two bodies, each on a guide fixed in a link solved before it (the
//! outer prismatic pairs), hinged to each other at P (the inner revolute pair). Each guide's
//! angle row fixes its body's angle, and the guides' normal rows and the hinge's rows are then
//! affine in the bodies' positions: P is where the two guides' lines (offset to P) meet, one
//! exact step with no branch ([`Local::affine`]), singular where the guides are parallel.

use super::local::Local;
use crate::model::{Mechanism, PairKind};
use crate::topology::AssurGroup;

/// The PRP dyad `g`: two one-body links, two outer prismatic pairs and an inner revolute one.
pub fn prp(mech: &Mechanism, g: &AssurGroup) -> Option<Local> {
    let ([l1, l2], [inner], [o1, o2]) = (g.links.as_slice(), g.inner_pairs.as_slice(), g.outer_pairs.as_slice()) else {
        return None;
    };
    let ([b1], [b2]) = (l1.as_slice(), l2.as_slice()) else { return None };
    let prismatic = |k: &crate::model::PairId| matches!(mech.pairs[k.0].kind, PairKind::Prismatic { .. });
    if mech.pairs[inner.0].kind != PairKind::Revolute || !prismatic(o1) || !prismatic(o2) {
        return None;
    }
    let group = Local::new(mech, &[b1.0, b2.0], &[*o1, *o2, *inner])?;
    group.is_affine().then_some(group)
}
