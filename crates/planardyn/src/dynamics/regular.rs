//! Checks at the dynamics entry points a user calls (not in the integrator's loop, which
//! switches charts near singularities and rejects non-finite steps itself): results that
//! overflow, and configurations too near a type II singularity to compute.

use super::workspace::Workspace;
use crate::kinematics::{sigma_min, Chart};
use crate::model::Mechanism;
use crate::{KinematicsError, SingularityKind};

/// Below this scaled type II measure (smallest singular value of the blocks of the scaled J,
/// each at its group's own length, `kinematics::group_sigma`: dimensionless and the same for
/// any size of mechanism) the mass matrix, forward and inverse dynamics and the reactions are
/// refused. The analogues U grow as 1/sigma and the efforts of a given motion as 1/sigma^2,
/// and so does their sensitivity to the last bit of q: on the slider-driven slider-crank
/// approaching its dead centre the efforts' relative spread over the next representable
/// slider positions is 4e-5 at sigma 2.0e-6, 3.5e-4 at 6.4e-7, 4.7e-3 at 2.0e-7, and below
/// 8e-8 they are off their 1/sigma^2 law by a factor 2 (test
/// `dynamics_guards::threshold_is_where_the_efforts_keep_three_digits`). Above this value the
/// results keep 3 digits or more.
pub const SINGULAR_SIGMA: f64 = 1e-6;

/// The scaled type II measure at the configuration in `ws` (the estimate of the factorised
/// J of the inputs chart where there is one, else an SVD); below [`SINGULAR_SIGMA`] a
/// `Singular` error with it unless `allow_singular`.
pub fn type_ii_measure(mech: &Mechanism, ws: &mut Workspace, allow_singular: bool) -> Result<f64, KinematicsError> {
    let estimate = if ws.chart == Chart::Inputs { ws.sys.sigma_min_estimate() } else { None };
    let sigma = estimate.unwrap_or_else(|| sigma_min(mech, &Chart::Inputs, &ws.x));
    if sigma < SINGULAR_SIGMA && !allow_singular {
        return Err(KinematicsError::Singular { kind: SingularityKind::TypeII, sigma_min: Some(sigma) });
    }
    Ok(sigma)
}

/// `values` unchanged if all finite, else an `Overflow` error naming `what`: the inputs were
/// checked finite, so a non-finite result is an overflow.
pub fn finite<T: AsRef<[f64]>>(what: &'static str, values: T) -> Result<T, KinematicsError> {
    if values.as_ref().iter().all(|v| v.is_finite()) {
        Ok(values)
    } else {
        Err(KinematicsError::Overflow { what })
    }
}
