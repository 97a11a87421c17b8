//! Friction at a pair: `type: friction`. Its viscous part, -c times the relative rate, is a
//! [`PairSpring`] with k = 0; its Coulomb part, from the pair's load (docs/actuators.md,
//! *Friction from the joint loads*), is a [`JointFriction`] of the model, which the dynamics
//! with losses apply (`dynamics::friction`): torque mu r |F| at a revolute pair of pin radius
//! r, force mu max(|N|, 2|M|/L) along a prismatic pair of length L, mu |N| along a slot,
//! mu F_t / cos(alpha) at a gear mesh.

use super::pair_spring::PairSpring;
use super::{Load, LoadSpecType};
use crate::model::actuators::JointFriction;
use crate::model::checks::{pair_id, relative_pair, Ctx, R};
use crate::model::pairs::{self, FrictionField, Relative};
use crate::model::{Mechanism, PairId};
use crate::units;
use serde::{Deserialize, Serialize};

/// Default regularisation speeds of a pair's slip (m/s): the stiction speed and the
/// Stribeck speed.
const PAIR_STICTION_SPEED: f64 = 1e-4;
const STRIBECK_SPEED: f64 = 1e-2;
/// Default pressure angle of a gear mesh: the standard involute tooth's 20 degrees.
const PRESSURE_ANGLE: f64 = 20.0 * std::f64::consts::PI / 180.0;
/// Largest pressure angle accepted (rad, 45 degrees): beyond, N = F_t / cos(alpha) is no tooth's.
const MAX_PRESSURE_ANGLE: f64 = std::f64::consts::FRAC_PI_4;

/// Friction at a pair: viscous, -c times the relative rate (N m s/rad or N s/m), and
/// Coulomb friction from the pair's load (docs/actuators.md, *Friction from the joint
/// loads*): torque mu r |F| at a revolute pair of pin radius r, force mu max(|N|, 2|M|/L)
/// along a prismatic pair of length L, mu |N| along a slot.
#[derive(Debug, Clone, Deserialize, Serialize, PartialEq)]
// `expecting`: as `force::ForceSpec`'s.
#[serde(deny_unknown_fields, expecting = "struct variant LoadSpec::Friction")]
pub struct FrictionSpec {
    pub pair: String,
    #[serde(default, deserialize_with = "units::pair_damping", skip_serializing_if = "Option::is_none")]
    pub viscous: Option<f64>,
    /// Sliding (kinetic) friction coefficient.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub mu: Option<f64>,
    /// Static coefficient (Stribeck peak at low speed); default `mu`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub mu_static: Option<f64>,
    /// Pin radius of a revolute pair (m): the friction arm.
    #[serde(default, deserialize_with = "units::length", skip_serializing_if = "Option::is_none")]
    pub pin_radius: Option<f64>,
    /// Length of a prismatic pair's slider (m): the arm over which it carries a couple.
    #[serde(default, deserialize_with = "units::length", skip_serializing_if = "Option::is_none")]
    pub length: Option<f64>,
    /// Slip speed (m/s) below which the regularised law lets the pair creep (default 1e-4).
    #[serde(default, deserialize_with = "units::speed", skip_serializing_if = "Option::is_none")]
    pub stiction_speed: Option<f64>,
    /// Slip speed (m/s) over which the coefficient falls from `mu_static` to `mu` (default 1e-2).
    #[serde(default, deserialize_with = "units::speed", skip_serializing_if = "Option::is_none")]
    pub stribeck_speed: Option<f64>,
    /// Pressure angle of a gear pair's teeth (rad, default 20 degrees): normal load F_t / cos.
    #[serde(default, deserialize_with = "units::angle", skip_serializing_if = "Option::is_none")]
    pub pressure_angle: Option<f64>,
}

impl LoadSpecType for FrictionSpec {
    /// The viscous damper; none at a gear mesh without `viscous`, whose friction is all the
    /// mesh's Coulomb friction (no damper on a relative coordinate it lacks).
    fn build(&self, ctx: &Ctx, mech: &Mechanism, path: &str) -> R<Option<Load>> {
        let mesh = |id: PairId| pairs::relative(&mech.pairs[id.0]).is_none();
        if self.viscous.is_none() && pair_id(ctx, mech, "", &self.pair).is_ok_and(mesh) {
            return Ok(None);
        }
        let pair = relative_pair(ctx, mech, &format!("{path}.pair"), &self.pair)?;
        Ok(Some(Load::PairSpring(PairSpring {
            pair,
            stiffness: 0.0,
            damping: ctx.non_negative(&format!("{path}.viscous"), self.viscous.unwrap_or(0.0))?,
            rest: 0.0,
            linear: pairs::linear_coordinate(&mech.pairs[pair.0]),
        })))
    }

