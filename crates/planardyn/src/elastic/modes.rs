//! Vibration (docs/stiffness.md, *Natural frequencies*): the natural frequencies, mode shapes
//! and damping ratios of the compliant mechanism about a pose, and the small oscillations of a
//! passive mechanism about an equilibrium.
//!
//! Both are the generalized symmetric eigenproblem K y = omega^2 M y. M is whitened by its own
//! symmetric eigendecomposition M = V diag(mu) V^T rather than by a Cholesky factor: the
//! directions without mass (a slender link's tip node, a rotor without inertia) are then
//! found and condensed statically (Guyan: they follow the massive ones through K), which a
//! Cholesky factor of a singular M cannot do; for a positive definite M both give the same
//! eigenvalues. The damping ratios are modal, zeta_i = y_i^T D y_i / (2 omega_i) for
//! mass-normalised y_i (exact for damping proportional to K and M, first order otherwise).

use super::model::ElasticModel;
use super::stiffness::{elastic_at, elastic_model, loaded_stiffness, null_basis, Applied};
use crate::dynamics::{inverse, inverse_derivatives, mass_matrix};
use crate::kinematics::assemble_into;
use crate::model::{CoordinateKind, Mechanism};
use crate::KinematicsError;
use crate::Workspace;
use nalgebra::{DMatrix, DVector, SymmetricEigen};

/// A mass eigenvalue below this fraction of the largest is a direction without mass (the
/// lightest real part, 1e-30 kg at most, is still above it for any machine of 1e-12 .. 1e6 kg).
const MASSLESS_TOL: f64 = 1e-14;
/// Newton on a passive equilibrium stops when the correction is below this many radians
/// (or drawing lengths for a displacement): a few hundred times the rounding of an angle.
const EQUILIBRIUM_TOL: f64 = 1e-13;
const EQUILIBRIUM_ITERATIONS: usize = 200;
/// Longest descent step (rad, or drawing lengths): the continuation of the position analysis
/// follows the branch over it, and a Newton step far from the equilibrium is not trusted further.
const MAX_DESCENT_STEP: f64 = 0.2;
/// K is taken as positive definite when its lowest eigenvalue exceeds this fraction of its
/// largest entry; else shifted to that margin.
const SHIFT_TOL: f64 = 1e-8;

/// Natural modes, by increasing frequency.
#[derive(Debug, Clone, PartialEq)]
pub struct Modes {
    /// omega^2 (rad^2/s^2); negative about an unstable equilibrium.
    pub omega2: Vec<f64>,
    /// Modal damping ratios (1).
    pub damping_ratio: Vec<f64>,
    /// Mass-normalised shapes, one a mode: the body coordinates' displacement [X, Y, phi] per
    /// body (3n) for the compliant mechanism, the coordinates' (m) for small oscillations.
    pub shapes: Vec<Vec<f64>>,
}

impl Modes {
    /// Natural frequencies omega (rad/s): the root of omega^2, 0 for an unstable direction.
    pub fn omega(&self) -> Vec<f64> {
        self.omega2.iter().map(|w| w.max(0.0).sqrt()).collect()
    }
}

/// The coordinates of K y = omega^2 M y in which M is the identity: t (columns of K and M x
/// the massive directions h) with t^T M t = I, the massless directions condensed statically
/// (they follow the massive ones through K).
pub(crate) fn condensation(k: &DMatrix<f64>, m: &DMatrix<f64>) -> DMatrix<f64> {
    let me = SymmetricEigen::new((m + m.transpose()) * 0.5);
    let top = me.eigenvalues.max();
    let (heavy, light): (Vec<usize>, Vec<usize>) =
        (0..m.ncols()).partition(|&i| me.eigenvalues[i] > MASSLESS_TOL * top);
    let pick = |idx: &[usize], whiten: bool| {
        let mut t = DMatrix::zeros(m.ncols(), idx.len());
        for (j, &i) in idx.iter().enumerate() {
            let s = if whiten { 1.0 / me.eigenvalues[i].sqrt() } else { 1.0 };
            t.column_mut(j).copy_from(&(me.eigenvectors.column(i) * s));
        }
        t
    };
    let (th, tl) = (pick(&heavy, true), pick(&light, false));
    // Static condensation: the massless directions x_l = -K_ll^-1 K_lh x_h.
    let k_ll = tl.transpose() * k * &tl;
    let k_lh = tl.transpose() * k * &th;
    let eps = MASSLESS_TOL * k_ll.norm();
    let follow = match light.is_empty() {
        true => DMatrix::zeros(0, heavy.len()),
        false => -(k_ll.pseudo_inverse(eps).expect("eps >= 0") * k_lh),
    };
    &th + &tl * follow
}

