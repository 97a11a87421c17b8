//! The units of each quantity kind a model file takes, with the SI value of one of each
//! (exact by definition: the inch 0.0254 m, the pound 0.45359237 kg, the pound-force
//! 0.45359237 * 9.80665 N, the revolution 2 pi rad). A spelling is written with single spaces
//! between factors; `read` accepts any white space, `*`, `·` or `⋅` there, `²` for `^2`,
//! `µ` or `μ` for `u` and `°` for `deg`.

use super::{Kind, Quantity};
use std::f64::consts::PI;

const INCH: f64 = 0.0254;
const FOOT: f64 = 0.3048;
const POUND: f64 = 0.45359237;
const POUND_FORCE: f64 = POUND * 9.80665;
const DEGREE: f64 = PI / 180.0;

pub const LENGTH: Kind = Kind {
    name: "a length",
    key: "length",
    si: "m",
    units: &[(&["m"], 1.0), (&["mm"], 1e-3), (&["cm"], 1e-2), (&["um"], 1e-6), (&["in"], INCH), (&["ft"], FOOT)],
};
pub const ANGLE: Kind = Kind {
    name: "an angle",
    key: "angle",
    si: "rad",
    units: &[(&["rad"], 1.0), (&["deg"], DEGREE), (&["rev", "turn"], 2.0 * PI)],
};
pub const MASS: Kind =
    Kind { name: "a mass", key: "mass", si: "kg", units: &[(&["kg"], 1.0), (&["g"], 1e-3), (&["lb"], POUND)] };
pub const INERTIA: Kind = Kind {
    name: "a moment of inertia",
    key: "inertia",
    si: "kg m^2",
    units: &[
        (&["kg m^2"], 1.0),
        (&["kg mm^2"], 1e-6),
        (&["kg cm^2"], 1e-4),
        (&["g mm^2"], 1e-9),
        (&["g cm^2"], 1e-7),
        (&["lb in^2"], POUND * INCH * INCH),
        (&["lb ft^2"], POUND * FOOT * FOOT),
    ],
};
pub const FORCE: Kind = Kind {
    name: "a force",
    key: "force",
    si: "N",
    units: &[(&["N"], 1.0), (&["kN"], 1e3), (&["mN"], 1e-3), (&["lbf"], POUND_FORCE)],
};
pub const TORQUE: Kind = Kind {
    name: "a torque",
    key: "torque",
    si: "N m",
    units: &[
        (&["N m", "Nm"], 1.0),
        (&["N mm", "Nmm"], 1e-3),
        (&["mN m", "mNm"], 1e-3),
        (&["kN m", "kNm"], 1e3),
        (&["lbf in"], POUND_FORCE * INCH),
        (&["lbf ft"], POUND_FORCE * FOOT),
    ],
};
pub const TIME: Kind =
    Kind { name: "a time", key: "time", si: "s", units: &[(&["s"], 1.0), (&["ms"], 1e-3), (&["min"], 60.0)] };
pub const SPEED: Kind = Kind {
    name: "a speed",
    key: "speed",
    si: "m/s",
    units: &[(&["m/s"], 1.0), (&["mm/s"], 1e-3), (&["cm/s"], 1e-2), (&["in/s"], INCH), (&["ft/s"], FOOT)],
};
pub const ANGULAR_SPEED: Kind = Kind {
    name: "an angular speed",
    key: "angularSpeed",
    si: "rad/s",
    units: &[(&["rad/s"], 1.0), (&["deg/s"], DEGREE), (&["rpm", "rev/min"], 2.0 * PI / 60.0), (&["rev/s"], 2.0 * PI)],
};
pub const ACCELERATION: Kind = Kind {
    name: "an acceleration",
    key: "acceleration",
    si: "m/s^2",
    units: &[(&["m/s^2"], 1.0), (&["mm/s^2"], 1e-3), (&["ft/s^2"], FOOT)],
};
pub const STIFFNESS: Kind = Kind {
    name: "a stiffness",
    key: "stiffness",
    si: "N/m",
    units: &[(&["N/m"], 1.0), (&["N/mm"], 1e3), (&["kN/m"], 1e3), (&["lbf/in"], POUND_FORCE / INCH)],
};
pub const TORSIONAL_STIFFNESS: Kind = Kind {
    name: "a torsional stiffness",
    key: "torsionalStiffness",
    si: "N m/rad",
    units: &[(&["N m/rad", "Nm/rad"], 1.0), (&["N m/deg", "Nm/deg"], 1.0 / DEGREE), (&["N mm/rad", "Nmm/rad"], 1e-3)],
};
pub const DAMPING: Kind = Kind {
    name: "a damping coefficient",
    key: "damping",
    si: "N s/m",
    units: &[(&["N s/m", "Ns/m"], 1.0), (&["N s/mm", "Ns/mm"], 1e3)],
};
pub const TORSIONAL_DAMPING: Kind = Kind {
    name: "a torsional damping coefficient",
    key: "torsionalDamping",
    si: "N m s/rad",
    units: &[(&["N m s/rad", "Nms/rad"], 1.0), (&["N mm s/rad", "Nmms/rad"], 1e-3)],
};

/// Every kind, for messages that name the kind a unit belongs to and for the schema check.
pub const KINDS: [&Kind; 14] = [
    &LENGTH,
    &ANGLE,
    &MASS,
    &INERTIA,
    &FORCE,
    &TORQUE,
    &TIME,
    &SPEED,
    &ANGULAR_SPEED,
    &ACCELERATION,
    &STIFFNESS,
    &TORSIONAL_STIFFNESS,
    &DAMPING,
    &TORSIONAL_DAMPING,
];

macro_rules! quantities {
    ($($(#[$doc:meta])* $name:ident = [$($kind:expr),+];)*) => {$(
        $(#[$doc])*
        pub struct $name;
        impl Quantity for $name {
            const KINDS: &'static [&'static Kind] = &[$(&$kind),+];
        }
    )*};
}

quantities! {
    Length = [LENGTH];
    Angle = [ANGLE];
    Mass = [MASS];
    Inertia = [INERTIA];
    Force = [FORCE];
    Torque = [TORQUE];
    Time = [TIME];
    Speed = [SPEED];
    AngularSpeed = [ANGULAR_SPEED];
    Acceleration = [ACCELERATION];
    Stiffness = [STIFFNESS];
    Damping = [DAMPING];
    TorsionalDamping = [TORSIONAL_DAMPING];
    TorsionalStiffness = [TORSIONAL_STIFFNESS];
    /// A pair's position: an angle (revolute) or a length (prismatic, slot).
    Position = [ANGLE, LENGTH];
    /// A pair's rate: rad/s or m/s.
    Rate = [ANGULAR_SPEED, SPEED];
    /// An effort on a pair: a torque or a force.
    Effort = [TORQUE, FORCE];
    /// A pair spring's stiffness: N m/rad or N/m.
    PairStiffness = [TORSIONAL_STIFFNESS, STIFFNESS];
    /// A pair's viscous coefficient: N m s/rad or N s/m.
    PairDamping = [TORSIONAL_DAMPING, DAMPING];
}
