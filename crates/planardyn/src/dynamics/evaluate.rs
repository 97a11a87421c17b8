//! Everything a view of the mechanism shows at one state (q, qd, qdd), in one call: the body
//! motion, the drive efforts that make it, the pair reactions under those efforts, the
//! singularity measures and the energies. The entry point of an interactive view (the browser
//! app draws a frame from one [`evaluate`]), so that a binding converts and does not assemble
//! the pipeline itself. And the rows of a singularity map over two coordinates, for a view
//! that redraws it as the design changes ([`sigma_rows`]).

use super::query::assembled;
use super::{forward, inverse, kinetic_energy, motor_torques, potential_energy, reactions, FixedDrives};
use crate::kinematics::{assemble_from, passive_sigma_min, sigma_min, sigma_min_with, Chart, ClosedForm, Frame};
use crate::model::Mechanism;
use crate::{Error, KinematicsError};

/// One state's quantities; shapes with n bodies, m coordinates, p pairs.
#[derive(Debug, Clone, PartialEq)]
pub struct Evaluation {
    /// Body coordinates [X, Y, phi] per body (3n; m, rad), on the branch reached.
    pub x: Vec<f64>,
    /// Body rates (3n; m/s, rad/s).
    pub xd: Vec<f64>,
    /// Body accelerations (3n; m/s^2, rad/s^2) of the forward evaluation under `tau`.
    pub xdd: Vec<f64>,
    /// Joint-side drive efforts (m; N m or N) giving the accelerations qdd (inverse dynamics).
    pub tau: Vec<f64>,
    /// Per pair, [F_x, F_y, M] that body a exerts on body b (N, N m) under `tau`.
    pub reactions: Vec<[f64; 3]>,
    /// Smallest scaled singular value of J in the input chart (type II measure; 0 at a
    /// singularity), and of the passive mechanism's constraints.
    pub sigma: f64,
    pub sigma_passive: f64,
    /// Kinetic and potential energy (J).
    pub kinetic: f64,
    pub potential: f64,
    /// Loop-closure residual of the assembly (m).
    pub residual: f64,
}

/// The quantities at coordinates q, rates qd and accelerations qdd (m each; rad or m, per s,
/// per s^2), assembled by continuation from `x_start` (3n, a neighbouring state on the wanted
/// branch) or else from the drawing. Stages: positions -> inverse dynamics (tau) -> forward
/// dynamics under tau as motor torques (so the reactions are those of this motion) ->
/// reactions -> measures and energies. Fails where the mechanism cannot be assembled or is
/// singular (type II: the forward evaluation has no unique accelerations).
pub fn evaluate(
    mech: &Mechanism,
    q: &[f64],
    qd: &[f64],
    qdd: &[f64],
    x_start: Option<&[f64]>,
) -> Result<Evaluation, Error> {
    let mut ws = assembled(mech, q, x_start)?;
    inverse(mech, q, qd, qdd, &mut ws)?;
    let tau = ws.tau.clone();
    let mut motor = vec![0.0; tau.len()];
    motor_torques(mech, &ws, &tau, &mut motor);
    forward(mech, 0.0, q, qd, &mut FixedDrives(motor), &mut ws)?;
    let reactions = reactions(mech, &mut ws);
    super::finite("reactions", reactions.as_flattened())?;
    let [kinetic, potential] =
        super::finite("energies", [kinetic_energy(mech, &ws.xd), potential_energy(mech, &ws.x)])?;
    Ok(Evaluation {
        sigma: sigma_min(mech, &Chart::Inputs, &ws.x),
        sigma_passive: passive_sigma_min(mech, &ws.x),
        residual: ws.residual,
        x: ws.frame.x,
        xd: ws.frame.xd,
        xdd: ws.xdd,
        tau,
        reactions,
        kinetic,
        potential,
    })
}

/// Rows of a map of the type II measure over two coordinates, as a design view draws it while
/// a dimension changes: cell (j, i) is the mechanism at q with `q[k[0]] = axes[0][i]` and
/// `q[k[1]] = axes[1][j]` (the other coordinates as in q). The map follows one branch by
/// continuation from the current state outwards: each row in `rows` (in that order) starts at
/// column `i0` from the previous row's start (from `x_start`, 3n, for the first), then walks
/// right and left from there, each cell from its neighbour; a cell that does not assemble is
/// NaN and the walk goes on from the row's start. A view computes the rows from the current
/// state's row up, then down again from it, a few at a time (refining progressively), passing
/// the returned `x` as the next call's `x_start`.
pub struct SigmaRows {
    /// sigma of the rows in the order given, row after row (axes[0].len() each), NaN where the
    /// mechanism does not assemble on the branch followed.
    pub sigma: Vec<f64>,
    /// Body coordinates (3n) of the last row's start cell: where the next rows continue.
    pub x: Vec<f64>,
}

