//! Quantities along a computed trajectory, each row on its own branch (the row's body
//! coordinates x, as a run records them): the body accelerations, the pair reactions and the
//! motion of the named points. A row is one forward evaluation under the efforts the run
//! applied (its `tau`), so the accelerations are the run's.

use super::workspace::Workspace;
use super::{forward, reactions, type_ii_measure, Drives};
use crate::kinematics::assemble_from;
use crate::kinematics::constraints::{point_acceleration, point_velocity, world_point};
use crate::model::{Attachment, Mechanism, PointId};
use crate::{Error, KinematicsError};

/// Efforts given as numbers (N m or N per coordinate), whatever t, q and qd: a recorded
/// row's, or a caller's.
pub struct FixedDrives<T: AsRef<[f64]>>(pub T);

impl<T: AsRef<[f64]>> Drives for FixedDrives<T> {
    fn efforts(&mut self, _t: f64, _q: &[f64], _qd: &[f64], tau: &mut [f64]) -> Result<(), String> {
        tau.copy_from_slice(self.0.as_ref());
        Ok(())
    }
    fn time_only(&self) -> bool {
        true
    }
}

/// The rows of a trajectory, time-major: N rows of t, x (3n), q, qd, tau (m).
#[derive(Debug, Clone, Copy)]
pub struct Rows<'a> {
    pub t: &'a [f64],
    pub x: &'a [f64],
    pub q: &'a [f64],
    pub qd: &'a [f64],
    pub tau: &'a [f64],
}

/// Body accelerations and pair reactions at every row.
#[derive(Debug, Clone, PartialEq)]
pub struct Along {
    /// N x 3n body accelerations [Xdd, Ydd, phidd] (m/s^2, rad/s^2).
    pub xdd: Vec<f64>,
    /// N x p x 3: per pair [F_x, F_y, M] (N, N m) that its first body exerts on its second
    /// (as [`reactions`]).
    pub reactions: Vec<f64>,
}

impl Rows<'_> {
    fn check(&self, mech: &Mechanism) -> Result<usize, KinematicsError> {
        let (m, nx, n) = (mech.dof(), mech.n_x(), self.t.len());
        let sizes = [(self.x.len(), nx), (self.q.len(), m), (self.qd.len(), m), (self.tau.len(), m)];
        if sizes.iter().any(|&(len, per)| len != n * per) {
            return Err(KinematicsError::bad_argument(
                "t, x, q, qd, tau",
                format!("{n} rows (one per t) of {nx} body coordinates, and of {m} values for q, qd, tau"),
                format!("{}, {}, {}, {} values", self.x.len(), self.q.len(), self.qd.len(), self.tau.len()),
            ));
        }
        Ok(n)
    }
}

/// Accelerations and reactions along `rows`. A row whose type II measure is below
/// [`super::SINGULAR_SIGMA`] is refused (`Singular`) unless `allow_singular`; the error of a
/// row says which (`Error::Row`).
pub fn along(mech: &Mechanism, rows: Rows<'_>, allow_singular: bool) -> Result<Along, Error> {
    let n = rows.check(mech)?;
    let (m, nx) = (mech.dof(), mech.n_x());
    let mut ws = Workspace::new(mech);
    let mut out = Along { xdd: Vec::with_capacity(n * nx), reactions: Vec::with_capacity(n * mech.pairs.len() * 3) };
    for k in 0..n {
        let (q, qd, tau) = (&rows.q[k * m..(k + 1) * m], &rows.qd[k * m..(k + 1) * m], &rows.tau[k * m..(k + 1) * m]);
        let row = |ws: &mut Workspace| -> Result<(), Error> {
            assemble_from(mech, &rows.x[k * nx..(k + 1) * nx], q, ws)?;
            forward(mech, rows.t[k], q, qd, &mut FixedDrives(tau), ws)?;
            type_ii_measure(mech, ws, allow_singular)?;
            Ok(())
        };
        row(&mut ws).map_err(|e| Error::Row { row: k, t: rows.t[k], source: Box::new(e) })?;
        out.xdd.extend_from_slice(&ws.xdd);
        out.reactions.extend(reactions(mech, &mut ws).into_iter().flatten());
    }
    super::finite("reactions", &out.reactions)?;
    Ok(out)
}

/// The named points some link carries (declared but unused ones are left out), with
/// where: the points [`point_motion`] reports, in the order of [`Mechanism::point_names`].
pub fn carried_points(mech: &Mechanism) -> Vec<(PointId, Attachment)> {
    (0..mech.points.len()).filter_map(|p| mech.carrier(PointId(p)).map(|a| (PointId(p), a))).collect()
}

/// Positions, velocities and accelerations (each N x P x 2, m, m/s, m/s^2) of the
/// [`carried_points`] for rows of body coordinates x, rates xd and accelerations xdd
/// (N x 3n each).
pub fn point_motion(mech: &Mechanism, x: &[f64], xd: &[f64], xdd: &[f64]) -> [Vec<f64>; 3] {
    let nx = mech.n_x();
    let at = carried_points(mech);
    let rows = x.len() / nx.max(1);
    let mut out: [Vec<f64>; 3] = std::array::from_fn(|_| Vec::with_capacity(rows * at.len() * 2));
    for ((x, xd), xdd) in x.chunks_exact(nx).zip(xd.chunks_exact(nx)).zip(xdd.chunks_exact(nx)) {
        for (_, a) in &at {
            out[0].extend(world_point(a.link, a.s, x));
            out[1].extend(point_velocity(a.link, a.s, x, xd));
            out[2].extend(point_acceleration(a.link, a.s, x, xd, xdd));
        }
    }
    out
}