/// K y = omega^2 M y with damping D, over the columns of the given matrices; the shapes in
/// those columns.
pub(crate) fn generalized(k: &DMatrix<f64>, m: &DMatrix<f64>, d: &DMatrix<f64>) -> Modes {
    let t = condensation(k, m);
    let kc = t.transpose() * k * &t;
    let dc = t.transpose() * d * &t;
    let eig = SymmetricEigen::new((&kc + kc.transpose()) * 0.5);
    let mut order: Vec<usize> = (0..t.ncols()).collect();
    order.sort_by(|&a, &b| eig.eigenvalues[a].total_cmp(&eig.eigenvalues[b]));
    let mut modes = Modes { omega2: Vec::new(), damping_ratio: Vec::new(), shapes: Vec::new() };
    for i in order {
        let y = eig.eigenvectors.column(i);
        let w2 = eig.eigenvalues[i];
        let c = (y.transpose() * &dc * y)[(0, 0)];
        modes.omega2.push(w2);
        modes.damping_ratio.push(if w2 > 0.0 { c / (2.0 * w2.sqrt()) } else { 0.0 });
        modes.shapes.push((&t * y).iter().copied().collect());
    }
    modes
}

/// The natural modes of the compliant mechanism about coordinates q (its rigid pose): with
/// each elastic drive's rotor held (`free_rotors` false: a stiff position loop) or free (a
/// torque-driven motor, its rotor inertia n^2 J a coordinate of its own, held by a constant
/// torque). With `gravity`, the pose is the equilibrium under the model's gravity (the
/// elements carry it there) and the stiffness holds its geometric term (an inverted pendulum
/// on a spring k: omega^2 = (k - m g l) / I_O); without, the elements' stiffness alone.
pub fn modes(
    mech: &Mechanism,
    q: &[f64],
    free_rotors: bool,
    gravity: bool,
    ws: &mut Workspace,
) -> Result<Modes, KinematicsError> {
    modes_of(&elastic_at(mech, q, free_rotors, ws)?, gravity)
}

/// [`modes`] about the assembled rigid pose x (3n body coordinates), not assembled again from
/// the drawing: a view's pose on the branch it shows (a 5R with the other elbow).
pub fn modes_about(mech: &Mechanism, x: &[f64], free_rotors: bool, gravity: bool) -> Result<Modes, KinematicsError> {
    modes_of(&elastic_model(mech, x, free_rotors)?, gravity)
}

/// [`modes`] of the elastic model about its pose.
pub(crate) fn modes_of(model: &ElasticModel, gravity: bool) -> Result<Modes, KinematicsError> {
    let z = model.z0.clone();
    let n = null_basis(&model.rigid_rows(&z).1, &model.col_scale);
    let k = loaded_stiffness(model, &z, Applied::gravity(gravity), &[], &n)?;
    let (m, damping) = mass_and_damping(model, &z, &n);
    let mut modes = generalized(&k, &m, &damping);
    for s in &mut modes.shapes {
        let full = &n * DVector::from_column_slice(s);
        *s = full.rows(0, model.mech.n_x()).iter().copied().collect();
    }
    Ok(modes)
}

/// The mass N^T M N and the elements' damping N^T (sum B^T D_e B) N over the basis n.
pub(crate) fn mass_and_damping(model: &ElasticModel, z: &[f64], n: &DMatrix<f64>) -> (DMatrix<f64>, DMatrix<f64>) {
    let mass = DMatrix::from_diagonal(&DVector::from_column_slice(&model.mass));
    let mut damping = DMatrix::zeros(n.ncols(), n.ncols());
    for (e, (_, b)) in model.elements.iter().zip(model.strains(z)) {
        let bn = b * n;
        damping += bn.transpose() * &e.damping * bn;
    }
    (n.transpose() * mass * n, damping)
}

