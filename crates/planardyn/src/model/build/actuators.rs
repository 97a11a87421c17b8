//! Validation of the actuators and of the Coulomb friction of the pairs.

use super::{coordinate_index, pair_id, relative_pair, Ctx, R};
use crate::model::actuators::{Actuator, JointFriction, Limits, PairActuator};
use crate::model::pairs::{self, Relative};
use crate::model::spec::{ActuatorSpec, LimitsSpec, LoadSpec};
use crate::model::{Mechanism, PairKind};

/// Default regularisation speeds: a motor's (rad/s) and a pair's slip (m/s).
const MOTOR_STICTION_SPEED: f64 = 1e-2;
const PAIR_STICTION_SPEED: f64 = 1e-4;
const STRIBECK_SPEED: f64 = 1e-2;
/// Default pressure angle of a gear mesh: the standard involute tooth's 20 degrees.
const PRESSURE_ANGLE: f64 = 20.0 * std::f64::consts::PI / 180.0;
/// Largest pressure angle accepted (rad, 45 degrees): beyond, N = F_t / cos(alpha) is no tooth's.
const MAX_PRESSURE_ANGLE: f64 = std::f64::consts::FRAC_PI_4;

/// One actuator slot per coordinate (`None`: an ideal effort source), and the redundant
/// actuators on pairs.
pub(in crate::model) fn build_actuators(
    ctx: &Ctx,
    mech: &Mechanism,
    specs: &[ActuatorSpec],
) -> R<(Vec<Option<Actuator>>, Vec<PairActuator>)> {
    let mut out: Vec<Option<Actuator>> = vec![None; mech.dof()];
    let mut on_pairs: Vec<PairActuator> = Vec::new();
    for (k, a) in specs.iter().enumerate() {
        let path = format!("actuators[{k}]");
        let coordinate = match (&a.coordinate, &a.pair) {
            (Some(c), None) => c,
            (None, Some(pair)) => {
                on_pairs.push(pair_actuator(ctx, mech, &path, a, pair, &on_pairs)?);
                continue;
            }
            _ => return Err(ctx.err(path, "give exactly one of `coordinate` or `pair` (a redundant actuator)")),
        };
        let i = coordinate_index(ctx, mech, &format!("{path}.coordinate"), coordinate)?;
        if out[i].is_some() {
            return Err(ctx.err(
                format!("{path}.coordinate"),
                format!("coordinate '{coordinate}' already has an actuator; remove one of the two"),
            ));
        }
        out[i] = Some(motor(ctx, &path, a, coordinate)?);
    }
    Ok((out, on_pairs))
}

/// The motor an actuator's spec describes (`default_name` when the spec names none).
fn motor(ctx: &Ctx, path: &str, a: &ActuatorSpec, default_name: &str) -> R<Actuator> {
    let positive = |field: &str, v: f64| -> R<f64> {
        let p = format!("{path}.{field}");
        if ctx.finite(&p, v)? <= 0.0 {
            return Err(ctx.err(p, format!("{v} must be > 0")));
        }
        Ok(v)
    };
    let efficiency = positive("efficiency", a.efficiency)?;
    if efficiency > 1.0 {
        return Err(ctx.err(
            format!("{path}.efficiency"),
            format!("{efficiency} is above 1; give the fraction of the power transmitted, in (0, 1]"),
        ));
    }
    Ok(Actuator {
        name: a.name.clone().unwrap_or_else(|| default_name.to_string()),
        ratio: positive("gear_ratio", a.gear_ratio)?,
        efficiency,
        rotor_inertia: ctx.non_negative(&format!("{path}.rotor_inertia"), a.rotor_inertia)?,
        viscous: ctx.non_negative(&format!("{path}.viscous"), a.viscous)?,
        coulomb: ctx.non_negative(&format!("{path}.coulomb"), a.coulomb)?,
        stiction_speed: positive("stiction_speed", a.stiction_speed.unwrap_or(MOTOR_STICTION_SPEED))?,
        limits: build_limits(ctx, &format!("{path}.limits"), a.limits.as_ref())?,
    })
}

/// A redundant actuator: a pair with a relative coordinate, not a coordinate's, driven by a
/// motor through its transmission, or by an ideal effort source when the spec gives none.
fn pair_actuator(
    ctx: &Ctx,
    mech: &Mechanism,
    path: &str,
    a: &ActuatorSpec,
    pair: &str,
    known: &[PairActuator],
) -> R<PairActuator> {
    let id = relative_pair(ctx, mech, &format!("{path}.pair"), pair)?;
    if !mech.friction.is_empty() {
        return Err(ctx.err(
            format!("{path}.pair"),
            "Coulomb pair friction with redundant actuators is not modelled (the reactions depend on the \
             effort distribution); use viscous friction",
        ));
    }
    if mech.coordinates.iter().any(|c| c.pair == id) {
        return Err(ctx.err(
            format!("{path}.pair"),
            format!("'{pair}' is a coordinate's pair: give `coordinate` instead of `pair`"),
        ));
    }
    if known.iter().any(|p| p.pair == id) {
        return Err(ctx.err(format!("{path}.pair"), format!("pair '{pair}' already has an actuator; remove one")));
    }
    let ideal = a.gear_ratio == 1.0
        && a.efficiency == 1.0
        && a.rotor_inertia == 0.0
        && a.viscous == 0.0
        && a.coulomb == 0.0
        && a.stiction_speed.is_none()
        && a.limits.is_none();
    let drive = if ideal { None } else { Some(motor(ctx, path, a, pair)?) };
    Ok(PairActuator { name: a.name.clone().unwrap_or_else(|| pair.to_string()), pair: id, drive })
}

