//! The rows of a map of the compliant mechanism's first natural frequency, or of a point's
//! weakest stiffness, over two coordinates: the design view's maps beside the singularity map,
//! on the same grid and the same branch (`dynamics::MapRows`: which branch a map shows). Each
//! cell is the elastic analysis of [`super::modes`] or [`super::stiffness`] about the rigid pose
//! placed there.

use super::model::Output;
use super::modes::modes_of;
use super::stiffness::{check_preload, elastic_model, stiffness_of, weakest_direction, Load};
use crate::dynamics::{self, MapGrid, MapRows};
use crate::model::Mechanism;
use crate::Error;
use std::f64::consts::TAU;

/// What a cell of an elastic map holds.
#[derive(Debug, Clone)]
pub enum MapValue {
    /// The first natural frequency (Hz) of [`super::modes`] without gravity's load, each
    /// elastic drive's rotor held (`free_rotors` false) or free.
    FirstFrequency { free_rotors: bool },
    /// The translational stiffness of `out` in its weakest direction (N/m) under `load`
    /// ([`super::stiffness`] then [`weakest_direction`] of the translational block).
    Weakest { out: Output, load: Load },
}

/// The rows of `value` over `grid` (see `dynamics::MapRows`), NaN where the mechanism does not
/// assemble on the branch shown or the analysis fails there (a singular pose). A model without
/// a `compliance:` section, or a preload on an actuator without a transmission spring, is
/// refused before any cell.
pub fn map_rows(mech: &Mechanism, q: &[f64], grid: &MapGrid<'_>, value: &MapValue) -> Result<MapRows, Error> {
    let free_rotors = matches!(value, MapValue::FirstFrequency { free_rotors: true });
    let model = elastic_model(mech, grid.x_start(), free_rotors)?;
    if let MapValue::Weakest { load, .. } = value {
        check_preload(&model, load)?;
    }
    Ok(dynamics::map_rows(mech, q, grid, |_, ws| {
        let model = elastic_model(mech, &ws.x, free_rotors).ok()?;
        match value {
            MapValue::FirstFrequency { .. } => Some(modes_of(&model, false).ok()?.omega().first()? / TAU),
            MapValue::Weakest { out, load } => {
                Some(weakest_direction(&stiffness_of(&model, *out, load).ok()?, None).stiffness)
            }
        }
    }))
}
