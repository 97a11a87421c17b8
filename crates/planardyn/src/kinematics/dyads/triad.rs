//! The class III triad of six revolute pairs: three legs (binary links) hinged at A_i to links
//! solved before them and at C_i to a platform (a ternary link). The platform's pose
//! p = (X, Y, phi) solves the three distance equations |C_i(p) - A_i| = l_i by Newton on their
//! 3 x 3 Jacobian, from the pose of the reference configuration (the integrator's last accepted
//! point), which keeps its assembly branch; each leg then follows from A_i and C_i in closed
//! form. Rates and accelerations solve with the same Jacobian at the solution, rows
//! (e_i, (R c_i) x e_i) with e_i = C_i - A_i and R c_i the platform's arm of C_i: its
//! determinant vanishes where the three legs' lines meet in a point (or are parallel), the
//! triad's type II singularity, and its sign is the branch's side of it.
//!
//! A leg may be two bodies a relative prismatic input locks into one link (the 3-RPR's
//! cylinders, `extension`): its length l_i then follows the input, C_i moves along it at the
//! rod's relative velocity s_i, and the leg's equations gain s_i (rates) and its Coriolis
//! term 2 w_i E s_i (accelerations).

pub(super) mod near;

use super::extension::Arm;
use super::{put_acceleration, put_rate, Joint};
use crate::kinematics::group_sigma::{triad_sigma, Block};
use crate::kinematics::position::{MAX_NEWTON, POLISH_BELOW, POSITION_TOL, ROUND_OFF_FLOOR};
use crate::model::pairs::frames::{dot, perp, rot, sub};
use crate::model::{BodyId, Link};
use crate::{KinematicsError, SingularityKind};
use near::{near_atan2, turned, EXACT_TURN};

#[inline]
fn cross(a: [f64; 2], b: [f64; 2]) -> f64 {
    a[0] * b[1] - a[1] * b[0]
}

/// Leg i's row of the 3 x 3 Jacobian: (e, lever x e).
#[inline]
fn row(e: [f64; 2], lever: [f64; 2]) -> [f64; 3] {
    [e[0], e[1], cross(lever, e)]
}

/// Inverse of a 3 x 3 matrix by its cofactors (None where it is singular), and its determinant.
#[inline]
fn inverse(m: &[[f64; 3]; 3]) -> Option<([[f64; 3]; 3], f64)> {
    let c = |i: usize, j: usize| {
        let (i1, i2, j1, j2) = ((i + 1) % 3, (i + 2) % 3, (j + 1) % 3, (j + 2) % 3);
        m[i1][j1] * m[i2][j2] - m[i1][j2] * m[i2][j1]
    };
    let cof = [[c(0, 0), c(0, 1), c(0, 2)], [c(1, 0), c(1, 1), c(1, 2)], [c(2, 0), c(2, 1), c(2, 2)]];
    let det = m[0][0] * cof[0][0] + m[0][1] * cof[0][1] + m[0][2] * cof[0][2];
    if !(det.abs() > 0.0 && det.is_finite()) {
        return None;
    }
    let k = 1.0 / det;
    Some(([0, 1, 2].map(|i| [0, 1, 2].map(|j| cof[j][i] * k)), det))
}

#[inline]
fn times(inv: &[[f64; 3]; 3], b: [f64; 3]) -> [f64; 3] {
    inv.map(|r| r[0] * b[0] + r[1] * b[1] + r[2] * b[2])
}

/// A body's three entries (x, y, angle) of x, v or a from `at`, one of the triad's offsets
/// (`Triad::at`, `Triad::outer_at`), unchecked: a checked slice costs 5-7 instructions and a
/// panic branch an access, 57 of them an evaluation of the 3-RRR; with one length check a call
/// instead (`Triad::holds`) the evaluation took 7375 instructions, not 7655 (7649 with an
/// assert an access, 7734 with `&v[at..][..3]`: benchmarks/icount).
///
/// # Safety
/// `Triad::holds(v)` has passed (every offset plus 3 is at most `span`, at most v's length).
#[inline(always)]
unsafe fn three(v: &[f64], at: usize) -> &[f64] {
    debug_assert!(at + 3 <= v.len());
    // SAFETY: at + 3 <= span <= v.len() (the caller's `holds`).
    unsafe { v.get_unchecked(at..at + 3) }
}

/// [`three`] to write.
///
/// # Safety
/// As `three`.
#[inline(always)]
unsafe fn three_mut(v: &mut [f64], at: usize) -> &mut [f64] {
    debug_assert!(at + 3 <= v.len());
    // SAFETY: as `three`.
    unsafe { v.get_unchecked_mut(at..at + 3) }
}

