//! Elastostatics at a pose (docs/stiffness.md): the Cartesian compliance and stiffness of a
//! body's point, with the geometric (load-dependent) term of a wrench W, of the model's own
//! gravity and of a preload of elastic drives, the weakest direction, and the deflection under
//! W and gravity, linear and non-linear by continuation in the load.
//!
//! With the rigid rows' gradient R (their null space N: the free motions of the compliant
//! mechanism), the elements' gradients B_e, forces sigma_e and the rigid rows' multipliers
//! lambda in equilibrium, B^T sigma - R^T lambda = F = S^T W + f_g (S = dp/dz; f_g = m g on
//! each body's centre of mass, linear in z), the tangent stiffness in the free motions is
//!
//!   H_N = N^T (sum_e B_e^T K_e B_e + sum_r sigma_r d2delta_r - sum_r lambda_r d2g_r - W . d2p) N,
//!
//! and the compliance of p is C = S N H_N^-1 N^T S^T (3 x 3; of rank the number of free
//! motions). Without pair or link compliance and with every actuator elastic, N spans the
//! velocity analogues U and C = S U K_q^-1 U^T S^T: Gosselin's J^-1 K_a^-1 J^-T.

use super::model::{ElasticModel, Output};
use crate::kinematics::assemble_into;
use crate::model::Mechanism;
use crate::KinematicsError;
use crate::Workspace;
use nalgebra::{Cholesky, DMatrix, DVector, Dyn, SymmetricEigen};

/// A singular value of the scaled rigid rows below this fraction of the largest is taken as
/// zero: a free motion of the compliant mechanism (rounding leaves ~1e-15 on the exact ones;
/// a mechanism within 1e-10 of losing a constraint is at a singularity anyway).
const NULL_TOL: f64 = 1e-10;
/// A compliance eigenvalue below this fraction of the largest counts as zero (the output
/// moves in fewer than three directions), in the scaled units of `weakest_direction`.
const RANK_TOL: f64 = 1e-12;
/// Newton on the loaded equilibrium stops when the correction is below this many drawing
/// lengths (a few hundred times the rounding of the coordinates).
const NEWTON_TOL: f64 = 1e-13;
const NEWTON_ITERATIONS: usize = 30;
/// Singular values of the equilibrium and KKT matrices below this fraction of the largest are
/// a self-stress or a redundant row (zero but for rounding, ~1e-16 of the largest), whose share
/// the minimum-norm solution leaves at zero.
const LSQ_TOL: f64 = 1e-12;

/// The minimum-norm least-squares solution of a x = b.
fn lstsq(a: DMatrix<f64>, b: &DVector<f64>) -> Result<DVector<f64>, &'static str> {
    let svd = a.svd(true, true);
    let eps = LSQ_TOL * svd.singular_values.max();
    svd.solve(b, eps)
}

/// A load on the output: the wrench W = [F_x, F_y, M] (N, N, N m) at the output point,
/// preload efforts (N m or N) of elastic drives by actuator index, and the model's own gravity
/// on the bodies' centres of mass when `gravity` is set.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Load {
    pub wrench: [f64; 3],
    pub preload: Vec<(usize, f64)>,
    pub gravity: bool,
}

impl Load {
    /// A load as a user writes it: the wrench [F_x, F_y, M] (N, N, N m; finite) and the
    /// preloads by actuator name (N m or N; each a known actuator, finite). One check for
    /// every binding.
    pub fn named(
        mech: &Mechanism,
        wrench: [f64; 3],
        preload: impl IntoIterator<Item = (String, f64)>,
        gravity: bool,
    ) -> Result<Load, KinematicsError> {
        if wrench.iter().any(|v| !v.is_finite()) {
            return Err(KinematicsError::bad_argument(
                "wrench",
                "[F_x, F_y, M], finite (N, N, N m)",
                format!("{wrench:?}"),
            ));
        }
        let names = mech.actuator_names();
        let mut load = Load { wrench, preload: Vec::new(), gravity };
        for (name, tau) in preload {
            let Some(k) = names.iter().position(|n| *n == name) else {
                let expected = format!("an actuator of the model ({})", names.join(", "));
                return Err(KinematicsError::bad_argument("preload", expected, format!("unknown actuator '{name}'")));
            };
            if !tau.is_finite() {
                let got = format!("preload['{name}'] = {tau}");
                return Err(KinematicsError::bad_argument("preload", "finite preloads (N m or N)", got));
            }
            load.preload.push((k, tau));
        }
        Ok(load)
    }
}

