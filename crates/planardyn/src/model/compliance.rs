//! Compliance of a mechanism (docs/model-format.md, *Compliance*; docs/stiffness.md): the
//! file's `compliance:` section and its validated form. Three kinds of elastic element:
//!
//! - a drive's transmission: a torsional (or, on a sliding coordinate, linear) spring and
//!   damper between the actuator's rotor and the driven pair, given at the joint side or the
//!   motor side (reflected to the joint side with the transmission ratio n: k_joint = n^2 k_motor);
//! - a revolute pair's radial compliance: an isotropic spring on the separation of the two
//!   copies of the pin; a prismatic pair's: a lateral spring on the offset of the slider's
//!   copy of the pair point from the guide and a tilt spring on their relative rotation;
//! - a slender link (planar Euler-Bernoulli beam) between its two points, clamped at its first
//!   point in the body frame, with axial stiffness EA and bending stiffness EI (given, or from
//!   the section and the material).
//!
//! The mechanics that use them are in `crate::elastic`. Units SI: N m/rad, N/m, N m s/rad,
//! N s/m, N, N m^2, m^2, m^4, Pa. The stiffnesses, dampings, EA and a rectangle's sides may be
//! written with a unit (`"20 kN m/rad"`, `"30 mm"`: `crate::units`); EI, E, area and
//! second_moment have no unit table and are numbers in SI.

use super::checks::{pair_id, Ctx, R};
use super::{BodyId, Mechanism, PairId, PairKind, PointId};
use crate::units;
use serde::{Deserialize, Serialize};

/// The `compliance:` section of a model file.
#[derive(Debug, Clone, Default, Deserialize, Serialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct ComplianceSpec {
    /// Transmission stiffness of actuators (coordinates or redundant pair actuators).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub drives: Vec<DriveComplianceSpec>,
    /// Compliance of revolute and prismatic pairs.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub pairs: Vec<PairComplianceSpec>,
    /// Slender links as planar beams.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub links: Vec<LinkComplianceSpec>,
}

/// Which side of the transmission a drive's stiffness and damping are given on.
#[derive(Debug, Clone, Copy, Default, Deserialize, Serialize, PartialEq, Eq)]
#[serde(rename_all = "snake_case")]
pub enum Side {
    /// On the driven pair's coordinate (N m/rad or N/m).
    #[default]
    Joint,
    /// On the motor shaft (N m/rad), reflected as n^2 k.
    Motor,
}

/// A drive's transmission stiffness k (and damping c) on an actuator (a coordinate's name or
/// a redundant pair actuator's name).
#[derive(Debug, Clone, Default, Deserialize, Serialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct DriveComplianceSpec {
    pub actuator: String,
    /// k (N m/rad, or N/m on a sliding coordinate), > 0.
    #[serde(deserialize_with = "units::pair_stiffness")]
    pub stiffness: f64,
    /// c (N m s/rad or N s/m), >= 0.
    #[serde(default, deserialize_with = "units::pair_damping")]
    pub damping: f64,
    #[serde(default)]
    pub side: Side,
}

/// A pair's stiffness k (N/m) and damping c (N s/m): radial for a revolute pair, lateral for a
/// prismatic one, which also takes a tilt stiffness (N m/rad) and damping (N m s/rad) against
/// the relative rotation of its two bodies.
#[derive(Debug, Clone, Default, Deserialize, Serialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct PairComplianceSpec {
    pub pair: String,
    #[serde(deserialize_with = "units::stiffness")]
    pub stiffness: f64,
    #[serde(default, deserialize_with = "units::damping")]
    pub damping: f64,
    #[serde(default, deserialize_with = "units::torsional_stiffness", skip_serializing_if = "Option::is_none")]
    pub tilt_stiffness: Option<f64>,
    #[serde(default, deserialize_with = "units::torsional_damping", skip_serializing_if = "Option::is_none")]
    pub tilt_damping: Option<f64>,
}

/// A slender link: EA (N) and EI (N m^2) directly, or a `section` and a `material`.
#[derive(Debug, Clone, Default, Deserialize, Serialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct LinkComplianceSpec {
    pub body: String,
    #[serde(default, rename = "EA", deserialize_with = "units::force", skip_serializing_if = "Option::is_none")]
    pub ea: Option<f64>,
    #[serde(default, rename = "EI", skip_serializing_if = "Option::is_none")]
    pub ei: Option<f64>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub section: Option<SectionSpec>,
    /// Young's modulus E (Pa).
    #[serde(default, rename = "E", skip_serializing_if = "Option::is_none")]
    pub young: Option<f64>,
}

/// A cross-section: its area A (m^2) and second moment of area I (m^4) about the bending
/// axis, or a solid rectangle [width, height] (m; bending in the plane of the mechanism, so
/// I = width height^3 / 12 with `height` the in-plane depth).
#[derive(Debug, Clone, Default, Deserialize, Serialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct SectionSpec {
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub area: Option<f64>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub second_moment: Option<f64>,
    #[serde(default, deserialize_with = "units::length", skip_serializing_if = "Option::is_none")]
    pub rectangle: Option<[f64; 2]>,
}

