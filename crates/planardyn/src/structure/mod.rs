//! Structural analysis: the one place where the rank of the pair constraints, the mobility,
//! the redundant constraints (self-stresses), the loops and the Assur groups are computed.
//!
//! Notation: n mobile bodies (the ground not counted), p pairs with r pair-constraint rows in
//! all (`Mechanism::n_pair_rows`), m generalized coordinates, Phi_x the r x 3n Jacobian of
//! the pair constraints, scaled as the solver's J.
//!
//! - **Mobility** two ways: Chebyshev-Grubler-Kutzbach 3n - r counts the constraints;
//!   3n - rank(Phi_x) at a configuration counts the independent ones. They differ by the
//!   redundant constraints r - rank, whose pairs carry a self-stress (a lambda != 0 with
//!   Phi_x^T lambda = 0: reactions in equilibrium without any load, so not unique).
//! - **Loops**: the independent cycles of the body-pair graph, p - (n + 1) + 1 for a
//!   connected mechanism.
//! - **Assur groups**: the blocks of the block-triangular form of the position Jacobian with
//!   the inputs locked, see [`AssurGroup`].

pub use crate::kinematics::rank::{
    pair_constraint_jacobian, scaled_constraint_jacobian, Rank, SelfStress, RANK_TOL, SELF_STRESS_TOL,
};
pub use crate::topology::{AssurGroup, Loop};

use crate::kinematics::rank::constraint_rank;
use crate::model::{BodyId, Mechanism, PairId};
use crate::topology::{assur, loops};
use crate::KinematicsError;

/// The structural analysis of a mechanism at a configuration.
#[derive(Debug, Clone, PartialEq)]
pub struct Structure {
    /// Body names (n) and pair names (p), in id order.
    pub bodies: Vec<String>,
    pub pairs: Vec<String>,
    /// Number of pair-constraint rows r (redundant ones included).
    pub n_pair_rows: usize,
    /// Chebyshev-Grubler-Kutzbach mobility 3n - r.
    pub grubler: i64,
    /// Numerical rank of the scaled Phi_x (r x 3n) at the configuration, its min(r, 3n)
    /// singular values (dimensionless, ascending) and a maximal set of independent rows
    /// (indices into 0..r, ascending).
    pub rank: usize,
    pub singular_values: Vec<f64>,
    pub independent_rows: Vec<usize>,
    /// 3n - rank: the mobility the constraints leave at the configuration.
    pub mobility: usize,
    /// r - rank redundant constraints, and a basis of the self-stresses (one per redundant
    /// constraint), each naming the pairs it involves.
    pub redundant: usize,
    pub self_stresses: Vec<SelfStress>,
    /// Degree of actuation: the number of actuators, the m generalized coordinates (inputs)
    /// and the redundant actuators on other pairs. The mechanism is fully actuated when it
    /// equals `mobility`, redundantly actuated beyond.
    pub actuation: usize,
    /// A basis of the independent loops (pairs outside a breadth-first spanning forest of
    /// the body-pair graph close one each), and whether every link reaches the ground.
    pub loops: Vec<Loop>,
    pub connected: bool,
    /// Links driven from the ground (locked to it), and the input pairs between two bodies
    /// (which lock them into one rigid link), in pair order.
    pub input_links: Vec<BodyId>,
    pub relative_inputs: Vec<PairId>,
    /// The Assur groups of the mechanism with its inputs locked, in an order they can be
    /// solved in (of two that could come next, the one of fewer links first).
    pub groups: Vec<AssurGroup>,
    /// Links that no zero-mobility group takes (over- or under-constrained parts), and
    /// 3k - (rows of the pairs that touch them) for those k links: < 0 over-constrained
    /// (redundant), > 0 free to move, 0 when none is left.
    pub left_over: Vec<Vec<BodyId>>,
    pub left_over_mobility: i64,
}

impl Structure {
    /// Number of independent loops.
    pub fn n_loops(&self) -> usize {
        self.loops.len()
    }
    /// Whether the inputs drive every freedom the constraints leave.
    pub fn fully_actuated(&self) -> bool {
        self.actuation == self.mobility
    }
    /// Whether it has more actuators than freedoms (internal forces: preload is possible).
    pub fn redundantly_actuated(&self) -> bool {
        self.actuation > self.mobility
    }
    /// The name of a link of a group: its bodies' names joined by `+`.
    pub fn link_name(&self, link: &[BodyId]) -> String {
        link.iter().map(|b| self.bodies[b.0].as_str()).collect::<Vec<_>>().join("+")
    }
}

/// The structural analysis of `mech` at body coordinates x (3n values: X, Y in m and phi in
/// rad per body; the drawing is `mech.x0`). The rank and the self-stresses are those of x;
/// the loops and the Assur groups depend on the topology alone.
pub fn analyse(mech: &Mechanism, x: &[f64]) -> Result<Structure, KinematicsError> {
    if x.len() != mech.n_x() || x.iter().any(|v| !v.is_finite()) {
        return Err(KinematicsError::bad_argument(
            "x",
            format!("{} finite values (X, Y, phi per body)", mech.n_x()),
            format!("{} values{}", x.len(), if x.len() == mech.n_x() { ", some not finite" } else { "" }),
        ));
    }
    Ok(structure(mech, x))
}

/// The analysis at a finite x of the right length.
pub(crate) fn structure(mech: &Mechanism, x: &[f64]) -> Structure {
    let (n, rows) = (mech.n_bodies(), mech.n_pair_rows());
    let Rank { rank, singular_values, independent_rows, self_stresses } = constraint_rank(mech, x);
    let (loops, connected) = loops::loops(mech);
    let a = assur::assur(mech);
    Structure {
        bodies: mech.body_names().into_iter().map(String::from).collect(),
        pairs: mech.pair_names().into_iter().map(String::from).collect(),
        n_pair_rows: rows,
        grubler: 3 * n as i64 - rows as i64,
        rank,
        singular_values,
        independent_rows,
        mobility: 3 * n - rank,
        redundant: rows - rank,
        self_stresses,
        actuation: mech.n_actuators(),
        loops,
        connected,
        input_links: a.input_links,
        relative_inputs: a.relative_inputs,
        groups: a.groups,
        left_over: a.left_over,
        left_over_mobility: a.left_over_mobility,
    }
}