/// The applied loads of a load step: a wrench on an output (None: none) and the model's
/// gravity times `gravity` (0 none, 1 all of it).
#[derive(Debug, Clone, Copy)]
pub(crate) struct Applied {
    wrench: Option<(Output, [f64; 3])>,
    gravity: f64,
}

impl Applied {
    fn of(out: Output, load: &Load) -> Self {
        Applied { wrench: Some((out, load.wrench)), gravity: if load.gravity { 1.0 } else { 0.0 } }
    }

    /// The model's gravity alone (`on`), or nothing.
    pub fn gravity(on: bool) -> Self {
        Applied { wrench: None, gravity: if on { 1.0 } else { 0.0 } }
    }

    fn scaled(self, t: f64) -> Self {
        Applied { wrench: self.wrench.map(|(o, w)| (o, w.map(|v| v * t))), gravity: self.gravity * t }
    }

    /// The generalized force F = S^T W + gravity f_g on z.
    fn force(&self, model: &ElasticModel, z: &[f64]) -> DVector<f64> {
        let mut f = model.gravity_force() * self.gravity;
        if let Some((out, w)) = self.wrench {
            f += model.output(out, z).1.transpose() * DVector::from_column_slice(&w);
        }
        f
    }

    /// W . d2p/dz2 over the basis: the wrench's own geometric term (gravity has none, being
    /// linear in z).
    fn curvature(&self, model: &ElasticModel, z: &[f64], basis: &DMatrix<f64>) -> DMatrix<f64> {
        match self.wrench {
            Some((out, w)) => model.output_curvature(out, z, &w, basis),
            None => DMatrix::zeros(basis.ncols(), basis.ncols()),
        }
    }
}

/// The Cartesian compliance and stiffness of an output p = [x, y, phi] (m, m, rad).
#[derive(Debug, Clone, PartialEq)]
pub struct CartesianStiffness {
    pub pose: [f64; 3],
    /// C (m/N, m/(N m), rad/N, rad/(N m)).
    pub compliance: [[f64; 3]; 3],
    /// K = C^-1 where the output moves in three directions.
    pub stiffness: Option<[[f64; 3]; 3]>,
    /// The translational block's stiffness, C_tt^-1 (N/m): force without moment, the angle free.
    pub translational: Option<[[f64; 2]; 2]>,
    /// The number of free motions of the compliant mechanism.
    pub freedoms: usize,
}

/// The direction [d_x, d_y, d_phi] (unit in the scaled units) in which the output gives most
/// and its stiffness 1/c_max (N/m).
#[derive(Debug, Clone, PartialEq)]
pub struct Weakest {
    pub direction: [f64; 3],
    pub stiffness: f64,
}

/// The deflection of the output under a load.
#[derive(Debug, Clone, PartialEq)]
pub struct Deflection {
    /// C0 W with the unloaded compliance (m, m, rad).
    pub linear: [f64; 3],
    /// p(W) - p(0) from the non-linear equilibrium, reached in `steps` load increments.
    pub nonlinear: [f64; 3],
    /// The tangent compliance at the loaded equilibrium.
    pub tangent: CartesianStiffness,
    /// The body coordinates [X, Y, phi] per body at the loaded equilibrium.
    pub x: Vec<f64>,
}

fn no_compliance() -> KinematicsError {
    KinematicsError::BadArgument {
        name: "mechanism",
        expected: "a model with a `compliance:` section (drives, pairs or links; docs/stiffness.md)".into(),
        got: "a rigid model".into(),
    }
}

/// The assembled body coordinates at q (rigid), and the elastic model about them.
pub(crate) fn elastic_at<'m>(
    mech: &'m Mechanism,
    q: &[f64],
    free_rotors: bool,
    ws: &mut Workspace,
) -> Result<ElasticModel<'m>, KinematicsError> {
    if mech.compliance.is_empty() {
        return Err(no_compliance());
    }
    assemble_into(mech, q, ws)?;
    elastic_model(mech, &ws.x, free_rotors)
}