/// A point of a link as the joint on the link's own entries (`three`): the body as the first
/// of them, a constant the joint's reads then check at compile time (a body index kept in the
/// triad was loaded and checked against 0 at every read, 3 instructions a leg in each of
/// `position`, `velocity` and `acceleration`); the ground as itself.
#[inline(always)]
fn local(on_body: bool, s: [f64; 2]) -> Joint {
    Joint { link: if on_body { Link::Body(BodyId(0)) } else { Link::Ground }, s }
}

/// Largest turn (rad) of a body from the reference for the side test near it
/// (`Triad::side_near_reference`): there [`near::near_sin_cos`] is within 2e-14 of sin and cos (its
/// first left-out terms, 0.5^13 / 13! and 0.5^14 / 14!). The fold guard's predictions are
/// within a step of the last accepted point; a body turned further takes the library's.
const NEAR_TURN: f64 = 0.5;

/// How far, relative to the product of the Jacobian's rows' sizes H (each row's entries at most
/// |arm_i| (1 + |c_i|)), the determinant from the series must clear zero for its sign to be the
/// library's. Rotations within eta = 3e-14 of the true ones (the series, the reference's
/// sin and cos and the turn, each within 1 ulp but the series' 2e-14) move each entry of a row
/// by at most 8 eta of its size and the determinant (six products of three entries) by at most
/// about 150 eta H = 4.5e-12 H; the library's own rounding moves it by about 5e-14 H. Where the
/// series' determinant is more than 1e-9 H from zero, 200 times both, the two have one sign.
const SIDE_MARGIN: f64 = 1e-9;

#[derive(Debug, Clone)]
pub struct Triad {
    /// The legs' bodies (the bases of two-body legs), then the platform's.
    pub bodies: [usize; 4],
    /// Those and the followers of two-body legs: the group's bodies.
    pub members: Vec<usize>,
    /// Where the bodies' entries start in x, v and a (3 b), and the outer joints' links' (their
    /// indices in trig, the ground's 0 and not read); all entries lie below `span`.
    at: [usize; 4],
    outer_at: [usize; 3],
    outer_trig: [usize; 3],
    span: usize,
    /// Per leg, its relative input if it is two bodies; whether any is.
    extended: [Option<Arm>; 3],
    cylinders: bool,
    /// A_i on the links solved before (whether each link is a body, the point in its frame:
    /// `local` makes the joint), and the same points in the legs' frames.
    outer_on_body: [bool; 3],
    outer_s: [[f64; 2]; 3],
    s_outer: [[f64; 2]; 3],
    /// C_i - A_i in leg i's frame, its squared length and 1 / length.
    arms: [[f64; 2]; 3],
    arms2: [f64; 3],
    inv_arm: [f64; 3],
    /// C_i in the platform's frame.
    s_platform: [[f64; 2]; 3],
    /// 1 / L, the mechanism's length (Newton's scaled residual).
    inv_scale: f64,
    /// The product over the legs of 1 + |c_i|: times that of the arms' lengths, it bounds the
    /// product of the Jacobian's rows' entries (`SIDE_MARGIN`).
    platform_sizes: f64,
    branch: Branch,
    geometry: Geometry,
}

/// What the triad keeps from the reference configuration: the platform's pose (Newton's start),
/// its Jacobian's determinant and the sign of it, and each leg's angle with R(angle) arm_i (the new
/// angles are taken within pi of them).
#[derive(Debug, Clone, Copy, Default)]
struct Branch {
    pose: [f64; 3],
    det: f64,
    side: f64,
    legs: [f64; 3],
    directions: [[f64; 2]; 3],
    /// The bodies' angles (legs, then the platform) and their [cos, sin], for the side test
    /// near the reference (`Triad::side_near_reference`).
    angles: [f64; 4],
    trig: [[f64; 2]; 4],
}

impl Branch {
    /// [cos, sin] of the platform's angle phi: the reference's rotation turned by the series
    /// within [`EXACT_TURN`] of its angle (the library's to a few ulp), else the library's.
    #[inline]
    fn platform_trig(&self, phi: f64) -> [f64; 2] {
        let d = phi - self.angles[3];
        if d.abs() <= EXACT_TURN {
            return turned(self.trig[3], d);
        }
        let (s, c) = phi.sin_cos();
        [c, s]
    }
}

