//! Closed-form kinematics of the user's chart, chosen from the Assur decomposition: when the
//! mechanism is made of input links (turned by revolute pairs, or sliders on guides fixed to
//! the ground), class I groups with a gear or slot pair (1R1G, 1P1G, 1P1S), class II RRR,
//! RRP, RPR and PRP dyads and class III triads of six revolute pairs only, the positions x at
//! z, the velocity analogues U, the body rates xd and the convective term c come from the
//! groups' closed forms (`dyads`), each group from the links solved before it, in the
//! decomposition's order: no factorisation of J, and no Newton iteration but the triad's on its
//! 3 x 3 platform system. A link of an RRR dyad or a triad's leg may be two bodies locked by a relative
//! prismatic input (a cylinder, `dyads::extension`) whose rod holds the group's inner pair.
//! Each group keeps the assembly branch of a reference configuration (the integrator's last
//! accepted point); where a dyad's circles do not meet (or an RPR's guide misses its hinge),
//! or the triad's Newton does not converge, the evaluation fails as a Newton solve that does
//! not converge does, and where a PRP's guides are parallel as at a type II singularity. Other
//! mechanisms (sliders carrying the ground's point on their guide, RPP dyads, other class I
//! groups, other class III groups and larger ones, relative revolute inputs and other relative
//! prismatic ones, redundant pairs) take the general path (`position`, `analogues`).

use super::analogues::body_rates;
use super::column_reach::ColumnReach;
use super::dyads::crank::Crank;
use super::dyads::extended_rrr::ExtendedRrr;
use super::dyads::extension::{Arm, Extension};
use super::dyads::local::Local;
use super::dyads::one_link::one_link;
use super::dyads::prp::prp;
use super::dyads::relative_crank::RelativeCrank;
use super::dyads::rpr::{self, Rpr};
use super::dyads::rrp::{self, Rrp};
use super::dyads::rrr::{self, Rrr};
use super::dyads::slider::Slider;
use super::dyads::triad::Triad;
use super::dyads::{rows, rows_mut, Joint, Pass};
use super::frame::Frame;
use super::group_sigma::{bodies_length, input_link_sigma};
use super::u_support::USupport;
use crate::linalg::copy_small;
use crate::model::{BodyId, Link, Mechanism, PairId, PairKind};
use crate::topology::assur::{self, AssurGroup};
use crate::KinematicsError;

/// A group of a kind with a closed form: a class II dyad with the branch of its reference
/// configuration (and for RRR and RRP its geometry at the last positions, for the rates and
/// accelerations), a group placed in one affine step (a class I group or a PRP dyad: no
/// branch), or the class III triad (which keeps its own); or a body turned by a relative
/// revolute input on a link placed before it (alternative charts only, before every other
/// group: a group, not a loop of its own in each stage, which cost the user's charts' stages
/// 5..34 instructions an evaluation though they have none).
#[derive(Debug, Clone)]
enum Group {
    Rrr(Rrr, rrr::Branch, rrr::Geometry),
    Rrp(Rrp, rrp::Branch, rrp::Geometry),
    Affine(Box<Local>),
    Rpr(Box<Rpr>, rpr::Branch),
    Extended(Box<ExtendedRrr>),
    Triad(Box<Triad>),
    Relative(RelativeCrank),
}

impl Group {
    fn bodies(&self) -> &[usize] {
        match self {
            Group::Rrr(d, ..) => &d.bodies,
            Group::Rrp(d, ..) => &d.bodies,
            Group::Affine(g) => g.bodies(),
            Group::Rpr(d, _) => d.bodies(),
            Group::Extended(d) => &d.members,
            Group::Triad(t) => &t.members,
            Group::Relative(c) => std::slice::from_ref(&c.body),
        }
    }

    fn set_reference(&mut self, x: &[f64]) {
        match self {
            Group::Rrr(d, b, _) => *b = d.branch(x),
            Group::Rrp(d, b, _) => *b = d.branch(x),
            Group::Affine(_) => {}
            Group::Rpr(d, b) => *b = d.branch(x),
            Group::Extended(d) => d.set_reference(x),
            Group::Triad(t) => t.set_reference(x),
            Group::Relative(_) => {}
        }
    }

    /// Take the reference of `from`, the same group in another copy of the closed forms.
    fn copy_reference(&mut self, from: &Group) {
        const SAME: &str = "the same group in both copies of the closed forms";
        match self {
            Group::Rrr(_, b, _) => {
                let Group::Rrr(_, f, _) = from else { unreachable!("{SAME}") };
                *b = *f;
            }
            Group::Rrp(_, b, _) => {
                let Group::Rrp(_, f, _) = from else { unreachable!("{SAME}") };
                *b = *f;
            }
            Group::Affine(_) => {}
            Group::Rpr(_, b) => {
                let Group::Rpr(_, f) = from else { unreachable!("{SAME}") };
                *b = *f;
            }
            Group::Extended(d) => {
                let Group::Extended(f) = from else { unreachable!("{SAME}") };
                d.copy_reference(f);
            }
            Group::Triad(t) => {
                let Group::Triad(f) = from else { unreachable!("{SAME}") };
                t.copy_reference(f);
            }
            Group::Relative(_) => {}
        }
    }

