//! Validation of the actuators (the pairs' Coulomb friction is a load kind: `model::loads::friction`).

use super::coordinate_index;
use crate::model::actuators::{Actuator, Limits, PairActuator};
use crate::model::checks::{relative_pair, Ctx, R};
use crate::model::spec::{ActuatorSpec, LimitsSpec};
use crate::model::Mechanism;

/// Default regularisation speed of a motor (rad/s).
const MOTOR_STICTION_SPEED: f64 = 1e-2;

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
    let rotor_inertia = ctx.non_negative(&format!("{path}.rotor_inertia"), a.rotor_inertia)?;
    let backdrive_efficiency = backdrive(ctx, path, a.backdrive_efficiency, efficiency, rotor_inertia)?;
    Ok(Actuator {
        name: a.name.clone().unwrap_or_else(|| default_name.to_string()),
        ratio: positive("gear_ratio", a.gear_ratio)?,
        efficiency,
        backdrive_efficiency,
        rotor_inertia,
        viscous: ctx.non_negative(&format!("{path}.viscous"), a.viscous)?,
        coulomb: ctx.non_negative(&format!("{path}.coulomb"), a.coulomb)?,
        stiction_speed: positive("stiction_speed", a.stiction_speed.unwrap_or(MOTOR_STICTION_SPEED))?,
        limits: build_limits(ctx, &format!("{path}.limits"), a.limits.as_ref())?,
    })
}

/// The back-drive efficiency eta_b in [0, 1] (default: the forward one). A self-locking gear
/// (0) needs a rotor: while the load would back-drive it, its output follows the rotor,
/// which its motor alone accelerates (docs/actuators.md).
fn backdrive(ctx: &Ctx, path: &str, given: Option<f64>, efficiency: f64, rotor_inertia: f64) -> R<f64> {
    let Some(v) = given else { return Ok(efficiency) };
    let p = format!("{path}.backdrive_efficiency");
    if !(0.0..=1.0).contains(&ctx.finite(&p, v)?) {
        return Err(ctx.err(p, format!("{v} is not an efficiency: give the fraction of the load's power that reaches the rotor, in [0, 1] (0: self-locking)")));
    }
    if v == 0.0 && rotor_inertia == 0.0 {
        return Err(ctx.err(
            format!("{path}.rotor_inertia"),
            "a self-locking gear (backdrive_efficiency 0) needs the rotor's inertia J > 0: while the load would \
             back-drive it the joint follows the rotor, which only its motor accelerates",
        ));
    }
    Ok(v)
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
        && a.backdrive_efficiency.is_none()
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