/// The triad at its solved position: R s of A_i on their links and on the legs, e_i, the
/// platform's arms R c_i, the inverse Jacobian, |e_i|^2 and 1 / |e_i|^2.
#[derive(Debug, Clone, Copy, Default)]
struct Geometry {
    known: [[f64; 2]; 3],
    own: [[f64; 2]; 3],
    e: [[f64; 2]; 3],
    lever: [[f64; 2]; 3],
    inv: [[f64; 3]; 3],
    e2: [f64; 3],
    inv_e2: [f64; 3],
}

impl Triad {
    /// A triad of legs `bodies[..3]` hinged at `outer` (the points `s_outer` in the legs'
    /// frames) and at C_i to the platform `bodies[3]` (`s_inner[i]` in leg i's frame,
    /// `s_platform[i]` in the platform's), legs of two bodies in `extended` (whose arms
    /// replace those of `s_outer` and `s_inner`); `scale` the mechanism's length.
    pub fn new(
        bodies: [usize; 4],
        outer: [Joint; 3],
        [s_outer, s_inner, s_platform]: [[[f64; 2]; 3]; 3],
        extended: [Option<Arm>; 3],
        scale: f64,
    ) -> Self {
        let arms = [0, 1, 2].map(|i| sub(s_inner[i], s_outer[i]));
        let members = bodies.iter().copied().chain(extended.iter().flatten().map(|a| a.ext.follower)).collect();
        let cylinders = extended.iter().any(Option::is_some);
        let outer_trig = outer.map(|j| match j.link {
            Link::Ground => 0,
            Link::Body(b) => b.0,
        });
        let mut triad = Triad {
            bodies,
            members,
            at: bodies.map(|b| 3 * b),
            outer_at: outer_trig.map(|b| 3 * b),
            outer_trig,
            span: 3 * (bodies.iter().chain(&outer_trig).max().unwrap() + 1),
            extended,
            cylinders,
            outer_on_body: outer.map(|j| matches!(j.link, Link::Body(_))),
            outer_s: outer.map(|j| j.s),
            s_outer,
            arms,
            arms2: [0.0; 3],
            inv_arm: [0.0; 3],
            s_platform,
            inv_scale: 1.0 / scale,
            platform_sizes: s_platform.iter().map(|c| 1.0 + c[0].hypot(c[1])).product(),
            branch: Branch::default(),
            geometry: Geometry::default(),
        };
        triad.set_arms(|_| 0.0);
        triad
    }

    /// A_i as the joint on its link's own entries (`local`).
    #[inline(always)]
    fn outer(&self, i: usize) -> Joint {
        local(self.outer_on_body[i], self.outer_s[i])
    }

    /// That x, v or a holds every entry of the triad's bodies and outer links (`span`), which
    /// makes `three` and `three_mut` at their offsets safe: checked once a call.
    #[inline(always)]
    fn holds(&self, v: &[f64]) {
        assert!(v.len() >= self.span, "{} entries, the triad's bodies need {}", v.len(), self.span);
    }

    /// The legs' arms at the extensions d(leg) of the two-body ones.
    #[inline]
    fn set_arms(&mut self, d: impl Fn(&Arm) -> f64) {
        for (i, a) in self.extended.iter().enumerate() {
            if let Some(a) = a {
                self.arms[i] = a.arm(d(a));
            }
            self.arms2[i] = dot(self.arms[i], self.arms[i]);
            self.inv_arm[i] = 1.0 / self.arms2[i].sqrt();
        }
    }

    /// The Jacobian's determinant with the bodies' rotations `cs` ([cos, sin] of the legs',
    /// then the platform's angle): the legs' directions and the platform's arms are theirs.
    #[inline]
    fn det_at(&self, cs: [[f64; 2]; 4]) -> f64 {
        let rows = [0, 1, 2].map(|i| row(rot(cs[i], self.arms[i]), rot(cs[3], self.s_platform[i])));
        let [a, b, d] = rows;
        a[0] * (b[1] * d[2] - b[2] * d[1]) - a[1] * (b[0] * d[2] - b[2] * d[0]) + a[2] * (b[0] * d[1] - b[1] * d[0])
    }

    /// The sign of the Jacobian's determinant with the bodies' angles in x (any x, not
    /// necessarily assembled).
    fn side(&self, x: &[f64]) -> f64 {
        self.det_at(self.bodies.map(|b| {
            let (s, c) = x[3 * b + 2].sin_cos();
            [c, s]
        }))
        .signum()
    }

    /// The turns of the bodies (legs, then the platform) in x from the reference's angles.
    #[inline]
    fn turns(&self, x: &[f64]) -> [f64; 4] {
        // Exact where the angles are 1 rad or more (Sterbenz), within 1.1e-16 below.
        self.holds(x);
        // SAFETY: `holds(x)`.
        [0, 1, 2, 3].map(|i| unsafe { three(x, self.at[i]) }[2] - self.branch.angles[i])
    }