    /// The Coulomb friction when the load gives a coefficient `mu`.
    fn friction(&self, ctx: &Ctx, mech: &Mechanism, path: &str) -> R<Option<JointFriction>> {
        let FrictionSpec {
            pair,
            viscous,
            mu,
            mu_static,
            pin_radius,
            length,
            stiction_speed,
            stribeck_speed,
            pressure_angle,
        } = self;
        if mu.is_none() && viscous.is_none() {
            return Err(ctx.err(path, "give `viscous` (N m s/rad or N s/m), Coulomb friction `mu`, or both"));
        }
        let Some(mu) = mu else {
            if mu_static.is_some() || pin_radius.is_some() || length.is_some() || pressure_angle.is_some() {
                return Err(ctx.err(format!("{path}.mu"), "Coulomb friction needs its sliding coefficient `mu`"));
            }
            return Ok(None);
        };
        let id = friction_pair(ctx, mech, &format!("{path}.pair"), pair)?;
        let mu = ctx.non_negative(&format!("{path}.mu"), *mu)?;
        let mu_static = ctx.non_negative(&format!("{path}.mu_static"), mu_static.unwrap_or(mu))?;
        let speed = |field: &str, v: Option<f64>, default: f64| -> R<f64> {
            let p = format!("{path}.{field}");
            let v = v.unwrap_or(default);
            if ctx.finite(&p, v)? <= 0.0 {
                return Err(ctx.err(p, format!("{v} must be > 0")));
            }
            Ok(v)
        };
        let p = &mech.pairs[id.0];
        let revolute = pairs::relative(p) == Some(Relative::Angle);
        // A field given where it does not apply (or missing where it must be), and the fix.
        let refuse = |field: &str, fix: String| -> R<f64> { Err(ctx.err(format!("{path}.{field}"), fix)) };
        let arm = match (revolute, pin_radius) {
            (true, Some(r)) => speed("pin_radius", Some(*r), 0.0)?,
            (true, None) => refuse(
                "pin_radius",
                format!("'{pair}' turns: give its pin radius (m), the arm of the friction force mu |F|"),
            )?,
            (false, Some(_)) => refuse("pin_radius", format!("'{pair}' does not turn on a pin: remove `pin_radius`"))?,
            (false, None) => 1.0,
        };
        let field = pairs::friction_field(&p.kind);
        let length = match (field, length) {
            (FrictionField::Length, Some(l)) => speed("length", Some(*l), 0.0)?,
            (FrictionField::None | FrictionField::PressureAngle, Some(_)) => {
                refuse("length", format!("'{pair}' carries no couple: `length` applies to a prismatic pair only"))?
            }
            (_, None) => 0.0,
        };
        let pressure_angle = match (field, pressure_angle) {
            (FrictionField::PressureAngle, a) => {
                let a = a.unwrap_or(PRESSURE_ANGLE);
                if !(0.0..=MAX_PRESSURE_ANGLE).contains(&ctx.finite(&format!("{path}.pressure_angle"), a)?) {
                    refuse(
                        "pressure_angle",
                        format!("{a} rad is not a tooth's pressure angle: give one in [0, {MAX_PRESSURE_ANGLE}] rad"),
                    )?;
                }
                a
            }
            (FrictionField::None | FrictionField::Length, Some(_)) => refuse(
                "pressure_angle",
                format!("'{pair}' has no teeth: `pressure_angle` applies to a gear pair only"),
            )?,
            (_, None) => 0.0,
        };
        Ok(Some(JointFriction {
            pair: id,
            mu,
            mu_static,
            arm,
            length,
            stiction_speed: speed("stiction_speed", *stiction_speed, PAIR_STICTION_SPEED)?,
            stribeck_speed: speed("stribeck_speed", *stribeck_speed, STRIBECK_SPEED)?,
            pressure_angle,
        }))
    }
}

/// The pair a Coulomb friction load acts on: one with a relative motion, or a gear mesh
/// (whose lever is the pitch-line travel).
fn friction_pair(ctx: &Ctx, mech: &Mechanism, path: &str, name: &str) -> R<PairId> {
    let id = pair_id(ctx, mech, path, name)?;
    match pairs::friction_field(&mech.pairs[id.0].kind) {
        FrictionField::PressureAngle => Ok(id),
        FrictionField::None | FrictionField::Length => relative_pair(ctx, mech, path, name),
    }
}
