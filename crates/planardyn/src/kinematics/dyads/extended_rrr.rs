//! The RRR dyad with a link of two bodies a relative prismatic input locks together (the
//! hydraulic boom: barrel and rod, `extension`): the dyad of `rrr` with that link's arm taken
//! at each evaluation's input, P's velocity relative to the link (the rod's sliding) in its
//! rate equations and its Coriolis term in the accelerations, then the follower placed on its
//! base.

use super::extension::Arm;
use super::rrr::{self, Rrr};
use crate::kinematics::group_sigma::Block;
use crate::KinematicsError;

#[derive(Debug, Clone)]
pub struct ExtendedRrr {
    rrr: Rrr,
    branch: rrr::Branch,
    geometry: rrr::Geometry,
    /// Per dyad body, its relative input if its link is two bodies.
    extended: [Option<Arm>; 2],
    /// The dyad's bodies (the bases of two-body links), then the followers.
    pub members: Vec<usize>,
}

impl ExtendedRrr {
    /// The dyad `rrr` of the bases, with the links `extended`.
    pub fn new(rrr: Rrr, extended: [Option<Arm>; 2]) -> Self {
        let members = rrr.bodies.iter().copied().chain(extended.iter().flatten().map(|a| a.ext.follower)).collect();
        ExtendedRrr { rrr, branch: Default::default(), geometry: Default::default(), extended, members }
    }

    fn set_arms(&mut self, d: impl Fn(&Arm) -> f64) {
        let arms = [0, 1].map(|i| self.extended[i].as_ref().map_or(self.rrr.arms[i], |a| a.arm(d(a))));
        self.rrr.set_arms(arms);
    }

    /// P's velocities relative to the bodies for the extensions' rates d'(link).
    fn slides(&self, d: impl Fn(&Arm) -> f64) -> [[f64; 2]; 2] {
        self.extended.each_ref().map(|a| a.as_ref().map_or([0.0; 2], |a| a.slide(d(a))))
    }

    /// Take the branch of the configuration x (a solution).
    pub fn set_reference(&mut self, x: &[f64]) {
        self.set_arms(|a| a.ext.shift_in(x));
        self.branch = self.rrr.branch(x);
    }

    /// Take the branch and arms of `from`, the same dyad in another copy of the closed forms
    /// (the arms are the dyad's only state that `set_reference` moves besides the branch).
    pub fn copy_reference(&mut self, from: &ExtendedRrr) {
        (self.rrr.arms, self.rrr.arms2, self.rrr.bend) = (from.rrr.arms, from.rrr.arms2, from.rrr.bend);
        self.branch = from.branch;
    }

    /// [`Rrr::keeps_side`] with the arms of the last positions: a guide off the arm's line
    /// turns the arm in its frame as the input moves, which shifts the guard's threshold by
    /// that turn over one step (nothing when the guide is along the arm, as in the shipped
    /// cylinders).
    pub fn keeps_side(&self, x: &[f64]) -> bool {
        self.rrr.keeps_side(&self.branch, x)
    }

    /// The bodies' poses at the coordinates z.
    #[inline(never)]
    pub fn position(&mut self, z: &[f64], x: &mut [f64], trig: &mut [[f64; 2]]) -> Result<(), KinematicsError> {
        self.set_arms(|a| a.ext.shift(z));
        self.rrr.position(&self.branch, &mut self.geometry, x, trig)?;
        for a in self.extended.iter_mut().flatten() {
            a.ext.place(z, x, trig);
        }
        Ok(())
    }

    /// The bodies' rates for the coordinate rates zd.
    #[inline(never)]
    pub fn velocity(&self, zd: &[f64], v: &mut [f64]) {
        self.rrr.velocity(&self.geometry, self.slides(|a| a.ext.input_rate(zd)), v);
        for a in self.extended.iter().flatten() {
            a.ext.velocity(zd, v);
        }
    }

    /// The bodies' accelerations at zero coordinate accelerations, from the rates v.
    #[inline(never)]
    pub fn acceleration(&self, v: &[f64], a: &mut [f64]) {
        self.rrr.acceleration(&self.geometry, self.slides(|x| x.ext.rate(v)), v, a);
        for x in self.extended.iter().flatten() {
            x.ext.acceleration(v, a);
        }
    }

    /// The type II measure (`group_sigma`): the SVD of the block of the dyad's three pairs
    /// (P on the follower of a two-body link) and of each relative input's rows.
    pub fn sigma(&self, inv_length: f64) -> f64 {
        let g = &self.geometry;
        let mut block = Block::new(self.members.len(), inv_length);
        let mut follower = 2;
        let mut inner = [(0, 0.0, [0.0; 2]); 2];
        for (i, x) in self.extended.iter().enumerate() {
            block.point_rows(&[(i, 1.0, g.own[i])]);
            let p = [g.own[i][0] + g.e[i][0], g.own[i][1] + g.e[i][1]];
            let sign = if i == 0 { 1.0 } else { -1.0 };
            inner[i] = (i, sign, p);
            if let Some(x) = x {
                inner[i] = (follower, sign, x.on_follower(p));
                x.ext.block_rows(i, follower, &mut block);
                follower += 1;
            }
        }
        block.point_rows(&inner);
        block.sigma()
    }
}