fn build_limits(ctx: &Ctx, path: &str, l: Option<&LimitsSpec>) -> R<Limits> {
    let Some(l) = l else { return Ok(Limits::default()) };
    let opt = |field: &str, v: Option<f64>| -> R<Option<f64>> {
        v.map(|v| {
            let p = format!("{path}.{field}");
            if ctx.finite(&p, v)? <= 0.0 {
                return Err(ctx.err(p, format!("{v} must be > 0")));
            }
            Ok(v)
        })
        .transpose()
    };
    let peak_torque = opt("peak_torque", l.peak_torque)?;
    let max_speed = opt("max_speed", l.max_speed)?;
    let mut envelope = Vec::new();
    match (&l.torque_speed, opt("corner_speed", l.corner_speed)?) {
        (Some(_), Some(_)) => {
            return Err(ctx.err(path, "give `torque_speed` points or `corner_speed`, not both"));
        }
        (Some(points), None) => {
            for (j, p) in points.iter().enumerate() {
                let pj = format!("{path}.torque_speed[{j}]");
                ctx.non_negative(&pj, p[0])?;
                ctx.non_negative(&pj, p[1])?;
                if j > 0 && p[0] <= points[j - 1][0] {
                    return Err(ctx.err(pj, "speeds must increase strictly"));
                }
            }
            if points.first().is_none_or(|p| p[0] != 0.0) {
                return Err(
                    ctx.err(format!("{path}.torque_speed"), "start the envelope at speed 0: [[0, T_stall], ...]")
                );
            }
            envelope.clone_from(points);
        }
        (None, Some(corner)) => {
            let (Some(peak), Some(max)) = (peak_torque, max_speed) else {
                return Err(ctx.err(path, "a `corner_speed` needs `peak_torque` and `max_speed`"));
            };
            if corner >= max {
                return Err(ctx.err(format!("{path}.corner_speed"), format!("{corner} must be below max_speed {max}")));
            }
            envelope = vec![[0.0, peak], [corner, peak], [max, 0.0]];
        }
        (None, None) => {}
    }
    Ok(Limits { peak_torque, continuous_torque: opt("continuous_torque", l.continuous_torque)?, max_speed, envelope })
}

/// The Coulomb friction of the `friction` loads that give a coefficient `mu`.
pub(in crate::model) fn build_friction(ctx: &Ctx, mech: &Mechanism, loads: &[LoadSpec]) -> R<Vec<JointFriction>> {
    let mut out = Vec::new();
    for (k, l) in loads.iter().enumerate() {
        let LoadSpec::Friction {
            pair,
            viscous,
            mu,
            mu_static,
            pin_radius,
            length,
            stiction_speed,
            stribeck_speed,
            pressure_angle,
        } = l
        else {
            continue;
        };
        let path = format!("loads[{k}]");
        if mu.is_none() && viscous.is_none() {
            return Err(ctx.err(&path, "give `viscous` (N m s/rad or N s/m), Coulomb friction `mu`, or both"));
        }
        let Some(mu) = mu else {
            if mu_static.is_some() || pin_radius.is_some() || length.is_some() || pressure_angle.is_some() {
                return Err(ctx.err(format!("{path}.mu"), "Coulomb friction needs its sliding coefficient `mu`"));
            }
            continue;
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
        let length = match (&p.kind, length) {
            (PairKind::Prismatic { .. }, Some(l)) => speed("length", Some(*l), 0.0)?,
            (_, Some(_)) => {
                refuse("length", format!("'{pair}' carries no couple: `length` applies to a prismatic pair only"))?
            }
            (_, None) => 0.0,
        };
        let pressure_angle = match (&p.kind, pressure_angle) {
            (PairKind::Gear(_), a) => {
                let a = a.unwrap_or(PRESSURE_ANGLE);
                if !(0.0..=MAX_PRESSURE_ANGLE).contains(&ctx.finite(&format!("{path}.pressure_angle"), a)?) {
                    refuse(
                        "pressure_angle",
                        format!("{a} rad is not a tooth's pressure angle: give one in [0, {MAX_PRESSURE_ANGLE}] rad"),
                    )?;
                }
                a
            }
            (_, Some(_)) => refuse(
                "pressure_angle",
                format!("'{pair}' has no teeth: `pressure_angle` applies to a gear pair only"),
            )?,
            (_, None) => 0.0,
        };
        out.push(JointFriction {
            pair: id,
            mu,
            mu_static,
            arm,
            length,
            stiction_speed: speed("stiction_speed", *stiction_speed, PAIR_STICTION_SPEED)?,
            stribeck_speed: speed("stribeck_speed", *stribeck_speed, STRIBECK_SPEED)?,
            pressure_angle,
        });
    }
    Ok(out)
}

/// The pair a Coulomb friction load acts on: one with a relative motion, or a gear mesh
/// (whose lever is the pitch-line travel).
fn friction_pair(ctx: &Ctx, mech: &Mechanism, path: &str, name: &str) -> R<crate::model::PairId> {
    let id = pair_id(ctx, mech, path, name)?;
    match mech.pairs[id.0].kind {
        PairKind::Gear(_) => Ok(id),
        _ => relative_pair(ctx, mech, path, name),
    }
}