    fn keeps_side(&self, x: &[f64]) -> bool {
        match self {
            Group::Rrr(d, b, _) => d.keeps_side(b, x),
            Group::Rrp(d, b, _) => d.keeps_side(b, x),
            Group::Affine(_) => true,
            Group::Rpr(d, b) => d.keeps_side(b, x),
            Group::Extended(d) => d.keeps_side(x),
            Group::Triad(t) => t.keeps_side(x),
            Group::Relative(_) => true,
        }
    }

    fn sigma(&self, inv_length: f64) -> f64 {
        match self {
            Group::Rrr(_, _, g) => g.sigma(inv_length),
            Group::Rrp(d, _, g) => g.sigma(inv_length, d.guide_on_g),
            Group::Affine(g) => g.sigma(inv_length),
            Group::Rpr(d, _) => d.sigma(inv_length),
            Group::Extended(d) => d.sigma(inv_length),
            Group::Triad(t) => t.sigma(inv_length),
            // Its input's measure is in `inputs_sigma`.
            Group::Relative(_) => f64::INFINITY,
        }
    }

    /// Inlined into [`ClosedForm::place`], as `place` is into the stages (see there).
    #[inline(always)]
    fn position(
        &mut self,
        z: &[f64],
        start: Start,
        x: &mut [f64],
        trig: &mut [[f64; 2]],
    ) -> Result<(), KinematicsError> {
        match self {
            Group::Rrr(d, b, g) => d.position(b, g, x, trig)?,
            Group::Rrp(d, b, g) => d.position(b, g, x, trig)?,
            Group::Affine(g) => g.affine(x, trig)?,
            Group::Rpr(d, b) => d.position(b, x, trig)?,
            Group::Extended(d) => d.position(z, x, trig)?,
            Group::Triad(t) => t.position(z, start == Start::Predicted, x, trig)?,
            Group::Relative(c) => c.position(z, x, trig),
        }
        Ok(())
    }

    /// Inlined into each column's pass (`ClosedForm::rates`): a call a group and column cost
    /// about 25 instructions, a quarter of an RRR dyad's rates.
    #[inline(always)]
    fn velocity(&self, zd: &[f64], v: &mut [f64]) {
        match self {
            Group::Rrr(d, _, g) => d.velocity(g, [[0.0; 2]; 2], v),
            Group::Rrp(d, _, g) => d.velocity(g, v),
            Group::Affine(g) => g.velocity(v),
            Group::Rpr(d, _) => d.velocity(v),
            Group::Extended(d) => d.velocity(zd, v),
            Group::Triad(t) => t.velocity(zd, v),
            Group::Relative(c) => c.velocity(zd, v),
        }
    }

    #[inline]
    fn acceleration(&self, v: &[f64], a: &mut [f64]) {
        match self {
            Group::Rrr(d, _, g) => d.acceleration(g, [[0.0; 2]; 2], v, a),
            Group::Rrp(d, _, g) => d.acceleration(g, v, a),
            Group::Affine(g) => g.acceleration(v, a),
            Group::Rpr(d, _) => d.acceleration(v, a),
            Group::Extended(d) => d.acceleration(v, a),
            Group::Triad(t) => t.acceleration(v, a),
            Group::Relative(c) => c.acceleration(v, a),
        }
    }

    /// The group's rows of U, xd and c in one pass ([`Pass::piece`]).
    #[inline(always)]
    fn pass<const M: usize>(&self, p: &mut Pass<M>) {
        match self {
            Group::Rrr(d, _, g) => p.piece(
                &d.bodies,
                |_, v| d.velocity(g, [[0.0; 2]; 2], v),
                |v, a| d.acceleration(g, [[0.0; 2]; 2], v, a),
            ),
            Group::Rrp(d, _, g) => p.piece(&d.bodies, |_, v| d.velocity(g, v), |v, a| d.acceleration(g, v, a)),
            Group::Affine(g) => p.piece(g.bodies(), |_, v| g.velocity(v), |v, a| g.acceleration(v, a)),
            Group::Rpr(d, _) => p.piece(d.bodies(), |_, v| d.velocity(v), |v, a| d.acceleration(v, a)),
            Group::Extended(d) => p.piece(&d.members, |zd, v| d.velocity(zd, v), |v, a| d.acceleration(v, a)),
            Group::Triad(t) => p.piece(&t.members, |zd, v| t.velocity(zd, v), |v, a| t.acceleration(v, a)),
            Group::Relative(c) => p.piece(&[c.body], |zd, v| c.velocity(zd, v), |v, a| c.acceleration(v, a)),
        }
    }
}