    /// H = prod_i H_i, H_i = |arm_i| (1 + |c_i|) the bound of the Jacobian's row i.
    #[inline]
    fn row_sizes(&self) -> f64 {
        self.platform_sizes * (self.arms2[0] * self.arms2[1] * self.arms2[2]).sqrt()
    }

    /// [`Triad::side`] from the reference's determinant alone where it is certain (6R triads,
    /// whose arms are fixed), for the bodies' turns d from the reference: turning leg i by d_i
    /// and the platform by d_p moves row i of the Jacobian (of size at most H_i) by at most
    /// H_i (|d_i| + |d_p|) (the chord of e_i, and the change of the arm's cross product with
    /// it), so the determinant (multilinear in the rows, each term bounded by Hadamard's
    /// inequality) by at most H (prod_i (1 + |d_i| + |d_p|) - 1). Where the reference's
    /// clears that by [`SIDE_MARGIN`] H (which covers its rounding and the library's), the
    /// side is the reference's; else None.
    #[inline]
    fn side_from_reference(&self, d: [f64; 4]) -> Option<f64> {
        if self.cylinders {
            return None;
        }
        let moved = [0, 1, 2].map(|i| 1.0 + (d[i].abs() + d[3].abs()));
        let bound = moved[0] * moved[1] * moved[2] - 1.0 + SIDE_MARGIN;
        (self.branch.det.abs() > bound * self.row_sizes()).then_some(self.branch.side)
    }

    /// [`Triad::side`] without the library's sin and cos where it can be told for certain:
    /// [`Triad::side_from_reference`], else each rotation from the reference's
    /// (`Branch::trig`) turned by the angle d from the reference's, by the series of sin d and
    /// cos d ([`NEAR_TURN`]), and the sign of that determinant where it clears zero by
    /// [`SIDE_MARGIN`] H; None where it does not (near the singularity, or a body turned
    /// further), and the caller then takes `side`.
    fn side_near_reference(&self, x: &[f64]) -> Option<f64> {
        let d = self.turns(x);
        if let Some(side) = self.side_from_reference(d) {
            return Some(side);
        }
        let mut cs = [[0.0; 2]; 4];
        for i in 0..4 {
            if !(d[i].abs() <= NEAR_TURN) {
                return None;
            }
            cs[i] = turned(self.branch.trig[i], d[i]);
        }
        let det = self.det_at(cs);
        (det.abs() > SIDE_MARGIN * self.row_sizes()).then(|| det.signum())
    }

    /// Take the branch of the configuration x (a solution).
    pub fn set_reference(&mut self, x: &[f64]) {
        self.set_arms(|a| a.ext.shift_in(x));
        let p = 3 * self.bodies[3];
        let angles = self.bodies.map(|b| x[3 * b + 2]);
        let trig = angles.map(|a| {
            let (s, c) = a.sin_cos();
            [c, s]
        });
        let directions = [0, 1, 2].map(|i| rot(trig[i], self.arms[i]));
        let legs = [angles[0], angles[1], angles[2]];
        let det = self.det_at(trig);
        let side = det.signum();
        self.branch = Branch { pose: [x[p], x[p + 1], x[p + 2]], det, side, legs, directions, angles, trig };
    }

    /// Take the branch and arms of `from`, the same triad in another copy of the closed forms:
    /// what `set_reference` sets, without its sines and cosines.
    pub fn copy_reference(&mut self, from: &Triad) {
        (self.arms, self.arms2, self.inv_arm) = (from.arms, from.arms2, from.inv_arm);
        self.branch = from.branch;
    }

    /// Whether the bodies' angles in x (a Newton predictor's) keep the reference's side of the
    /// triad's singularity; a predictor past it means the motion leaves the branch there,
    /// which Newton from the reference pose would not follow. The fold guard asks it at every
    /// evaluation: from the series near the reference, the library's sin and cos only where
    /// the series cannot tell.
    pub fn keeps_side(&self, x: &[f64]) -> bool {
        self.side_near_reference(x).unwrap_or_else(|| self.side(x)) == self.branch.side
    }