/// The validated compliances (all empty: a rigid mechanism).
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Compliance {
    pub drives: Vec<DriveCompliance>,
    pub pairs: Vec<PairCompliance>,
    pub links: Vec<LinkCompliance>,
}

impl Compliance {
    pub fn is_empty(&self) -> bool {
        self.drives.is_empty() && self.pairs.is_empty() && self.links.is_empty()
    }
}

/// A drive's transmission spring, joint side.
#[derive(Debug, Clone, PartialEq)]
pub struct DriveCompliance {
    /// The actuator's index (the coordinates', then the pair actuators').
    pub actuator: usize,
    /// The pair whose relative coordinate the actuator drives.
    pub pair: PairId,
    /// k (N m/rad or N/m) and c (N m s/rad or N s/m), joint side.
    pub stiffness: f64,
    pub damping: f64,
    /// The rotor's inertia reflected to the joint side, n^2 J (kg m^2 or kg; 0 without a motor).
    pub rotor_inertia: f64,
}

/// A pair's springs and dampers, one a constraint row of its kind (`model::pairs`): a
/// revolute pair's [x, y] separation both radial (N/m, N s/m), a prismatic pair's [relative
/// rotation, lateral offset] tilt (N m/rad, N m s/rad) and lateral (N/m, N s/m).
#[derive(Debug, Clone, PartialEq)]
pub struct PairCompliance {
    pub pair: PairId,
    pub stiffness: [f64; 2],
    pub damping: [f64; 2],
}

/// A beam from the body's first point (clamped) to its second point, the `tip`.
#[derive(Debug, Clone, PartialEq)]
pub struct LinkCompliance {
    pub body: BodyId,
    pub tip: PointId,
    /// L (m), EA (N), EI (N m^2).
    pub length: f64,
    pub ea: f64,
    pub ei: f64,
}

/// The compliances of a specification, checked against the mechanism as drawn.
pub(crate) fn build(ctx: &Ctx, mech: &Mechanism, spec: Option<&ComplianceSpec>) -> R<Compliance> {
    let Some(spec) = spec else { return Ok(Compliance::default()) };
    let mut out = Compliance::default();
    for (k, d) in spec.drives.iter().enumerate() {
        let drive = drive(ctx, mech, &format!("compliance.drives[{k}]"), d)?;
        if out.drives.iter().any(|o| o.actuator == drive.actuator) {
            return Err(ctx.err(
                format!("compliance.drives[{k}].actuator"),
                format!("actuator '{}' is given twice; give it once", d.actuator),
            ));
        }
        out.drives.push(drive);
    }
    for (k, p) in spec.pairs.iter().enumerate() {
        let path = format!("compliance.pairs[{k}]");
        let id = pair_id(ctx, mech, &format!("{path}.pair"), &p.pair)?;
        if out.pairs.iter().any(|o| o.pair == id) {
            return Err(ctx.err(format!("{path}.pair"), format!("pair '{}' is given twice; give it once", p.pair)));
        }
        let stiffness = positive(ctx, &format!("{path}.stiffness"), p.stiffness)?;
        let damping = ctx.non_negative(&format!("{path}.damping"), p.damping)?;
        let (stiffness, damping) = match mech.pairs[id.0].kind {
            PairKind::Revolute => {
                if p.tilt_stiffness.is_some() || p.tilt_damping.is_some() {
                    return Err(ctx.err(
                        format!("{path}.tilt_stiffness"),
                        format!(
                            "'{}' is a revolute pair, which turns freely: drop tilt_stiffness and tilt_damping",
                            p.pair
                        ),
                    ));
                }
                ([stiffness; 2], [damping; 2])
            }
            PairKind::Prismatic { .. } => {
                let tilt = p.tilt_stiffness.ok_or_else(|| {
                    ctx.err(
                        format!("{path}.tilt_stiffness"),
                        format!(
                            "'{}' is a prismatic pair: give tilt_stiffness (N m/rad) against its bodies' relative \
                             rotation, beside stiffness (N/m) against the lateral offset",
                            p.pair
                        ),
                    )
                })?;
                let tilt = positive(ctx, &format!("{path}.tilt_stiffness"), tilt)?;
                let tilt_damping = ctx.non_negative(&format!("{path}.tilt_damping"), p.tilt_damping.unwrap_or(0.0))?;
                // The prismatic pair's rows: [relative rotation, lateral offset] (pairs::prismatic).
                ([tilt, stiffness], [tilt_damping, damping])
            }
            PairKind::Gear(_) | PairKind::Slot(_) => {
                return Err(ctx.err(
                    format!("{path}.pair"),
                    format!(
                        "'{}' is a gear or slot pair; pair compliance is modelled on revolute and prismatic pairs",
                        p.pair
                    ),
                ))
            }
        };
        out.pairs.push(PairCompliance { pair: id, stiffness, damping });
    }
    for (k, l) in spec.links.iter().enumerate() {
        let link = link(ctx, mech, &format!("compliance.links[{k}]"), l)?;
        if out.links.iter().any(|o| o.body == link.body) {
            return Err(ctx.err(
                format!("compliance.links[{k}].body"),
                format!("body '{}' is given twice; give it once", l.body),
            ));
        }
        out.links.push(link);
    }
    Ok(out)
}