/// Where the iterative groups (the triad's Newton) start: from the reference configuration,
/// or from the point in the buffer x (a prediction on the reference branches, which the
/// caller's fold guard has checked: `MechanismOde`'s).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Start {
    Reference,
    Predicted,
}

/// The most coordinates for which U is solved over all the pieces per column (the few of a
/// robot: no bookkeeping), beyond which over each coordinate's reach ([`ColumnReach`]).
const REACH_FROM_M: usize = 4;

#[derive(Debug, Clone)]
pub struct ClosedForm {
    cranks: Vec<Crank>,
    sliders: Vec<Slider>,
    /// In order of placement: the relative cranks, each after the link it turns on, then the
    /// Assur groups.
    groups: Vec<Group>,
    /// Per dyad 1 / L_k (its group's length, `group_sigma`), and the smallest input link
    /// measure (constant).
    inv_length: Vec<f64>,
    inputs_sigma: f64,
    /// Beyond a few coordinates, the pieces each coordinate moves (`column_reach`): U is then
    /// solved column by column over them only.
    reach: Option<ColumnReach>,
    /// Whether no group iterates ([`ClosedForm::is_explicit`]; asked at every ODE evaluation).
    explicit: bool,
}

/// The end of a revolute pair on `body` (its point there) and the other end.
fn ends(mech: &Mechanism, pair: PairId, body: usize) -> ([f64; 2], Joint) {
    let p = &mech.pairs[pair.0];
    if p.a == Link::Body(BodyId(body)) {
        (p.sa, Joint { link: p.b, s: p.sb })
    } else {
        (p.sb, Joint { link: p.a, s: p.sa })
    }
}

/// Whether pair k joins body b.
fn on(mech: &Mechanism, k: PairId, b: usize) -> bool {
    let p = &mech.pairs[k.0];
    p.a == Link::Body(BodyId(b)) || p.b == Link::Body(BodyId(b))
}

/// A group link's base (its body of the group's outer pair), that pair, the body holding
/// `inner` (a pair to another link of the group) and the base's point of each pair; and if the
/// link is two bodies, their relative input with the arm between the two points.
struct LinkParts {
    base: usize,
    outer: Joint,
    s_outer: [f64; 2],
    s_inner: [f64; 2],
    arm: Option<Arm>,
}

fn link_parts(mech: &Mechanism, link: &[BodyId], outer: &[PairId], inner: PairId) -> Option<LinkParts> {
    let base = link.iter().map(|b| b.0).find(|&b| outer.iter().any(|&k| on(mech, k, b)))?;
    let o = *outer.iter().find(|&&k| on(mech, k, base))?;
    let holder = link.iter().map(|b| b.0).find(|&b| on(mech, inner, b))?;
    let (s_outer, joint) = ends(mech, o, base);
    let s_inner = ends(mech, inner, holder).0;
    let arm = match link {
        [_] => None,
        [_, _] => {
            let follower = link.iter().map(|b| b.0).find(|&b| b != base)?;
            if outer.iter().any(|&k| on(mech, k, follower)) {
                return None;
            }
            let joins = |c: &crate::model::Coordinate| on(mech, c.pair, base) && on(mech, c.pair, follower);
            let k = mech.coordinates.iter().position(joins)?;
            if holder != follower {
                return None; // its follower has a block of its own in J (`Arm`)
            }
            Some(Arm::new(Extension::new(mech, k, base)?, s_outer, s_inner))
        }
        _ => return None,
    };
    // The inner point in the base's frame (at the drawn input for a two-body link).
    let s_inner = arm.as_ref().map_or(s_inner, |a| {
        let d = a.arm(0.0);
        [s_outer[0] + d[0], s_outer[1] + d[1]]
    });
    Some(LinkParts { base, outer: joint, s_outer, s_inner, arm })
}

/// The RRR dyad `g` with one or two links of two bodies (a relative input each).
fn extended_rrr(mech: &Mechanism, g: &AssurGroup) -> Option<ExtendedRrr> {
    let [inner] = g.inner_pairs.as_slice() else { return None };
    if g.kind != "RRR" || g.links.len() != 2 || mech.pairs[inner.0].kind != PairKind::Revolute {
        return None;
    }
    let [l1, l2] = [0, 1].map(|i| link_parts(mech, &g.links[i], &g.outer_pairs, *inner));
    let (l1, l2) = (l1?, l2?);
    let rrr = Rrr::new([l1.base, l2.base], [l1.outer, l2.outer], [l1.s_outer, l2.s_outer], [l1.s_inner, l2.s_inner]);
    Some(ExtendedRrr::new(rrr, [l1.arm, l2.arm]))
}

