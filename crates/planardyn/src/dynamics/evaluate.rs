//! Everything a view of the mechanism shows at one state (q, qd, qdd), in one call: the body
//! motion, the drive efforts that make it, the pair reactions under those efforts, the
//! singularity measures and the energies. The entry point of an interactive view (the browser
//! app draws a frame from one [`evaluate`]), so that a binding converts and does not assemble
//! the pipeline itself. And the rows of a singularity map over two coordinates, for a view
//! that redraws it as the design changes ([`sigma_rows`], [`map_rows`]: which branch a map shows).

use super::query::assembled;
use super::{forward, inverse, kinetic_energy, motor_torques, potential_energy, reactions, FixedDrives, Workspace};
use crate::kinematics::{assemble_from, passive_sigma_min, sigma_min, sigma_min_with, BranchPath, Chart, ClosedForm};
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

/// Rows of a map over two coordinates, as a design view draws it while a dimension changes:
/// cell (j, i) is the mechanism at q with `q[k[0]] = axes[0][i]` and `q[k[1]] = axes[1][j]`
/// (the other coordinates as in q), and its value one number of the configuration placed
/// there (the type II measure: [`sigma_rows`]; a natural frequency or a stiffness:
/// `crate::elastic::map_rows`). A view asks for a few rows a call (refining progressively),
/// passing the returned `x` as the next call's `x_start`.
///
/// Which branch a map shows (the configuration of a cell, where the coordinates admit several):
/// - where every group has a closed form without iteration (`ClosedForm::is_explicit`: a 5R,
///   a two-input robot of dyads), the branch of `x_start`: at each cell the configuration in
///   which every group keeps the assembly mode it has in `x_start` (a dyad's elbow on the same
///   side of the line through its outer joints). That is the branch continuation through
///   assembled neighbours keeps (a group's side changes only where its circles touch, at the
///   edge of the cells that assemble), and it needs no walk: each cell is placed on its own,
///   in any order, and a cell is missing (NaN) exactly where no configuration exists at all
///   (the group cannot close on any branch: its circles do not meet).
/// - where a class III triad is solved by Newton's method within the closed forms (a 3-RRR,
///   a 3-RPR), the branch of `x_start` too, each cell again on its own: the configuration
///   reached from `x_start` along the straight path in the coordinates (from those of
///   `x_start` to the cell's) without leaving its assembly modes (the triad's side of its
///   type II singularity, each dyad's elbow), in steps that cannot jump to another mode
///   ([`crate::kinematics::BranchPath`]); a cell is missing where that path is blocked: no
///   configuration on the way, or a fold of the branch (sigma -> 0) before the cell. A triad
///   has up to six assembly modes, several on one side of its singularity, and Newton's method
///   from a distant pose may converge to any of them: the path, not a test of the solution,
///   is what keeps the branch. Such a map shows the part of the branch seen from `x_start`
///   along straight lines (a region the branch reaches only around a bend is missing).
/// - otherwise (no closed form for some group), by
///   continuation: each row in `rows` (in that order) starts at column `i0` from the previous
///   row's start (from `x_start` for the first), then walks right and left from there, each
///   cell from its neighbour; a cell that does not assemble is NaN and the walk goes on from
///   the row's start. A view computes the rows from the current state's row up, then down
///   again from it.
#[derive(Debug, Clone, PartialEq)]
pub struct MapRows {
    /// The value of the rows' cells in the order given, row after row (axes[0].len() each),
    /// NaN where the mechanism does not assemble on the branch shown or has no value there.
    pub values: Vec<f64>,
    /// Body coordinates (3n) where the next rows continue: the last row's start cell (by
    /// continuation), or `x_start` itself (the branch's reference, by the closed forms and
    /// the triad's path).
    pub x: Vec<f64>,
}

/// The rows of the type II measure sigma (see [`MapRows`]), each cell's measured by the SVD of
/// J's blocks (`sigma_min_with`, the measure of [`evaluate`]). One workspace for all the cells
/// (no allocation per cell).
pub fn sigma_rows(
    mech: &Mechanism,
    q: &[f64],
    k: [usize; 2],
    axes: [&[f64]; 2],
    i0: usize,
    rows: &[usize],
    x_start: &[f64],
) -> Result<MapRows, Error> {
    let grid = MapGrid::new(mech, k, axes, i0, rows, x_start)?;
    Ok(map_rows(mech, q, &grid, |_, ws| Some(sigma_min_with(&mut ws.frame.sys, mech, &Chart::Inputs, &ws.frame.x))))
}