    /// The bodies' poses (x and trig) on the reference branch, the links before them solved.
    /// Newton starts from the reference pose, or with `from_x` from the platform's pose in x
    /// (a prediction on the reference branch, `ClosedForm::predicted_stages`). Newton stops as the general position solve does (`position`): at a scaled residual
    /// (each leg's length error / L) of POSITION_TOL relative to the pose's size, or at
    /// round-off once a step no longer halves it, with one more step above POLISH_BELOW.
    #[inline(never)]
    pub fn position(
        &mut self,
        z: &[f64],
        from_x: bool,
        x: &mut [f64],
        trig: &mut [[f64; 2]],
    ) -> Result<(), KinematicsError> {
        if self.cylinders {
            self.set_arms(|a| a.ext.shift(z));
        }
        self.holds(x);
        // The geometry is written in place (a 42-value copy an evaluation less), the Newton
        // iterates' levers, e and inverse once they have converged: a failed solve leaves it
        // partial, as it leaves x, and nothing reads it before the next successful one.
        let g = &mut self.geometry;
        let mut a = [[0.0; 2]; 3];
        for i in 0..3 {
            let (j, at) = (local(self.outer_on_body[i], self.outer_s[i]), self.outer_at[i]);
            // SAFETY: `holds(x)` above.
            (a[i], g.known[i]) = j.place(unsafe { three(x, at) }, &trig[self.outer_trig[i]..]);
        }
        let mut pose = if from_x {
            // SAFETY: `holds(x)` above.
            let p = unsafe { three(x, self.at[3]) };
            [p[0], p[1], p[2]]
        } else {
            self.branch.pose
        };
        let size = (pose[0].abs() * self.inv_scale).max(pose[1].abs() * self.inv_scale).max(pose[2].abs());
        let tol = POSITION_TOL * (1.0 + size);
        let (mut first, mut previous, mut polish) = (f64::INFINITY, f64::INFINITY, false);
        for _ in 0..=MAX_NEWTON {
            let cs = self.branch.platform_trig(pose[2]);
            let (mut f, mut lever, mut e) = ([0.0; 3], [[0.0; 2]; 3], [[0.0; 2]; 3]);
            let mut norm: f64 = 0.0;
            for i in 0..3 {
                lever[i] = rot(cs, self.s_platform[i]);
                e[i] = sub([pose[0] + lever[i][0], pose[1] + lever[i][1]], a[i]);
                f[i] = 0.5 * (dot(e[i], e[i]) - self.arms2[i]);
                norm = norm.max(f[i].abs() * self.inv_arm[i]);
            }
            norm *= self.inv_scale;
            if !norm.is_finite() || norm > 1e6 * first.max(1.0) {
                break;
            }
            first = first.min(norm);
            let jac = [0, 1, 2].map(|i| row(e[i], lever[i]));
            let Some((inv, _)) = inverse(&jac) else { return Err(KinematicsError::singular(SingularityKind::TypeII)) };
            let done = polish || norm <= tol || (norm <= ROUND_OFF_FLOOR && norm > 0.5 * previous);
            if done && (polish || norm <= POLISH_BELOW) {
                (g.lever, g.e, g.inv) = (lever, e, inv);
                self.place(pose, cs, x, trig);
                for a in self.extended.iter_mut().flatten() {
                    a.ext.place(z, x, trig);
                }
                return Ok(());
            }
            polish = done;
            previous = norm;
            let d = times(&inv, f);
            pose = [pose[0] - d[0], pose[1] - d[1], pose[2] - d[2]];
        }
        let residual = if first.is_finite() { first } else { f64::INFINITY };
        Err(KinematicsError::AssemblyFailed { residual, iterations: MAX_NEWTON })
    }

    /// Write the platform at `pose` and the legs from A_i and C_i, completing the geometry
    /// (`position`'s, after its `holds(x)`).
    #[inline]
    fn place(&mut self, pose: [f64; 3], cs: [f64; 2], x: &mut [f64], trig: &mut [[f64; 2]]) {
        let g = &mut self.geometry;
        // SAFETY: `holds(x)` in `position`, the only caller.
        unsafe { three_mut(x, self.at[3]) }.copy_from_slice(&pose);
        trig[self.bodies[3]] = cs;
        for i in 0..3 {
            let (arm, e, b) = (self.arms[i], g.e[i], self.bodies[i]);
            let e2 = dot(e, e);
            // The rotation taking the arm in the leg's frame to e, and its angle from the
            // reference's direction.
            let r = 1.0 / (self.arms2[i] * e2).sqrt();
            let leg_cs = [dot(arm, e) * r, cross(arm, e) * r];
            let d = self.branch.directions[i];
            let turn = near_atan2(cross(d, e), dot(d, e));
            let rs = rot(leg_cs, self.s_outer[i]);
            let c = sub([pose[0] + g.lever[i][0], pose[1] + g.lever[i][1]], e);
            // SAFETY: as the platform's.
            unsafe { three_mut(x, self.at[i]) }.copy_from_slice(&[
                c[0] - rs[0],
                c[1] - rs[1],
                self.branch.legs[i] + turn,
            ]);
            trig[b] = leg_cs;
            g.own[i] = rs;
            g.e2[i] = e2;
            g.inv_e2[i] = 1.0 / e2;
        }
    }