/// The RPR dyad `g`: two one-body links hinged to solved links by the outer revolute pairs,
/// joined by the inner prismatic one (its `a` the guide's owner, o).
fn rpr_dyad(mech: &Mechanism, g: &AssurGroup) -> Option<Rpr> {
    let ([l1, l2], [inner], [_, _]) = (g.links.as_slice(), g.inner_pairs.as_slice(), g.outer_pairs.as_slice()) else {
        return None;
    };
    let ([_], [_]) = (l1.as_slice(), l2.as_slice()) else { return None };
    let pair = &mech.pairs[inner.0];
    let (Link::Body(o), Link::Body(f)) = (pair.a, pair.b) else { return None };
    let hinge = |b: usize| {
        let k = *g.outer_pairs.iter().find(|&&k| on(mech, k, b))?;
        (mech.pairs[k.0].kind == PairKind::Revolute).then(|| (k, ends(mech, k, b)))
    };
    let ((ka, (sa, a)), (kb, (sb, b))) = (hinge(o.0)?, hinge(f.0)?);
    if ka == kb {
        return None;
    }
    Rpr::new(mech, [o.0, f.0], [a, b], [sa, sb], [ka, kb], *inner)
}

/// The triad of six revolute pairs `g` (class III): three legs, each hinged to the platform and
/// to a link solved before (each one body, or two a relative input locks), and the platform
/// (the link of the three inner pairs).
fn triad(mech: &Mechanism, g: &AssurGroup) -> Option<Triad> {
    if g.links.len() != 4 || g.inner_pairs.len() != 3 || g.outer_pairs.len() != 3 {
        return None;
    }
    if g.inner_pairs.iter().chain(&g.outer_pairs).any(|k| mech.pairs[k.0].kind != PairKind::Revolute) {
        return None;
    }
    let platform = g.links.iter().position(|l| l.len() == 1 && g.inner_pairs.iter().all(|&k| on(mech, k, l[0].0)))?;
    let p = g.links[platform][0].0;
    let (mut bodies, mut outer) = ([p; 4], [Joint { link: Link::Ground, s: [0.0; 2] }; 3]);
    let mut s = [[[0.0; 2]; 3]; 3];
    let mut extended = [None, None, None];
    for (i, link) in g.links.iter().enumerate().filter(|(j, _)| *j != platform).map(|(_, l)| l).enumerate() {
        let inner = *g.inner_pairs.iter().find(|&&k| link.iter().any(|b| on(mech, k, b.0)))?;
        let parts = link_parts(mech, link, &g.outer_pairs, inner)?;
        (bodies[i], outer[i], extended[i]) = (parts.base, parts.outer, parts.arm);
        (s[0][i], s[1][i], s[2][i]) = (parts.s_outer, parts.s_inner, ends(mech, inner, p).0);
    }
    Some(Triad::new(bodies, outer, s, extended, mech.scale))
}

/// The relative revolute inputs `pending` (indices of coordinates) as cranks on links placed
/// before them: the cranks' bodies, then each other's, in an order where each one's pivot link
/// is placed; None if some input turns a body on a link no input places.
fn relative_cranks(mech: &Mechanism, cranks: &[Crank], mut pending: Vec<usize>) -> Option<Vec<RelativeCrank>> {
    let mut placed: Vec<usize> = cranks.iter().map(|c| c.body).collect();
    let mut relative = Vec::new();
    while !pending.is_empty() {
        let before = pending.len();
        pending.retain(|&k| {
            let c = &mech.coordinates[k];
            let p = &mech.pairs[c.pair.0];
            let (Link::Body(a), Link::Body(b)) = (p.a, p.b) else { return true };
            let (body, sign) = match (placed.contains(&a.0), placed.contains(&b.0)) {
                (true, false) => (b.0, 1.0),
                (false, true) => (a.0, -1.0),
                _ => return true,
            };
            let (s, pivot) = ends(mech, c.pair, body);
            relative.push(RelativeCrank {
                body,
                pivot,
                s,
                k,
                sign,
                offset: p.rel_angle0 - c.value,
                rs: [0.0; 2],
                pivot_rs: [0.0; 2],
            });
            placed.push(body);
            false
        });
        if pending.len() == before {
            return None;
        }
    }
    Some(relative)
}