/// The elastic model about the rigid pose x (3n, assembled by the caller: a map's cell on its
/// branch).
pub(crate) fn elastic_model<'m>(
    mech: &'m Mechanism,
    x: &[f64],
    free_rotors: bool,
) -> Result<ElasticModel<'m>, KinematicsError> {
    if mech.compliance.is_empty() {
        return Err(no_compliance());
    }
    Ok(ElasticModel::new(mech, x, free_rotors))
}

/// A basis of the null space of the rigid rows' gradient (cols x d), from the SVD of the
/// column-scaled gradient.
pub(crate) fn null_basis(g: &DMatrix<f64>, col_scale: &[f64]) -> DMatrix<f64> {
    let nc = g.ncols();
    let scale = DMatrix::from_diagonal(&DVector::from_column_slice(col_scale));
    let mut gs = DMatrix::zeros(g.nrows().max(nc), nc);
    gs.rows_mut(0, g.nrows()).copy_from(&(g * &scale));
    let svd = gs.svd(false, true);
    let v_t = svd.v_t.expect("requested");
    let top = svd.singular_values.max();
    let free: Vec<usize> = (0..nc).filter(|&i| svd.singular_values[i] <= NULL_TOL * top).collect();
    let mut n = DMatrix::zeros(nc, free.len());
    for (j, &i) in free.iter().enumerate() {
        n.column_mut(j).copy_from(&(&scale * v_t.row(i).transpose()));
    }
    n
}

/// The elements' forces sigma (stacked by element) and the rigid rows' multipliers lambda
/// balancing the applied loads at z: B^T sigma - R^T lambda = F, the preloaded drives'
/// sigma = -tau given, each free rotor held by its motor (a constant torque, of no stiffness);
/// least squares (minimum norm) where redundant rows leave it open.
fn balance(
    model: &ElasticModel,
    z: &[f64],
    applied: Applied,
    preload: &[(usize, f64)],
) -> Result<(Vec<f64>, Vec<f64>), KinematicsError> {
    let strains = model.strains(z);
    let (_, r) = model.rigid_rows(z);
    let n_e: usize = strains.iter().map(|(v, _)| v.len()).sum();
    let rotors: Vec<usize> = model.rotors().iter().map(|&(c, _)| c).collect();
    let mut a = DMatrix::zeros(model.n_cols(), n_e + r.nrows() + rotors.len());
    let mut rhs = applied.force(model, z);
    let mut fixed = vec![None; n_e];
    let mut at = 0;
    for (e, (v, b)) in model.elements.iter().zip(&strains) {
        a.columns_mut(at, v.len()).copy_from(&b.transpose());
        if let Some(&(_, tau)) = e.actuator.and_then(|k| preload.iter().find(|(a, _)| *a == k)) {
            fixed[at] = Some(-tau);
        }
        at += v.len();
    }
    a.columns_mut(n_e, r.nrows()).copy_from(&(-r.transpose()));
    for (j, &c) in rotors.iter().enumerate() {
        a[(c, n_e + r.nrows() + j)] = 1.0;
    }
    for (j, f) in fixed.iter().enumerate() {
        if let Some(f) = f {
            rhs -= a.column(j) * *f;
            a.column_mut(j).fill(0.0);
        }
    }
    let y = lstsq(a, &rhs).map_err(|e| KinematicsError::BadArgument {
        name: "load",
        expected: "a load the compliant mechanism can balance".into(),
        got: e.into(),
    })?;
    let mut sigma: Vec<f64> = y.rows(0, n_e).iter().copied().collect();
    for (s, f) in sigma.iter_mut().zip(&fixed) {
        if let Some(f) = f {
            *s = *f;
        }
    }
    Ok((sigma, y.rows(n_e, r.nrows()).iter().copied().collect()))
}