/// See [`SigmaRows`]. One kinematic frame for all the cells (no allocation per cell).
///
/// Where every group of the mechanism has a closed form without iteration
/// (`ClosedForm::is_explicit`: a 5R, a two-input robot of dyads), a cell whose neighbour
/// assembled is placed by the closed forms on the neighbour's branches instead of by Newton continuation from it (the same solution: continuation keeps
/// the branch of its start over the step). A row's cells beyond a gap are then not tried:
/// the closed forms fail where a group cannot close on any branch, and the continuation from
/// the row's start passes through that cell. A cell continued from another row's start, or
/// the first from `x_start`, is continued as before.
pub fn sigma_rows(
    mech: &Mechanism,
    q: &[f64],
    k: [usize; 2],
    axes: [&[f64]; 2],
    i0: usize,
    rows: &[usize],
    x_start: &[f64],
) -> Result<SigmaRows, Error> {
    let m = mech.dof();
    if k[0] == k[1] || k.iter().any(|&k| k >= m) {
        let got = format!("{k:?} (the model has {m} coordinates)");
        return Err(KinematicsError::bad_argument("k", "two different coordinate indices", got).into());
    }
    let n = axes[0].len();
    if i0 >= n || rows.iter().any(|&j| j >= axes[1].len()) || axes.iter().any(|a| a.iter().any(|v| !v.is_finite())) {
        let got = format!("i0 {i0}, rows {rows:?} of axes of {n} and {} finite values", axes[1].len());
        return Err(KinematicsError::bad_argument("axes", "finite axes, i0 and rows within them", got).into());
    }
    if x_start.len() != mech.n_x() || x_start.iter().any(|v| !v.is_finite()) {
        let got = format!("{} values", x_start.len());
        return Err(
            KinematicsError::bad_argument("x_start", format!("{} finite body coordinates", mech.n_x()), got).into()
        );
    }
    let closed = ClosedForm::new(mech).filter(ClosedForm::is_explicit);
    let mut cells = Cells { mech, frame: Frame::new(mech), closed };
    let mut q = q.to_vec();
    let (mut start, mut sigma) = (x_start.to_vec(), vec![f64::NAN; rows.len() * n]);
    let mut last = start.clone();
    // Whether `start` is the previous row's start cell (a neighbour) rather than `x_start`.
    let mut start_adjacent = false;
    for (&j, row) in rows.iter().zip(sigma.chunks_exact_mut(n)) {
        q[k[1]] = axes[1][j];
        q[k[0]] = axes[0][i0];
        match cells.sigma(&q, &start, start_adjacent) {
            Some(s) => {
                row[i0] = s;
                start.copy_from_slice(&cells.frame.x);
                start_adjacent = true;
            }
            None => start_adjacent = false,
        }
        // Whether `start` is this row's own start cell: a cell beyond a gap then continues from
        // it along the row, through the gap's cell.
        let own_start = row[i0].is_finite();
        for side in [&mut (i0 + 1..n) as &mut dyn Iterator<Item = usize>, &mut (0..i0).rev()] {
            last.copy_from_slice(&start);
            let mut adjacent = start_adjacent;
            for i in side {
                q[k[0]] = axes[0][i];
                if !adjacent && own_start && cells.closed.is_some() {
                    // The closed forms fail where a group cannot close on any branch (a dyad's
                    // circles do not meet), so the continuation from the row's start, whose
                    // path along the row passes through that cell, cannot reach this one.
                    break;
                }
                match cells.sigma(&q, &last, adjacent) {
                    Some(s) => {
                        row[i] = s;
                        last.copy_from_slice(&cells.frame.x);
                        adjacent = true;
                    }
                    None => {
                        last.copy_from_slice(&start);
                        adjacent = false;
                    }
                }
            }
        }
    }
    Ok(SigmaRows { sigma, x: start })
}

/// The map's cells, assembled in one frame.
struct Cells<'a> {
    mech: &'a Mechanism,
    frame: Frame,
    closed: Option<ClosedForm>,
}

impl Cells<'_> {
    /// The type II measure at q, the configuration left in `frame.x`: by the closed forms on
    /// the branches of `from` where it is the neighbouring cell's solution (`adjacent`) and the
    /// mechanism has them, else by continuation from `from`. None where it does not assemble.
    fn sigma(&mut self, q: &[f64], from: &[f64], adjacent: bool) -> Option<f64> {
        let (mech, frame) = (self.mech, &mut self.frame);
        let placed = match self.closed.as_mut().filter(|_| adjacent) {
            Some(closed) => {
                closed.set_reference(from);
                closed.positions(q, frame)
            }
            None => assemble_from(mech, from, q, frame),
        };
        placed.ok().map(|()| sigma_min_with(&mut frame.sys, mech, &Chart::Inputs, &frame.x))
    }
}
