//! The class I groups: one body held by two outer pairs of three rows in all, one of which
//! fixes its angle alone and two of which are then affine in its position. They are
//! - 1R1G, a wheel on a revolute pivot meshing with a solved gear (or a pinion with a solved
//!   rack): the gear row fixes the angle, the pivot's rows the position;
//! - 1P1G, a rack on a guide meshing with a solved pinion: the guide's angle row, then its
//!   normal row and the rack's travel;
//! - 1P1S, a yoke on a guide with a solved pin in its slot (or a pin on a guide in a solved
//!   slot): the guide's angle row, then its normal row and the slot's.
//!
//! Each row being affine in the unknown it solves, one Newton step from any start is exact
//! ([`Local::affine`]): the angle from the angle row, then the position from the other two (a
//! 2 x 2 solve); rates, accelerations and the measure come from the group's block of J.

use super::local::Local;
use crate::model::{Mechanism, PairId};

/// The group of `body` held by the outer pairs `outer`, if its rows are of the kinds above.
pub fn one_link(mech: &Mechanism, body: usize, outer: [PairId; 2]) -> Option<Local> {
    let group = Local::new(mech, &[body], &outer)?;
    group.is_affine().then_some(group)
}