    /// C_i's velocity relative to leg i (s_i), for the extensions' rates d'(leg); None where
    /// every leg is one body (the 6R triad: every s_i is zero, and its terms are left out).
    /// `CYLINDERS` is `self.cylinders`, a constant in each of `velocity` and `acceleration`'s
    /// two compilations (`velocity_with`, `acceleration_with`), so that the 6R triad's carries
    /// no test of it.
    #[inline(always)]
    fn slides<const CYLINDERS: bool>(&self, d: impl Fn(&Arm) -> f64) -> Option<[[f64; 2]; 3]> {
        CYLINDERS.then(|| self.extended.each_ref().map(|a| a.as_ref().map_or([0.0; 2], |a| a.slide(d(a)))))
    }

    /// The bodies' rates for the coordinate rates zd, those of the links before them in v:
    /// the platform's from e_i . (v_C_i - v_A_i - s_i) = 0, each leg's turning rate from
    /// v_C_i - v_A_i - s_i = w E e_i.
    #[inline(never)]
    pub fn velocity(&self, zd: &[f64], v: &mut [f64]) {
        if self.cylinders {
            self.velocity_with::<true>(zd, v);
        } else {
            self.velocity_with::<false>(zd, v);
        }
    }

    /// [`Triad::velocity`] with `CYLINDERS` = `self.cylinders` (`slides`).
    #[inline(always)]
    fn velocity_with<const CYLINDERS: bool>(&self, zd: &[f64], v: &mut [f64]) {
        let g = &self.geometry;
        let s = self.slides::<CYLINDERS>(|a| a.ext.input_rate(zd));
        self.holds(v);
        // SAFETY (each `three` and `three_mut` below): `holds(v)`.
        let va = [0, 1, 2].map(|i| self.outer(i).velocity(g.known[i], unsafe { three(v, self.outer_at[i]) }));
        let b = [0, 1, 2].map(|i| match s {
            Some(s) => dot(g.e[i], [va[i][0] + s[i][0], va[i][1] + s[i][1]]),
            None => dot(g.e[i], va[i]),
        });
        let [vx, vy, w] = times(&g.inv, b);
        unsafe { three_mut(v, self.at[3]) }.copy_from_slice(&[vx, vy, w]);
        for i in 0..3 {
            let mut vc = [vx - w * g.lever[i][1], vy + w * g.lever[i][0]];
            if let Some(s) = s {
                vc = sub(vc, s[i]);
            }
            let wl = cross(g.e[i], sub(vc, va[i])) * g.inv_e2[i];
            put_rate(unsafe { three_mut(v, self.at[i]) }, 0, va[i], g.own[i], wl);
        }
        if s.is_some() {
            self.extended.iter().flatten().for_each(|a| a.ext.velocity(zd, v));
        }
    }

    /// The bodies' accelerations, from the rates v and the accelerations of the links before
    /// them in a: with a_C_i = a_A_i + al_i E e_i - w_i^2 e_i + 2 w_i E s_i (leg i's rates),
    /// e_i . (a_C_i - a_A_i) = -w_i^2 |e_i|^2 + 2 w_i s_i x e_i.
    #[inline(never)]
    pub fn acceleration(&self, v: &[f64], a: &mut [f64]) {
        if self.cylinders {
            self.acceleration_with::<true>(v, a);
        } else {
            self.acceleration_with::<false>(v, a);
        }
    }