impl ClosedForm {
    /// The closed forms of `mech`'s groups, if every group has one (see the module's doc); the
    /// branches are those of the drawing until [`ClosedForm::set_reference`].
    pub fn new(mech: &Mechanism) -> Option<Self> {
        let decomposition = assur::assur(mech);
        if !decomposition.left_over.is_empty() {
            return None;
        }
        let revolute = |k: PairId| mech.pairs[k.0].kind == PairKind::Revolute;
        let (mut cranks, mut sliders, mut pending) = (Vec::new(), Vec::new(), Vec::new());
        let mut inputs_sigma = f64::INFINITY;
        for (k, c) in mech.coordinates.iter().enumerate() {
            let p = &mech.pairs[c.pair.0];
            let body = match (p.a, p.b) {
                (Link::Ground, Link::Body(b)) | (Link::Body(b), Link::Ground) => b.0,
                // A relative prismatic input: its group solves it (`Extension`).
                (Link::Body(_), Link::Body(_)) if matches!(p.kind, PairKind::Prismatic { .. }) => continue,
                // A relative revolute input: a crank on a link placed before it (below).
                (Link::Body(_), Link::Body(_)) if p.kind == PairKind::Revolute => {
                    pending.push(k);
                    continue;
                }
                _ => return None,
            };
            let (s, ground) = ends(mech, c.pair, body);
            match p.kind {
                PairKind::Revolute => {}
                // A slider on a guide fixed to the ground: one block of J (`input_link_sigma`).
                PairKind::Prismatic { axis } if p.a == Link::Ground => {
                    let arm = s[0].hypot(s[1]) / bodies_length(mech, &[body]);
                    inputs_sigma = inputs_sigma.min(input_link_sigma(arm));
                    let (phi, origin) = (p.rel_angle0, ground.s);
                    sliders.push(Slider { body, origin, axis, s, k, value: c.value, phi, cs: [phi.cos(), phi.sin()] });
                    continue;
                }
                _ => return None,
            }
            let pivot = ground.s;
            let sign = if p.b == Link::Body(BodyId(body)) { 1.0 } else { -1.0 };
            // A crank's rows split in J's block-triangular form: the coordinate's on its angle
            // (+-1) and the pivot's on its centre (I), each of measure 1.
            inputs_sigma = inputs_sigma.min(1.0);
            cranks.push(Crank {
                body,
                pivot,
                s,
                k,
                sign,
                offset: p.rel_angle0 - c.value,
                rs: [0.0; 2],
                reference: (f64::NAN, [0.0; 2]),
            });
        }
        let relative = relative_cranks(mech, &cranks, pending)?;
        let has_relative = !relative.is_empty();
        inputs_sigma = inputs_sigma.min(if has_relative { 1.0 } else { f64::INFINITY });
        let mut groups: Vec<_> = relative.into_iter().map(Group::Relative).collect();
        let mut pairs_used = mech.coordinates.len();
        for g in &decomposition.groups {
            if let ([link], [o1, o2]) = (g.links.as_slice(), g.outer_pairs.as_slice()) {
                let [body] = link.as_slice() else { return None };
                groups.push(Group::Affine(Box::new(one_link(mech, body.0, [*o1, *o2])?)));
                pairs_used += 2;
                continue;
            }
            if g.class == 2 && g.links.iter().any(|l| l.len() == 2) {
                groups.push(Group::Extended(Box::new(extended_rrr(mech, g)?)));
                pairs_used += 3;
                continue;
            }
            if g.class == 3 {
                groups.push(Group::Triad(Box::new(triad(mech, g)?)));
                pairs_used += 6;
                continue;
            }
            if g.kind == "PRP" {
                groups.push(Group::Affine(Box::new(prp(mech, g)?)));
                pairs_used += 3;
                continue;
            }
            if g.kind == "RPR" {
                groups.push(Group::Rpr(Box::new(rpr_dyad(mech, g)?), Default::default()));
                pairs_used += 3;
                continue;
            }
            let [inner] = g.inner_pairs.as_slice() else { return None };
            if g.class != 2 || g.links.iter().any(|l| l.len() != 1) || !revolute(*inner) {
                return None;
            }
            let bodies = [g.links[0][0].0, g.links[1][0].0];
            let touching = |b: usize| {
                g.outer_pairs.iter().copied().find(|&k| {
                    let p = &mech.pairs[k.0];
                    p.a == Link::Body(BodyId(b)) || p.b == Link::Body(BodyId(b))
                })
            };
            let (Some(o1), Some(o2)) = (touching(bodies[0]), touching(bodies[1])) else { return None };
            let (i1, _) = ends(mech, *inner, bodies[0]);
            let (i2, _) = ends(mech, *inner, bodies[1]);
            groups.push(match (g.kind.as_str(), revolute(o1), revolute(o2)) {
                ("RRR", true, true) => {
                    let ((s1, a), (s2, b)) = (ends(mech, o1, bodies[0]), ends(mech, o2, bodies[1]));
                    Group::Rrr(Rrr::new(bodies, [a, b], [s1, s2], [i1, i2]), Default::default(), Default::default())
                }
                ("RRP", true, false) => {
                    let (s1, a) = ends(mech, o1, bodies[0]);
                    let d = Rrp::new(bodies, a, s1, [i1, i2], &mech.pairs[o2.0])?;
                    Group::Rrp(d, Default::default(), Default::default())
                }
                ("RRP", false, true) => {
                    let (s2, a) = ends(mech, o2, bodies[1]);
                    let d = Rrp::new([bodies[1], bodies[0]], a, s2, [i2, i1], &mech.pairs[o1.0])?;
                    Group::Rrp(d, Default::default(), Default::default())
                }
                _ => return None,
            });
            pairs_used += 3;
        }
        let mut solved = vec![0; mech.n_bodies()];
        cranks
            .iter()
            .map(|c| c.body)
            .chain(sliders.iter().map(|s| s.body))
            .chain(groups.iter().flat_map(|d| d.bodies().iter().copied()))
            .for_each(|b| solved[b] += 1);
        if pairs_used != mech.pairs.len() || solved.iter().any(|&k| k != 1) {
            return None;
        }
        cranks.iter_mut().for_each(|c| c.set_reference(&mech.x0));
        groups.iter_mut().for_each(|d| d.set_reference(&mech.x0));
        let inv_length = groups.iter().map(|d| 1.0 / bodies_length(mech, d.bodies())).collect();
        if mech.dof() > REACH_FROM_M && has_relative {
            return None;
        }
        let reach = (mech.dof() > REACH_FROM_M).then(|| {
            let (c, s): (Vec<_>, Vec<_>) =
                (cranks.iter().map(|c| (c.body, c.k)).collect(), sliders.iter().map(|s| (s.body, s.k)).collect());
            ColumnReach::new(mech, &c, &s, &decomposition.groups)
        });
        let explicit = !groups.iter().any(|g| matches!(g, Group::Triad(_)));
        Some(ClosedForm { cranks, sliders, groups, inv_length, inputs_sigma, reach, explicit })
    }

