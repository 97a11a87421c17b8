//! Positions on the assembly branch of a reference configuration, at coordinates far from it,
//! for a mechanism with a class III triad (whose Newton solve from a distant pose may converge
//! to another assembly mode, or fail where the branch goes on): the configuration reached from
//! the reference along the straight path in the coordinates, by steps each placed by the closed
//! forms with the triad's Newton from the last step's pose (`ClosedForm::predicted_positions`,
//! a secant predictor), and each kept on the reference's branch:
//! - every group keeps its reference's side (`ClosedForm::keeps_branches`: the triad's sign of
//!   the determinant of its platform Jacobian, the sign of (e_i, (R c_i) x e_i), which changes
//!   only through the triad's type II singularity; a dyad's elbow), and
//! - Newton's correction from the prediction stays small (`MAX_CORRECTION`, as `continue_to`'s),
//!   so a step does not jump to another assembly mode of the same side (a cuspidal triad's);
//!
//! a failing step is cut by 4, and the path is blocked (the coordinates are not reached on this
//! branch) once a step below `MIN_STEP` fails: where no configuration exists on the way (a leg
//! that cannot reach), or at a fold of the branch (its type II singularity, sigma -> 0). The
//! result depends on the reference and the coordinates alone, not on any other point solved
//! before: a map's cells are placed each on its own. Along a path that stays on its branch it
//! is what continuation gives (`assemble_from` from the reference, the Python API's
//! `assemble(q, x_start=)`), to Newton's tolerance.

use super::closed_form::ClosedForm;
use super::constraints::coordinates;
use super::frame::Frame;
use super::position::{scaled_distance, MAX_CORRECTION};
use super::system::col_scales;
use crate::model::{CoordinateKind, Mechanism};
use crate::KinematicsError;

/// Largest step in any coordinate: 0.1 rad, or 0.1 L for a displacement (as `continue_to`'s):
/// the triad's Newton from the secant prediction then corrects by O(0.01) (scaled), far inside
/// the basin of the branch followed.
const MAX_STEP: f64 = 0.1;
/// Smallest step (rad, or L for a displacement) tried before the path is blocked: three cuts
/// by 4 below a full step. Where a step that small fails, the branch ends within 1e-3 rad of
/// the last point reached (a fold, or a leg that cannot reach), and the cells of a map past
/// it are missing whatever finer steps would do; a map's cells are 0.06 rad apart (100 over
/// 2 pi). Most of a map's time is spent on the paths that are blocked (on the 3-RRR's 100 x
/// 100: 1e-4, four cuts, took 1.4 times as long as 1e-3, the same cells present).
const MIN_STEP: f64 = 1e-3;

/// The reference configuration and the buffers of a path (sized once for the mechanism).
#[derive(Debug, Clone)]
pub struct BranchPath {
    /// The reference (3n), on the branches `closed` was given, and its coordinates (m).
    x_from: Vec<f64>,
    z_from: Vec<f64>,
    /// Per coordinate the unit of a step: 1 for an angle, L for a displacement.
    unit: Vec<f64>,
    /// L for translations, 1 for angles, per body coordinate (Newton's correction scaled).
    col_scale: Vec<f64>,
    /// The last two points reached (3n), the prediction (3n) and the coordinates of a step (m).
    x_ok: Vec<f64>,
    x_prev: Vec<f64>,
    predicted: Vec<f64>,
    z: Vec<f64>,
}

impl BranchPath {
    /// Paths from the configuration `x_from` (3n, assembled); `closed` then takes its branches.
    pub fn new(mech: &Mechanism, closed: &mut ClosedForm, x_from: &[f64]) -> Self {
        closed.set_reference(x_from);
        let mut z_from = vec![0.0; mech.dof()];
        coordinates(mech, x_from, &mut z_from);
        let unit = mech.coordinates.iter().map(|c| if c.kind == CoordinateKind::Angle { 1.0 } else { mech.scale });
        BranchPath {
            x_from: x_from.to_vec(),
            unit: unit.collect(),
            col_scale: col_scales(mech),
            x_ok: x_from.to_vec(),
            x_prev: x_from.to_vec(),
            predicted: x_from.to_vec(),
            z: z_from.clone(),
            z_from,
        }
    }

    /// Positions `ws.x` at coordinates q (m) on the reference's branches, reached along the
    /// straight path from its coordinates (see the module's doc); fails where the path is
    /// blocked, `ws.x` then the last point reached.
    pub fn place(&mut self, closed: &mut ClosedForm, q: &[f64], ws: &mut Frame) -> Result<(), KinematicsError> {
        let span = q.iter().zip(&self.z_from).zip(&self.unit).fold(0.0, |a: f64, ((q, z), u)| a.max((q - z).abs() / u));
        let h_max = if span > 0.0 { (MAX_STEP / span).min(1.0) } else { 1.0 };
        self.x_ok.copy_from_slice(&self.x_from);
        self.x_prev.copy_from_slice(&self.x_from);
        let (mut s, mut s_prev, mut h) = (0.0_f64, 0.0_f64, h_max);
        while s < 1.0 {
            let s_new = (s + h).min(1.0);
            let r = if s > s_prev { (s_new - s) / (s - s_prev) } else { 0.0 };
            for ((p, a), b) in self.predicted.iter_mut().zip(&self.x_ok).zip(&self.x_prev) {
                *p = a + r * (a - b);
            }
            for ((z, q), z0) in self.z.iter_mut().zip(q).zip(&self.z_from) {
                *z = z0 + s_new * (q - z0);
            }
            ws.x.copy_from_slice(&self.predicted);
            let stays = closed.predicted_positions(&self.z, ws).is_ok()
                && closed.keeps_branches(&ws.x)
                && scaled_distance(&ws.x, &self.predicted, &self.col_scale) <= MAX_CORRECTION;
            if stays {
                std::mem::swap(&mut self.x_prev, &mut self.x_ok);
                self.x_ok.copy_from_slice(&ws.x);
                (s_prev, s) = (s, s_new);
                h = (2.0 * h).min(h_max);
            } else {
                h /= 4.0;
                if h * span < MIN_STEP {
                    ws.x.copy_from_slice(&self.x_ok);
                    let residual = scaled_distance(&self.z, q, &self.unit);
                    return Err(KinematicsError::AssemblyFailed { residual, iterations: ws.iterations });
                }
            }
        }
        Ok(())
    }
}