    /// [`Triad::acceleration`] with `CYLINDERS` = `self.cylinders` (`slides`).
    #[inline(always)]
    fn acceleration_with<const CYLINDERS: bool>(&self, v: &[f64], a: &mut [f64]) {
        let g = &self.geometry;
        let s = self.slides::<CYLINDERS>(|x| x.ext.rate(v));
        // The Coriolis acceleration of C_i on leg i, 2 w_i E s_i.
        let coriolis = |s: [[f64; 2]; 3], i: usize, wl: f64| {
            let c = perp(s[i]);
            [2.0 * wl * c[0], 2.0 * wl * c[1]]
        };
        self.holds(v);
        self.holds(a);
        // SAFETY (each `three` and `three_mut` below): `holds(v)` and `holds(a)`.
        let w = unsafe { three(v, self.at[3]) }[2];
        let wl = [0, 1, 2].map(|i| unsafe { three(v, self.at[i]) }[2]);
        let (mut aa, mut rhs) = ([[0.0; 2]; 3], [0.0; 3]);
        for i in 0..3 {
            let (wl, l, at) = (wl[i], g.lever[i], self.outer_at[i]);
            // a_A_i plus the Coriolis acceleration of C_i on the leg.
            aa[i] = self.outer(i).acceleration(g.known[i], unsafe { three(v, at) }, unsafe { three(a, at) });
            let mut ac = aa[i];
            if let Some(s) = s {
                let k = coriolis(s, i, wl);
                ac = [ac[0] + k[0], ac[1] + k[1]];
            }
            rhs[i] = dot(g.e[i], [ac[0] + w * w * l[0], ac[1] + w * w * l[1]]) - wl * wl * g.e2[i];
        }
        let [ax, ay, al] = times(&g.inv, rhs);
        unsafe { three_mut(a, self.at[3]) }.copy_from_slice(&[ax, ay, al]);
        for i in 0..3 {
            let (wl, l) = (wl[i], g.lever[i]);
            let ac = [ax - al * l[1] - w * w * l[0], ay + al * l[0] - w * w * l[1]];
            let mut rel = sub(ac, aa[i]);
            if let Some(s) = s {
                rel = sub(rel, coriolis(s, i, wl));
            }
            let al_leg = cross(g.e[i], rel) * g.inv_e2[i];
            put_acceleration(unsafe { three_mut(a, self.at[i]) }, 0, aa[i], g.own[i], wl, al_leg);
        }
        if s.is_some() {
            self.extended.iter().flatten().for_each(|x| x.ext.acceleration(v, a));
        }
    }

    /// The triad's type II measure at the last positions (`group_sigma`'s): the smallest
    /// singular value of its block at its own length L_k (1 / L_k = `inv_length`), 12 x 12
    /// (21 x 21 with three two-body legs): columns (r, phi) of each leg, the platform, then the
    /// followers; two rows a pair, the outer pair i [I, E R s_A] on leg i, the inner pair i
    /// [I, E R s_C] on the body of leg i that holds C_i and -[I, E R c_i] on the platform, and
    /// each relative input's three (`Extension::block_rows`). The 6R triad's from a 4 x 4
    /// secular equation (`group_sigma::triad_sigma`); with cylinder legs, a dense SVD of the
    /// block (18 us for 21 x 21 on a loaded machine: the monitor takes it once a step).
    pub fn sigma(&self, inv_length: f64) -> f64 {
        let g = &self.geometry;
        if self.extended.iter().all(Option::is_none) {
            let k = |v: [f64; 2]| [v[0] * inv_length, v[1] * inv_length];
            let p = [0, 1, 2].map(|i| k([g.own[i][0] + g.e[i][0], g.own[i][1] + g.e[i][1]]));
            return triad_sigma(g.own.map(k), p, g.lever.map(k));
        }
        let mut block = Block::new(self.members.len(), inv_length);
        let mut follower = 4;
        for (i, x) in self.extended.iter().enumerate() {
            block.point_rows(&[(i, 1.0, g.own[i])]);
            let c = [g.own[i][0] + g.e[i][0], g.own[i][1] + g.e[i][1]];
            match x {
                Some(x) => {
                    block.point_rows(&[(follower, 1.0, x.on_follower(c)), (3, -1.0, g.lever[i])]);
                    x.ext.block_rows(i, follower, &mut block);
                    follower += 1;
                }
                None => block.point_rows(&[(i, 1.0, c), (3, -1.0, g.lever[i])]),
            }
        }
        block.sigma()
    }
}

#[cfg(test)]
mod tests {
    use super::{Joint, Triad};
    use crate::model::Link;

    /// A 3-RRR's triad: legs 0-2 hinged to the ground at A_i, the platform body 3 (m).
    fn three_rrr() -> Triad {
        let a = [[0.0, 0.0], [1.0, 0.0], [0.5, 0.9]];
        let outer = a.map(|s| Joint { link: Link::Ground, s });
        let s_outer = [[-0.2, 0.0]; 3];
        let s_inner = [[0.2, 0.0], [0.25, 0.0], [0.3, 0.0]];
        let s_platform = [[-0.1, -0.05], [0.1, -0.05], [0.0, 0.1]];
        Triad::new([0, 1, 2, 3], outer, [s_outer, s_inner, s_platform], [None, None, None], 1.0)
    }