/// sum_e B_e^T K_e B_e projected on the basis.
fn elastic_stiffness(model: &ElasticModel, z: &[f64], basis: &DMatrix<f64>) -> DMatrix<f64> {
    let mut k = DMatrix::zeros(basis.ncols(), basis.ncols());
    for (e, (_, b)) in model.elements.iter().zip(model.strains(z)) {
        let bn = b * basis;
        k += bn.transpose() * &e.stiffness * bn;
    }
    k
}

/// The tangent stiffness H_N (over `basis`) at z with forces (sigma, lambda) and the applied
/// loads.
fn tangent(
    model: &ElasticModel,
    z: &[f64],
    (sigma, lambda): (&[f64], &[f64]),
    applied: Applied,
    basis: &DMatrix<f64>,
) -> DMatrix<f64> {
    let minus_lambda: Vec<f64> = lambda.iter().map(|l| -l).collect();
    elastic_stiffness(model, z, basis) + model.curvature(z, &minus_lambda, sigma, basis)
        - applied.curvature(model, z, basis)
}

/// The tangent stiffness over `basis` at z taken as the equilibrium with the applied loads and
/// the preload (the elements and rigid rows carrying them there, `balance`).
pub(crate) fn loaded_stiffness(
    model: &ElasticModel,
    z: &[f64],
    applied: Applied,
    preload: &[(usize, f64)],
    basis: &DMatrix<f64>,
) -> Result<DMatrix<f64>, KinematicsError> {
    let (sigma, lambda) = balance(model, z, applied, preload)?;
    Ok(tangent(model, z, (&sigma, &lambda), applied, basis))
}

/// The Cholesky factor of a tangent stiffness, or the error saying the pose is not stable.
fn factor(h: DMatrix<f64>) -> Result<Cholesky<f64, Dyn>, KinematicsError> {
    h.clone().cholesky().ok_or_else(|| {
        let lowest = SymmetricEigen::new(h).eigenvalues.min();
        KinematicsError::BadArgument {
            name: "q",
            expected: "a pose where the compliant mechanism is stable (its tangent stiffness positive definite): \
                       give every actuator and loose part a stiffness, or lower the load"
                .into(),
            got: format!("a tangent stiffness with eigenvalue {lowest:.3e}"),
        }
    })
}

/// The compliance of the output from the factored tangent stiffness over the rigid rows'
/// null space n.
fn cartesian(
    model: &ElasticModel,
    z: &[f64],
    out: Output,
    chol: &Cholesky<f64, Dyn>,
    n: &DMatrix<f64>,
) -> Result<CartesianStiffness, KinematicsError> {
    let (pose, s) = model.output(out, z);
    let freedoms = n.ncols();
    let sn = &s * n;
    let c = &sn * chol.solve(&sn.transpose());
    let c = (&c + c.transpose()) * 0.5;
    let compliance = to3(&c);
    let scaled = scale_rotation(&c, model.mech.scale);
    let eig = SymmetricEigen::new(scaled.clone());
    let full_rank = eig.eigenvalues.min() > RANK_TOL * eig.eigenvalues.max();
    let stiffness = full_rank.then(|| c.clone().try_inverse().map(|k| to3(&k))).flatten();
    let ctt = c.view((0, 0), (2, 2)).into_owned();
    let e2 = SymmetricEigen::new(ctt.clone()).eigenvalues;
    let translational = (e2.min() > RANK_TOL * e2.max())
        .then(|| ctt.try_inverse().map(|k| [[k[(0, 0)], k[(0, 1)]], [k[(1, 0)], k[(1, 1)]]]))
        .flatten();
    Ok(CartesianStiffness { pose, compliance, stiffness, translational, freedoms })
}

fn to3(c: &DMatrix<f64>) -> [[f64; 3]; 3] {
    std::array::from_fn(|i| std::array::from_fn(|j| c[(i, j)]))
}

/// D C D with D = diag(1, 1, length): the displacement (x, y, length phi) under the wrench
/// (F_x, F_y, M / length), all in m/N.
fn scale_rotation(c: &DMatrix<f64>, length: f64) -> DMatrix<f64> {
    let d = DMatrix::from_diagonal(&DVector::from_column_slice(&[1.0, 1.0, length]));
    &d * c * &d
}