    /// Whether every group is placed without iteration (no class III triad, whose Newton
    /// solve can fail on one branch where a configuration exists): `positions` then fails
    /// only where no configuration exists at those coordinates.
    pub fn is_explicit(&self) -> bool {
        self.explicit
    }

    /// Take the assembly branches from the configuration x (a solution).
    pub fn set_reference(&mut self, x: &[f64]) {
        self.cranks.iter_mut().for_each(|c| c.set_reference(x));
        self.groups.iter_mut().for_each(|d| d.set_reference(x));
    }

    /// Take the assembly branches of `from`, a copy of these closed forms whose reference was
    /// set last ([`ClosedForm::set_reference`]): the same values, without the sines and cosines.
    pub fn copy_reference(&mut self, from: &ClosedForm) {
        self.cranks.iter_mut().zip(&from.cranks).for_each(|(c, f)| c.copy_reference(f));
        self.groups.iter_mut().zip(&from.groups).for_each(|(d, f)| d.copy_reference(f));
    }

    /// Whether every group's side in the body coordinates x (a predicted point) is that of its
    /// reference branch ([`Rrr::keeps_side`], [`Rrp::keeps_side`], [`Rpr::keeps_side`],
    /// [`Triad::keeps_side`]); if not, a step crosses a fold or the triad's singularity and the
    /// closed forms would leave the motion's branch there.
    pub fn keeps_branches(&self, x: &[f64]) -> bool {
        self.groups.iter().all(|d| d.keeps_side(x))
    }

    /// Where U is written by [`ClosedForm::velocity_analogues`] when its zero pattern is
    /// `zeros_id` (`Frame::u_zeros_for`): each column's runs of bodies, beyond a few coordinates.
    pub fn u_support_for(&self, zeros_id: u64) -> Option<&USupport> {
        self.reach.as_ref().filter(|r| r.zeros_id == zeros_id).map(|r| &r.support)
    }

    /// Whether [`ClosedForm::velocity_analogues`] writes U's columns whole (up to a few
    /// coordinates), leaving `Frame::u_zeros_for` as it was.
    pub fn writes_u_whole(&self) -> bool {
        self.reach.is_none()
    }

    /// The type II measure at the last positions (`group_sigma`'s: the smallest singular
    /// value of each group's block at its own length), from the groups' closed forms: no
    /// factorisation of J.
    pub fn sigma(&self) -> f64 {
        let groups = self.groups.iter().zip(&self.inv_length).map(|(d, &k)| d.sigma(k));
        groups.fold(self.inputs_sigma, f64::min)
    }

    /// Positions `ws.x` (and `ws.trig`) at the user's coordinates z on the reference branches.
    pub fn positions(&mut self, z: &[f64], ws: &mut Frame) -> Result<(), KinematicsError> {
        self.place(z, Start::Reference, ws)
    }

    /// [`ClosedForm::positions`] with the triad's Newton from the platform's pose in `ws.x` (a
    /// prediction on the reference branches, nearer than the reference configuration), the
    /// positions alone: a step of a path on the reference branches (`branch_path`).
    pub fn predicted_positions(&mut self, z: &[f64], ws: &mut Frame) -> Result<(), KinematicsError> {
        self.place(z, Start::Predicted, ws)
    }