    /// A few hundred thousand numbers in [0, 1) from a fixed seed (an LCG: the test repeats).
    fn uniform(seed: &mut u64) -> f64 {
        *seed = seed.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
        (*seed >> 11) as f64 / (1u64 << 53) as f64
    }

    /// Wherever the side from the reference's determinant alone decides, it is the library's
    /// side, at 200 random references with 50000 predictions each of turns up to 5e-4, 5e-3,
    /// 0.05 and 0.3 rad (the bound is rigorous, so none differs). Near a point, as the
    /// integrator's steps are, it decides almost always (measured with this seed: 49705, 43835,
    /// 6454 and 10 of 50000; asserted: at least 49000 and 40000 at the first two).
    #[test]
    fn side_from_reference_is_the_exact_side_where_it_decides() {
        let mut t = three_rrr();
        let mut seed = 11;
        let (mut decided, mut asked) = ([0; 4], [0; 4]);
        for _ in 0..200 {
            let mut x = [0.0; 12];
            (0..4).for_each(|b| x[3 * b + 2] = 6.0 * (uniform(&mut seed) - 0.5));
            t.set_reference(&x);
            for k in 0..1000 {
                let spread = [1e-3, 1e-2, 0.1, 0.6][k % 4];
                let mut y = x;
                (0..4).for_each(|b| y[3 * b + 2] += spread * (uniform(&mut seed) - 0.5));
                asked[k % 4] += 1;
                if let Some(s) = t.side_from_reference(t.turns(&y)) {
                    decided[k % 4] += 1;
                    assert_eq!(s, t.side(&y), "x = {x:?}, y = {y:?}");
                }
            }
        }
        assert!(decided[0] >= 49000 && decided[1] >= 40000, "decided {decided:?} of {asked:?}");
    }

    /// Wherever the side test from the series decides, it decides as the library's sin and cos
    /// do: at 200000 random predictions up to 0.6 rad from references of up to 1000 rad, and at
    /// 2000 points within 1e-13 ... 1e-3 rad of where the determinant changes sign (found by
    /// bisection), where it must defer at the nearest. It decides almost everywhere else.
    #[test]
    fn side_near_reference_is_the_exact_side_where_it_decides() {
        let mut t = three_rrr();
        let mut seed = 7;
        let (mut decided, mut asked) = (0, 0);
        for case in 0..200 {
            let mut x = [0.0; 12];
            let span = if case % 2 == 0 { 6.0 } else { 2000.0 };
            (0..4).for_each(|b| x[3 * b + 2] = span * (uniform(&mut seed) - 0.5));
            t.set_reference(&x);
            for _ in 0..1000 {
                let mut y = x;
                (0..4).for_each(|b| y[3 * b + 2] += 1.2 * (uniform(&mut seed) - 0.5));
                asked += 1;
                if let Some(s) = t.side_near_reference(&y) {
                    decided += 1;
                    assert_eq!(s, t.side(&y), "x = {x:?}, y = {y:?}");
                }
            }
        }
        // Each of the 4 turns is within 0.5 rad with probability 5/6: (5/6)^4 = 0.48.
        assert!(decided as f64 > 0.45 * asked as f64, "decided {decided} of {asked}");
        let (mut near, mut deferred) = (0, 0);
        for _ in 0..2000 {
            let mut x = [0.0; 12];
            (0..4).for_each(|b| x[3 * b + 2] = 6.0 * (uniform(&mut seed) - 0.5));
            t.set_reference(&x);
            let step: [f64; 4] = std::array::from_fn(|_| 0.4 * (uniform(&mut seed) - 0.5));
            let at = |h: f64| {
                let mut y = x;
                (0..4).for_each(|b| y[3 * b + 2] += h * step[b]);
                y
            };
            if t.side(&at(1.0)) == t.side(&x) {
                continue;
            }
            let (mut lo, mut hi) = (0.0, 1.0);
            for _ in 0..80 {
                let mid = 0.5 * (lo + hi);
                if t.side(&at(mid)) == t.side(&x) {
                    lo = mid;
                } else {
                    hi = mid;
                }
            }
            for e in [1e-13, 1e-11, 1e-9, 1e-7, 1e-5, 1e-3] {
                for h in [lo - e, hi + e] {
                    let y = at(h);
                    if let Some(s) = t.side_near_reference(&y) {
                        assert_eq!(s, t.side(&y), "x = {x:?}, y = {y:?}");
                    }
                }
            }
            near += 1;
            deferred += usize::from(t.side_near_reference(&at(lo)).is_none());
        }
        assert!(near > 100 && deferred == near, "{deferred} of {near} crossings deferred");
    }
}