/// The Cartesian stiffness of `out` at coordinates q, in equilibrium with `load` at that pose
/// (the elements carry it there; its geometric term included); `ws` is left assembled at q.
pub fn stiffness(
    mech: &Mechanism,
    q: &[f64],
    out: Output,
    load: &Load,
    ws: &mut Workspace,
) -> Result<CartesianStiffness, KinematicsError> {
    stiffness_of(&elastic_at(mech, q, false, ws)?, out, load)
}

/// [`stiffness`] about the assembled rigid pose x (3n body coordinates), not assembled again
/// from the drawing: a view's pose on the branch it shows.
pub fn stiffness_about(
    mech: &Mechanism,
    x: &[f64],
    out: Output,
    load: &Load,
) -> Result<CartesianStiffness, KinematicsError> {
    stiffness_of(&elastic_model(mech, x, false)?, out, load)
}

/// [`stiffness`] of the elastic model about its pose.
pub(crate) fn stiffness_of(
    model: &ElasticModel,
    out: Output,
    load: &Load,
) -> Result<CartesianStiffness, KinematicsError> {
    check_preload(model, load)?;
    let z = model.z0.clone();
    let n = null_basis(&model.rigid_rows(&z).1, &model.col_scale);
    let h = loaded_stiffness(model, &z, Applied::of(out, load), &load.preload, &n)?;
    cartesian(model, &z, out, &factor(h)?, &n)
}

pub(crate) fn check_preload(model: &ElasticModel, load: &Load) -> Result<(), KinematicsError> {
    for &(a, _) in &load.preload {
        if !model.elements.iter().any(|e| e.actuator == Some(a)) {
            return Err(KinematicsError::BadArgument {
                name: "preload",
                expected: "efforts of actuators with a transmission spring (`compliance.drives`)".into(),
                got: format!("a preload on actuator {a}, which has none"),
            });
        }
    }
    Ok(())
}

/// The direction in which the output gives most: of the translational block (`length`
/// None), or of the whole compliance with rotations scaled by a characteristic length (m).
pub fn weakest_direction(c: &CartesianStiffness, length: Option<f64>) -> Weakest {
    let full = DMatrix::from_fn(3, 3, |i, j| c.compliance[i][j]);
    let (m, dims) = match length {
        Some(l) => (scale_rotation(&full, l), 3),
        None => (full.view((0, 0), (2, 2)).into_owned(), 2),
    };
    let eig = SymmetricEigen::new(m);
    let i = eig.eigenvalues.imax();
    let mut direction = [0.0; 3];
    for (k, d) in direction.iter_mut().take(dims).enumerate() {
        *d = eig.eigenvectors[(k, i)];
    }
    Weakest { direction, stiffness: 1.0 / eig.eigenvalues[i] }
}

/// The deflection of `out` under `load.wrench` and (`load.gravity`) the model's gravity, from
/// the pose q unstrained but for the preload: linear (the unloaded compliance,
/// S N H_N^-1 N^T F) and non-linear (the equilibrium followed in `steps` equal load increments
/// by Newton on the equilibrium and the rigid rows), with the tangent compliance at the loaded
/// equilibrium.
pub fn deflection(
    mech: &Mechanism,
    q: &[f64],
    out: Output,
    load: &Load,
    steps: usize,
    ws: &mut Workspace,
) -> Result<Deflection, KinematicsError> {
    let model = elastic_at(mech, q, false, ws)?;
    check_preload(&model, load)?;
    let applied = Applied::of(out, load);
    let unloaded = applied.scaled(0.0);
    let mut z = model.z0.clone();
    let (_, r) = model.rigid_rows(&z);
    let mut lambda = vec![0.0; r.nrows()];
    let sigma0 = balance(&model, &z, unloaded, &load.preload)?.0;
    equilibrium(&model, &sigma0, unloaded, &mut z, &mut lambda)?;
    let n0 = null_basis(&model.rigid_rows(&z).1, &model.col_scale);
    let sigma_at = |z: &[f64]| stresses(&model, z, &sigma0);
    let chol0 = factor(tangent(&model, &z, (&sigma_at(&z), &lambda), unloaded, &n0))?;
    let sn0 = model.output(out, &z).1 * &n0;
    let linear = &sn0 * chol0.solve(&(n0.transpose() * applied.force(&model, &z)));
    let p0 = model.output(out, &z).0;
    for step in 1..=steps.max(1) {
        let t = step as f64 / steps.max(1) as f64;
        equilibrium(&model, &sigma0, applied.scaled(t), &mut z, &mut lambda).map_err(|e| match e {
            KinematicsError::AssemblyFailed { residual, iterations } => KinematicsError::BadArgument {
                name: "load",
                expected: "a load the compliant mechanism carries (no buckling or snap-through before it): \
                           lower it or raise `steps`"
                    .into(),
                got: format!(
                    "no equilibrium at {:.0}% of it (residual {residual:.3e} after {iterations} iterations)",
                    100.0 * t
                ),
            },
            other => other,
        })?;
    }
    let n = null_basis(&model.rigid_rows(&z).1, &model.col_scale);
    let h = tangent(&model, &z, (&sigma_at(&z), &lambda), applied, &n);
    let tangent_c = cartesian(&model, &z, out, &factor(h)?, &n)?;
    let p = model.output(out, &z).0;
    Ok(Deflection {
        linear: std::array::from_fn(|i| linear[i]),
        nonlinear: std::array::from_fn(|i| p[i] - p0[i]),
        tangent: tangent_c,
        x: z[..mech.n_x()].to_vec(),
    })
}