    /// [`ClosedForm::positions`], the triad's Newton from `start`. Inlined, with the crank's,
    /// the group's and the affine group's positions: left to the compiler, since the relative
    /// cranks came, one of them became a call of its own (icount four-bar 2033 -> 2003,
    /// 3-RRR 6188 -> 6140, gear-train 9301 -> 9279 with all four inlined; `place` alone
    /// inlined left the groups' positions out: four-bar 2094).
    #[inline(always)]
    fn place(&mut self, z: &[f64], start: Start, ws: &mut Frame) -> Result<(), KinematicsError> {
        let x = rows_mut(&mut ws.x);
        // trig as long as x's body rows: a body's check on one then holds for the other.
        let trig = &mut ws.trig[..x.len() / 3];
        for c in &mut self.cranks {
            c.position(z, x, trig);
        }
        for s in &self.sliders {
            s.position(z, x, trig);
        }
        for d in &mut self.groups {
            d.position(z, start, x, trig)?;
        }
        ws.residual = 0.0;
        ws.iterations = 0;
        Ok(())
    }

    /// Body rates for coordinate rates zd into v (3n), at the positions in `ws`.
    fn rates(&self, zd: &[f64], v: &mut [f64]) {
        for c in &self.cranks {
            c.velocity(zd, v);
        }
        for s in &self.sliders {
            s.velocity(zd, v);
        }
        for d in &self.groups {
            d.velocity(zd, v);
        }
    }

    /// The velocity analogues `ws.u` (column j the rates for zd = e_j).
    pub fn velocity_analogues(&self, ws: &mut Frame) {
        if let Some(reach) = &self.reach {
            return self.velocity_analogues_over(reach, ws);
        }
        let (n, m) = (ws.x.len(), ws.q.len());
        if m == 1 {
            // One column, the rates for zd = 1: no loop over the unit rates.
            return self.rates(&[1.0], &mut ws.u[..n]);
        }
        // Without `reach`, m <= REACH_FROM_M: the unit rates fit on the stack.
        let mut unit = [0.0; REACH_FROM_M];
        for j in 0..m {
            unit[j] = 1.0;
            self.rates(&unit[..m], &mut ws.u[j * n..(j + 1) * n]);
            unit[j] = 0.0;
        }
    }

    /// [`ClosedForm::velocity_analogues`] with each column over the pieces its coordinate moves
    /// (`reach`): U is cleared whole when it held another zero pattern, then each column's
    /// other entries keep those zeros.
    fn velocity_analogues_over(&self, reach: &ColumnReach, ws: &mut Frame) {
        let (n, m) = (ws.x.len(), ws.q.len());
        if ws.u_zeros_for != reach.zeros_id {
            ws.u.fill(0.0);
            ws.u_zeros_for = reach.zeros_id;
        }
        let (mut u, mut unit) = (std::mem::take(&mut ws.u), std::mem::take(&mut ws.rhs));
        unit[..m].fill(0.0);
        for j in 0..m {
            unit[j] = 1.0;
            let (zd, v) = (&unit[..m], &mut u[j * n..(j + 1) * n]);
            reach.cranks[j].iter().for_each(|&i| self.cranks[i].velocity(zd, v));
            reach.sliders[j].iter().for_each(|&i| self.sliders[i].velocity(zd, v));
            reach.groups[j].iter().for_each(|&i| self.groups[i].velocity(zd, v));
            unit[j] = 0.0;
        }
        (ws.u, ws.rhs) = (u, unit);
    }

    /// Body rates `ws.xd` = U zd and the convective term `ws.c` (accelerations at zdd = 0),
    /// from `ws.u`.
    pub fn convective(&self, zd: &[f64], ws: &mut Frame) {
        if let [zd] = zd {
            // One coordinate: each xd_i = 0 + u_i zd, as `body_rates` sums it (its pass over one
            // column, `u_times_from`), here in place of that generic call.
            ws.xd.iter_mut().zip(&ws.u).for_each(|(v, u)| *v = 0.0 + u * zd);
        } else {
            body_rates(zd, ws);
        }
        self.accelerations(&ws.xd, &mut ws.c);
    }

    /// Body accelerations `a` at zero coordinate accelerations for body rates v (3n, a velocity
    /// of the mechanism), at the last positions: the convective term for v, -J^-1 gamma(v, v).
    pub fn accelerations(&self, v: &[f64], a: &mut [f64]) {
        let (v, a) = (rows(v), rows_mut(a));
        for k in &self.cranks {
            k.acceleration(v, a);
        }
        for s in &self.sliders {
            s.acceleration(a);
        }
        for d in &self.groups {
            d.acceleration(v, a);
        }
    }