/// A map's grid and rows, checked (see [`MapRows`]).
#[derive(Debug, Clone, Copy)]
pub struct MapGrid<'a> {
    k: [usize; 2],
    axes: [&'a [f64]; 2],
    i0: usize,
    rows: &'a [usize],
    x_start: &'a [f64],
}

impl<'a> MapGrid<'a> {
    /// The grid over coordinates k (two different indices) with cell centres `axes` (finite),
    /// rows `rows` of axes[1] walked from column `i0` of axes[0], on the branch of `x_start`
    /// (3n finite body coordinates).
    pub fn new(
        mech: &Mechanism,
        k: [usize; 2],
        axes: [&'a [f64]; 2],
        i0: usize,
        rows: &'a [usize],
        x_start: &'a [f64],
    ) -> Result<Self, Error> {
        let m = mech.dof();
        if k[0] == k[1] || k.iter().any(|&k| k >= m) {
            let got = format!("{k:?} (the model has {m} coordinates)");
            return Err(KinematicsError::bad_argument("k", "two different coordinate indices", got).into());
        }
        let n = axes[0].len();
        if i0 >= n || rows.iter().any(|&j| j >= axes[1].len()) || axes.iter().any(|a| a.iter().any(|v| !v.is_finite()))
        {
            let got = format!("i0 {i0}, rows {rows:?} of axes of {n} and {} finite values", axes[1].len());
            return Err(KinematicsError::bad_argument("axes", "finite axes, i0 and rows within them", got).into());
        }
        if x_start.len() != mech.n_x() || x_start.iter().any(|v| !v.is_finite()) {
            let got = format!("{} values", x_start.len());
            return Err(KinematicsError::bad_argument(
                "x_start",
                format!("{} finite body coordinates", mech.n_x()),
                got,
            )
            .into());
        }
        Ok(MapGrid { k, axes, i0, rows, x_start })
    }

    /// The branch's reference (3n).
    pub fn x_start(&self) -> &'a [f64] {
        self.x_start
    }
}

/// The rows of `grid` (see [`MapRows`]): each cell placed in `ws` at its q on the branch
/// shown, then `value(q, ws)` (None: no value there, NaN).
pub fn map_rows(
    mech: &Mechanism,
    q: &[f64],
    grid: &MapGrid<'_>,
    mut value: impl FnMut(&[f64], &mut Workspace) -> Option<f64>,
) -> MapRows {
    let MapGrid { k, axes, i0, rows, x_start } = *grid;
    let n = axes[0].len();
    let mut ws = Workspace::new(mech);
    let mut q = q.to_vec();
    let mut values = vec![f64::NAN; rows.len() * n];
    if let Some(mut closed) = ClosedForm::new(mech) {
        // Each cell on its own: by the closed forms in the reference's modes, or with a triad
        // along the path from the reference (`BranchPath`).
        let mut path = (!closed.is_explicit()).then(|| BranchPath::new(mech, &mut closed, x_start));
        closed.set_reference(x_start);
        for (&j, row) in rows.iter().zip(values.chunks_exact_mut(n)) {
            q[k[1]] = axes[1][j];
            for (i, cell) in row.iter_mut().enumerate() {
                q[k[0]] = axes[0][i];
                let placed = match &mut path {
                    Some(path) => path.place(&mut closed, &q, &mut ws.frame),
                    None => closed.positions(&q, &mut ws.frame),
                };
                if placed.is_ok() {
                    *cell = value(&q, &mut ws).unwrap_or(f64::NAN);
                }
            }
        }
        return MapRows { values, x: x_start.to_vec() };
    }
    let mut cell = |q: &[f64], from: &[f64], ws: &mut Workspace| {
        assemble_from(mech, from, q, ws).ok().map(|()| value(q, ws).unwrap_or(f64::NAN))
    };
    let (mut start, mut last) = (x_start.to_vec(), x_start.to_vec());
    for (&j, row) in rows.iter().zip(values.chunks_exact_mut(n)) {
        q[k[1]] = axes[1][j];
        q[k[0]] = axes[0][i0];
        if let Some(v) = cell(&q, &start, &mut ws) {
            row[i0] = v;
            start.copy_from_slice(&ws.frame.x);
        }
        for side in [&mut (i0 + 1..n) as &mut dyn Iterator<Item = usize>, &mut (0..i0).rev()] {
            last.copy_from_slice(&start);
            for i in side {
                q[k[0]] = axes[0][i];
                match cell(&q, &last, &mut ws) {
                    Some(v) => {
                        row[i] = v;
                        last.copy_from_slice(&ws.frame.x);
                    }
                    None => last.copy_from_slice(&start),
                }
            }
        }
    }
    MapRows { values, x: start }
}