/// The elements' forces sigma = K_e delta_e(z) + sigma0 (stacked).
fn stresses(model: &ElasticModel, z: &[f64], sigma0: &[f64]) -> Vec<f64> {
    let mut out = Vec::with_capacity(sigma0.len());
    for (e, (d, _)) in model.elements.iter().zip(model.strains(z)) {
        out.extend((&e.stiffness * d).iter());
    }
    out.iter_mut().zip(sigma0).for_each(|(s, s0)| *s += s0);
    out
}

/// Newton on grad Pi - R^T lambda = 0, g = 0 from (z, lambda), the full Hessian of the
/// Lagrangian over all columns.
fn equilibrium(
    model: &ElasticModel,
    sigma0: &[f64],
    applied: Applied,
    z: &mut [f64],
    lambda: &mut [f64],
) -> Result<(), KinematicsError> {
    let nc = model.n_cols();
    let eye = DMatrix::identity(nc, nc);
    let mut last = f64::INFINITY;
    for _ in 0..NEWTON_ITERATIONS {
        let sigma = stresses(model, z, sigma0);
        let (g, r) = model.rigid_rows(z);
        let mut grad = -applied.force(model, z) - r.transpose() * DVector::from_column_slice(lambda);
        let mut at = 0;
        for (v, b) in model.strains(z).iter() {
            grad += b.transpose() * DVector::from_column_slice(&sigma[at..at + v.len()]);
            at += v.len();
        }
        let h = tangent(model, z, (&sigma, lambda), applied, &eye);
        let nr = r.nrows();
        let mut kkt = DMatrix::zeros(nc + nr, nc + nr);
        kkt.view_mut((0, 0), (nc, nc)).copy_from(&h);
        kkt.view_mut((0, nc), (nc, nr)).copy_from(&(-r.transpose()));
        kkt.view_mut((nc, 0), (nr, nc)).copy_from(&r);
        let mut rhs = DVector::zeros(nc + nr);
        rhs.rows_mut(0, nc).copy_from(&(-grad));
        rhs.rows_mut(nc, nr).copy_from(&(-g));
        let step = lstsq(kkt, &rhs).map_err(|e| KinematicsError::BadArgument {
            name: "load",
            expected: "a regular equilibrium".into(),
            got: e.into(),
        })?;
        z.iter_mut().zip(step.rows(0, nc).iter()).for_each(|(z, d)| *z += d);
        lambda.iter_mut().zip(step.rows(nc, nr).iter()).for_each(|(l, d)| *l += d);
        last = step.rows(0, nc).iter().zip(&model.col_scale).map(|(d, s)| (d * s).abs()).fold(0.0, f64::max);
        if last <= NEWTON_TOL * model.mech.scale {
            return Ok(());
        }
    }
    Err(KinematicsError::AssemblyFailed { residual: last, iterations: NEWTON_ITERATIONS })
}