/// A passive mechanism at rest at q: the efforts tau(q) = -U^T f that hold it there (gravity,
/// springs), its stiffness K = d tau/dq exact from the analogues
/// (`dynamics::inverse_derivatives`), and its viscous damping D = d tau / d qd.
struct Rest {
    tau: Vec<f64>,
    k: DMatrix<f64>,
    d: DMatrix<f64>,
}

fn at_rest(mech: &Mechanism, q: &[f64], ws: &mut Workspace) -> Result<Rest, KinematicsError> {
    let m = q.len();
    let zero = vec![0.0; m];
    let jac = inverse_derivatives(mech, q, &zero, &zero, ws)?;
    Ok(Rest {
        tau: ws.tau.clone(),
        k: DMatrix::from_row_slice(m, m, &jac.dq),
        d: DMatrix::from_row_slice(m, m, &jac.dqd),
    })
}

/// The stable equilibrium of a passive mechanism (no drives: its gravity and springs) reached
/// from `q_start` by descending its potential: Newton steps on tau(q) = 0 with the exact K,
/// shifted to K + mu I where K is not positive definite (so each step goes downhill, not to a
/// maximum or a saddle) and at most `MAX_DESCENT_STEP` long.
pub fn equilibrium(mech: &Mechanism, q_start: &[f64], ws: &mut Workspace) -> Result<Vec<f64>, KinematicsError> {
    let mut q = q_start.to_vec();
    assemble_into(mech, &q, ws)?;
    let scale: Vec<f64> =
        mech.coordinates.iter().map(|c| if c.kind == CoordinateKind::Angle { 1.0 } else { mech.scale }).collect();
    let mut last = f64::INFINITY;
    for _ in 0..EQUILIBRIUM_ITERATIONS {
        let Rest { tau, k, .. } = at_rest(mech, &q, ws)?;
        let k = (&k + k.transpose()) * 0.5;
        let lowest = SymmetricEigen::new(k.clone()).eigenvalues.min();
        let top = k.amax();
        let shift = if lowest > SHIFT_TOL * top { 0.0 } else { SHIFT_TOL * top - lowest + f64::MIN_POSITIVE };
        let shifted = &k + DMatrix::identity(q.len(), q.len()) * shift;
        let mut step =
            shifted.lu().solve(&DVector::from_column_slice(&tau)).ok_or_else(|| KinematicsError::BadArgument {
                name: "q",
                expected: "a start where gravity or a spring holds the mechanism (an isolated equilibrium)".into(),
                got: "no stiffness: the mechanism is indifferent there".into(),
            })?;
        let longest = step.iter().zip(&scale).map(|(d, s)| (d / s).abs()).fold(0.0, f64::max);
        if longest > MAX_DESCENT_STEP {
            step *= MAX_DESCENT_STEP / longest;
        }
        q.iter_mut().zip(step.iter()).for_each(|(q, d)| *q -= d);
        last = longest;
        if shift == 0.0 && last <= EQUILIBRIUM_TOL {
            inverse(mech, &q, &vec![0.0; q.len()], &vec![0.0; q.len()], ws)?;
            return Ok(q);
        }
    }
    Err(KinematicsError::AssemblyFailed { residual: last, iterations: EQUILIBRIUM_ITERATIONS })
}

/// The small oscillations of a passive mechanism about q (an equilibrium: see [`equilibrium`]):
/// K y = omega^2 A y, K = d tau/dq, A = U^T M U, damping d tau/d qd. Shapes in the coordinates.
pub fn small_oscillations(mech: &Mechanism, q: &[f64], ws: &mut Workspace) -> Result<Modes, KinematicsError> {
    assemble_into(mech, q, ws)?;
    let Rest { k, d, .. } = at_rest(mech, q, ws)?;
    mass_matrix(mech, ws);
    let m = q.len();
    let a = DMatrix::from_row_slice(m, m, &ws.a);
    Ok(generalized(&((&k + k.transpose()) * 0.5), &a, &d))
}