fn positive(ctx: &Ctx, path: &str, v: f64) -> R<f64> {
    if ctx.finite(path, v)? <= 0.0 {
        return Err(ctx.err(path, format!("{v} must be > 0 (SI units)")));
    }
    Ok(v)
}

fn drive(ctx: &Ctx, mech: &Mechanism, path: &str, d: &DriveComplianceSpec) -> R<DriveCompliance> {
    let names = mech.actuator_names();
    let actuator = names.iter().position(|n| *n == d.actuator).ok_or_else(|| {
        ctx.err(
            format!("{path}.actuator"),
            format!(
                "unknown actuator '{}'; actuators are the coordinates and the pair actuators: {} (use one of them)",
                d.actuator,
                names.join(", ")
            ),
        )
    })?;
    let m = mech.dof();
    let (pair, motor) = if actuator < m {
        (mech.coordinates[actuator].pair, mech.actuators[actuator].as_ref())
    } else {
        let a = &mech.pair_actuators[actuator - m];
        (a.pair, a.drive.as_ref())
    };
    let ratio = match (d.side, motor) {
        (Side::Joint, _) => 1.0,
        (Side::Motor, Some(a)) => a.ratio * a.ratio,
        (Side::Motor, None) => {
            return Err(ctx.err(
                format!("{path}.side"),
                format!(
                    "'motor' needs the transmission ratio of actuator '{}': add it to `actuators` with its \
                     `gear_ratio`, or give the stiffness on the joint side (side: joint)",
                    d.actuator
                ),
            ))
        }
    };
    Ok(DriveCompliance {
        actuator,
        pair,
        stiffness: ratio * positive(ctx, &format!("{path}.stiffness"), d.stiffness)?,
        damping: ratio * ctx.non_negative(&format!("{path}.damping"), d.damping)?,
        rotor_inertia: motor.map_or(0.0, |a| a.ratio * a.ratio * a.rotor_inertia),
    })
}

fn link(ctx: &Ctx, mech: &Mechanism, path: &str, l: &LinkComplianceSpec) -> R<LinkCompliance> {
    let body = mech.body_id(&l.body).ok_or_else(|| {
        ctx.err(
            format!("{path}.body"),
            format!("unknown body '{}'; bodies are: {} (use one of them)", l.body, mech.body_names().join(", ")),
        )
    })?;
    let points = &mech.bodies[body.0].points;
    if points.len() != 2 {
        return Err(ctx.err(
            format!("{path}.body"),
            format!(
                "body '{}' carries {} points; a slender link is a beam between exactly two points (its first, \
                 clamped, and its second, the tip): model a plate or a ternary link as rigid",
                l.body,
                points.len()
            ),
        ));
    }
    let tip = points[1].0;
    let geared = mech.pairs.iter().any(|p| {
        matches!(p.kind, PairKind::Gear(_)) && [p.a, p.b].contains(&super::Link::Body(body)) && p.point == tip
    });
    if geared {
        return Err(ctx.err(format!("{path}.body"), "a gear at the tip of a slender link is not modelled"));
    }
    let (a, b) = (points[0].1, points[1].1);
    let length = (b[0] - a[0]).hypot(b[1] - a[1]);
    let (ea, ei) = match (l.ea, l.ei, &l.section, l.young) {
        (Some(ea), Some(ei), None, None) => (ea, ei),
        (None, None, Some(s), Some(e)) => {
            let e = positive(ctx, &format!("{path}.E"), e)?;
            let (area, second_moment) = section(ctx, &format!("{path}.section"), s)?;
            (e * area, e * second_moment)
        }
        _ => {
            return Err(
                ctx.err(path, "give either `EA` (N) and `EI` (N m^2), or a `section` and the material's `E` (Pa)")
            )
        }
    };
    Ok(LinkCompliance {
        body,
        tip,
        length,
        ea: positive(ctx, &format!("{path}.EA"), ea)?,
        ei: positive(ctx, &format!("{path}.EI"), ei)?,
    })
}

/// A (m^2) and I (m^4) of a section.
fn section(ctx: &Ctx, path: &str, s: &SectionSpec) -> R<(f64, f64)> {
    match (s.area, s.second_moment, s.rectangle) {
        (Some(a), Some(i), None) => {
            Ok((positive(ctx, &format!("{path}.area"), a)?, positive(ctx, &format!("{path}.second_moment"), i)?))
        }
        (None, None, Some([w, h])) => {
            let w = positive(ctx, &format!("{path}.rectangle[0]"), w)?;
            let h = positive(ctx, &format!("{path}.rectangle[1]"), h)?;
            Ok((w * h, w * h.powi(3) / 12.0))
        }
        _ => Err(ctx.err(path, "give `area` and `second_moment`, or `rectangle: [width, height]` (m)")),
    }
}