    /// U (whole columns: no `reach`), xd and c at the positions in `ws` in one pass over the
    /// pieces ([`Pass`]): what [`ClosedForm::velocity_analogues`] then
    /// [`ClosedForm::convective`] write, to the bit; and q = z, qd = zd.
    #[inline(always)]
    fn pass<const M: usize>(&self, z: &[f64], zd: &[f64], ws: &mut Frame) {
        let zd: [f64; M] = zd.try_into().expect("M coordinates");
        // q = z and qd = zd as M values (no dispatch on the length as `copy_small`'s).
        let q: &mut [f64; M] = ws.q.as_mut_slice().try_into().expect("M coordinates");
        *q = z.try_into().expect("M coordinates");
        let qd: &mut [f64; M] = ws.qd.as_mut_slice().try_into().expect("M coordinates");
        *qd = zd;
        let mut p = Pass::new(zd, &mut ws.u, &mut ws.xd, &mut ws.c);
        for c in &self.cranks {
            p.piece(&[c.body], |zd, v| c.velocity(zd, v), |v, a| c.acceleration(v, a));
        }
        for s in &self.sliders {
            p.piece(&[s.body], |zd, v| s.velocity(zd, v), |_, a| s.acceleration(a));
        }
        for d in &self.groups {
            d.pass(&mut p);
        }
    }

    /// Positions, analogues and the convective term at (z, zd) in the user's chart, and the
    /// user's coordinates q = z, qd = zd: what `dynamics::kinematic_stages` computes there.
    pub fn kinematic_stages(&mut self, z: &[f64], zd: &[f64], ws: &mut Frame) -> Result<(), KinematicsError> {
        self.stages_from(z, zd, Start::Reference, ws)
    }

    /// [`ClosedForm::kinematic_stages`] with the triad's Newton from the platform's pose in
    /// `ws.x`, a prediction on the reference branches (the ODE's, whose side `keeps_branches`
    /// has checked and whose distance from the solution the ODE bounds, as the Newton path's):
    /// nearer than the reference configuration, so about two iterations fewer. The solution is
    /// then the reference's to the Newton tolerance, not to the bit.
    pub fn predicted_stages(&mut self, z: &[f64], zd: &[f64], ws: &mut Frame) -> Result<(), KinematicsError> {
        self.stages_from(z, zd, Start::Predicted, ws)
    }

    fn stages_from(&mut self, z: &[f64], zd: &[f64], start: Start, ws: &mut Frame) -> Result<(), KinematicsError> {
        self.place(z, start, ws)?;
        match (&self.reach, zd.len()) {
            (None, 1) => self.pass::<1>(z, zd, ws),
            (None, 2) => self.pass::<2>(z, zd, ws),
            (None, 3) => self.pass::<3>(z, zd, ws),
            (None, 4) => self.pass::<4>(z, zd, ws),
            _ => {
                self.velocity_analogues(ws);
                self.convective(zd, ws);
                copy_small(&mut ws.q, z);
                copy_small(&mut ws.qd, zd);
            }
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::Workspace;

    /// The one pass over the pieces (`ClosedForm::pass`, up to 4 coordinates) writes U, xd and
    /// c to the bit as the passes by stage do ([`ClosedForm::velocity_analogues`], a pass over
    /// the pieces per column of U, then [`ClosedForm::convective`]: xd = U zd by
    /// `u_times_from` and an accelerations pass), for every shipped model with closed forms
    /// (1, 2 and 3 coordinates among them), at its drawing and, where they assemble there, at a
    /// point 0.05 away in each coordinate, with rates of both signs.
    #[test]
    fn one_pass_writes_what_the_stages_do_to_the_bit() {
        let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples/models");
        let mut files: Vec<_> = [root.clone(), root.join("library")]
            .iter()
            .flat_map(|d| std::fs::read_dir(d).unwrap().map(|e| e.unwrap().path()))
            .filter(|p| p.extension().is_some_and(|e| e == "yaml"))
            .collect();
        files.sort();
        let mut coordinates = Vec::new();
        for path in &files {
            let mech = crate::load(path.to_str().unwrap()).unwrap();
            let Some(mut closed) = ClosedForm::new(&mech).filter(|c| c.writes_u_whole()) else { continue };
            let (q0, _) = mech.initial_state();
            let m = q0.len();
            coordinates.push(m);
            for shift in [0.0, 0.05] {
                let z: Vec<f64> = q0.iter().map(|q| q + shift).collect();
                let zd: Vec<f64> = (0..m).map(|j| [0.7, -1.3, 0.4, -0.9][j] * (1.0 + shift)).collect();
                let (mut one, mut staged) = (Workspace::new(&mech), Workspace::new(&mech));
                let placed = closed.kinematic_stages(&z, &zd, &mut one).is_ok();
                assert_eq!(closed.positions(&z, &mut staged).is_ok(), placed, "{}", path.display());
                if !placed {
                    // Off the drawing a triad's Newton from its reference may not converge.
                    assert!(shift > 0.0, "{} at its drawing", path.display());
                    continue;
                }
                closed.velocity_analogues(&mut staged);
                closed.convective(&zd, &mut staged);
                let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
                for (what, a, b) in [("U", &one.u, &staged.u), ("xd", &one.xd, &staged.xd), ("c", &one.c, &staged.c)] {
                    assert_eq!(bits(a), bits(b), "{what} of {} at shift {shift}", path.display());
                }
            }
        }
        coordinates.sort();
        coordinates.dedup();
        assert_eq!(coordinates, [1, 2, 3]);
    }
}
