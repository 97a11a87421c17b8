//! The output columns of a simulation, each declared once: its name, its shape per output row,
//! its unit, what it is, and the headings of its columns in a table (a results file).
//!
//! The glues convert a [`Trajectory`] by walking [`COLUMNS`] (the Python glue into numpy
//! arrays, the WebAssembly glue into typed arrays), and the Python package reads the table
//! (`planardyn._core.output_columns()`) for its result's fields, its results files' layout,
//! their writing and their reading. A new column is a row here, its field in [`Trajectory`]
//! and the line of [`Trajectory::record`] that fills it.

use super::trajectory::Trajectory;

/// What a column holds in each output row.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Shape {
    /// One number.
    Scalar,
    /// One true/false.
    Flag,
    /// One number per coordinate: m.
    Coordinates,
    /// [X, Y, phi] per body: 3n.
    BodyPoses,
}

impl Shape {
    /// Short machine-readable name (what `output_columns()` gives Python).
    pub fn name(self) -> &'static str {
        match self {
            Shape::Scalar => "scalar",
            Shape::Flag => "flag",
            Shape::Coordinates => "coordinates",
            Shape::BodyPoses => "body_poses",
        }
    }

    /// Values per row for m coordinates and 3n = `nx` body coordinates.
    pub fn width(self, m: usize, nx: usize) -> usize {
        match self {
            Shape::Scalar | Shape::Flag => 1,
            Shape::Coordinates => m,
            Shape::BodyPoses => nx,
        }
    }
}

/// A column's values, time-major: row k is `values[k * width..(k + 1) * width]`.
#[derive(Debug, Clone, Copy)]
pub enum Values<'a> {
    Numbers(&'a [f64]),
    Flags(&'a [bool]),
}

/// One output column.
#[derive(Debug, Clone, Copy)]
pub struct Column {
    /// Its name: the result's field, the results file's group.
    pub name: &'static str,
    pub shape: Shape,
    /// SI unit ("rad or m": by the coordinate's kind; "1" for a pure number).
    pub unit: &'static str,
    /// What it is, one line.
    pub doc: &'static str,
    /// The heading of each of its columns in a table: `{coordinate}` stands for a coordinate's
    /// name, `{axis}` (X, Y, phi) and `{body}` for a body's pose; a scalar's is its name.
    pub heading: &'static str,
    /// Its values in a trajectory.
    pub values: fn(&Trajectory) -> Values<'_>,
}

/// Every output column, in the order of a results file's table.
pub const COLUMNS: &[Column] = &[
    Column {
        name: "t",
        shape: Shape::Scalar,
        unit: "s",
        doc: "output times",
        heading: "t",
        values: |t| Values::Numbers(&t.t),
    },
    Column {
        name: "q",
        shape: Shape::Coordinates,
        unit: "rad or m",
        doc: "coordinates",
        heading: "{coordinate}",
        values: |t| Values::Numbers(&t.q),
    },
    Column {
        name: "qd",
        shape: Shape::Coordinates,
        unit: "rad/s or m/s",
        doc: "coordinate rates",
        heading: "qd_{coordinate}",
        values: |t| Values::Numbers(&t.qd),
    },
    Column {
        name: "qdd",
        shape: Shape::Coordinates,
        unit: "rad/s^2 or m/s^2",
        doc: "coordinate accelerations",
        heading: "qdd_{coordinate}",
        values: |t| Values::Numbers(&t.qdd),
    },
    Column {
        name: "tau",
        shape: Shape::Coordinates,
        unit: "N m or N",
        doc: "drive efforts applied, joint-side (after the transmissions)",
        heading: "tau_{coordinate}",
        values: |t| Values::Numbers(&t.tau),
    },
    Column {
        name: "kinetic",
        shape: Shape::Scalar,
        unit: "J",
        doc: "kinetic energy",
        heading: "kinetic",
        values: |t| Values::Numbers(&t.kinetic),
    },
    Column {
        name: "potential",
        shape: Shape::Scalar,
        unit: "J",
        doc: "potential energy (gravity, springs)",
        heading: "potential",
        values: |t| Values::Numbers(&t.potential),
    },
    Column {
        name: "work",
        shape: Shape::Scalar,
        unit: "J",
        doc: "work done by the non-conservative forces (drives, dampers, external loads) since t0",
        heading: "work",
        values: |t| Values::Numbers(&t.work),
    },
    Column {
        name: "sigma",
        shape: Shape::Scalar,
        unit: "1",
        doc: "type II singularity measure (smallest scaled singular value)",
        heading: "sigma",
        values: |t| Values::Numbers(&t.sigma),
    },
    Column {
        name: "residual",
        shape: Shape::Scalar,
        unit: "1",
        doc: "scaled loop-closure residual of the position solve (lengths / L, angles in rad)",
        heading: "residual",
        values: |t| Values::Numbers(&t.residual),
    },
    Column {
        name: "partitioned",
        shape: Shape::Flag,
        unit: "1",
        doc: "whether the point was integrated in body coordinates near a singularity",
        heading: "partitioned",
        values: |t| Values::Flags(&t.partitioned),
    },
    Column {
        name: "x",
        shape: Shape::BodyPoses,
        unit: "m, m, rad",
        doc: "body coordinates [X, Y, phi] of each centre of mass",
        heading: "{axis}_{body}",
        values: |t| Values::Numbers(&t.x),
    },
    Column {
        name: "xd",
        shape: Shape::BodyPoses,
        unit: "m/s, m/s, rad/s",
        doc: "body rates [Xd, Yd, phid]",
        heading: "{axis}d_{body}",
        values: |t| Values::Numbers(&t.xd),
    },
];
