//! The mechanism model, pure data: the bodies, the pairs with their kinds ([`pairs`], one file
//! a kind), coordinates, drives, loads with their kinds ([`loads`], one file a kind) and
//! actuators; immutable once built from a
//! [`MechanismSpec`]. The checks that need no mechanics are here (`build`); the loader
//! (`crate::loader`) reads model files and adds the checks that need kinematics.
//!
//! Bodies carry their points in a local frame with origin at the centre of mass, rotated by
//! the body's drawn angle, so that a world point is `r + R(phi) s` with `x_i = [X, Y, phi]`.
//! The ground is not part of `x`; its local frame is the global frame.

pub mod actuators;
pub(crate) mod build;
pub(crate) mod checks;
pub mod compliance;
pub mod construct;
pub mod construction;
pub(crate) mod diameter;
pub mod loads;
mod motion;
pub mod pairs;
pub mod spec;

pub use actuators::{Actuator, JointFriction, Limits, PairActuator};
pub use loads::Load;
pub use motion::{MotionLaw, Spline};
pub use spec::MechanismSpec;

/// Index of a mobile body (its coordinates are `x[3i..3i+3]`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct BodyId(pub usize);
/// Index of a kinematic pair.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct PairId(pub usize);
/// Index of a named point.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct PointId(pub usize);

/// A body taking part in a pair or a load: the fixed ground or a mobile body.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Link {
    Ground,
    Body(BodyId),
}

/// A mobile rigid body.
#[derive(Debug, Clone, PartialEq)]
pub struct Body {
    pub name: String,
    /// Mass (kg), > 0.
    pub mass: f64,
    /// Moment of inertia about the centre of mass (kg m^2), > 0.
    pub inertia: f64,
    /// Centre of mass in the drawing (m).
    pub com0: [f64; 2],
    /// Body angle in the drawing (rad): the angle of the line from its first to its second point.
    pub angle0: f64,
    /// The points it carries, with their coordinates in the body frame (m).
    pub points: Vec<(PointId, [f64; 2])>,
}

/// The kind of a kinematic pair.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum PairKind {
    /// Hinge: the two copies of the pair point coincide.
    Revolute,
    /// Slider: no relative rotation, b's copy of the point stays on a line fixed to a.
    Prismatic {
        /// Unit direction of the guide in a's frame.
        axis: [f64; 2],
    },
    /// Gears (or a pinion and a rack) rolling without slip: [`pairs::gear`].
    Gear(pairs::gear::Gear),
    /// A pin of b in a slot of a: [`pairs::slot`].
    Slot(pairs::slot::Slot),
}

/// A kinematic pair between links `a` and `b` at a point both carry (a gear pair: at the
/// two gear centres, `sa` and `sb`).
#[derive(Debug, Clone, PartialEq)]
pub struct Pair {
    pub name: String,
    pub kind: PairKind,
    pub a: Link,
    pub b: Link,
    pub point: PointId,
    /// The pair point in a's and b's frames (m).
    pub sa: [f64; 2],
    pub sb: [f64; 2],
    /// Drawn relative angle phi_b - phi_a (rad).
    pub rel_angle0: f64,
}

/// What a generalized coordinate measures.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum CoordinateKind {
    /// Relative angle of a revolute pair (rad).
    Angle,
    /// Displacement along a prismatic pair (m).
    Displacement,
}

impl CoordinateKind {
    /// Its name where a binding shows it: `angle` or `displacement`.
    pub fn name(self) -> &'static str {
        match self {
            CoordinateKind::Angle => "angle",
            CoordinateKind::Displacement => "displacement",
        }
    }
}

/// A generalized coordinate `q_k`: the relative motion of an input pair, offset to equal
/// `value` in the drawing.
#[derive(Debug, Clone, PartialEq)]
pub struct Coordinate {
    pub name: String,
    pub pair: PairId,
    pub kind: CoordinateKind,
    /// Value in the drawing (rad or m).
    pub value: f64,
    /// Start value (rad or m); the drawing's value unless the file gives `q0`.
    pub q0: f64,
    /// Initial rate (rad/s or m/s).
    pub qd0: f64,
    /// The pair's relative coordinate as a difference of two entries of x, where it is one
    /// (`pairs::linear_coordinate`): a drive's effort through it at every evaluation.
    pub linear: Option<pairs::LinearCoordinate>,
}

/// Largest move one continuation of the position analysis may make (rad, or lengths L for
/// a displacement), for the model's `q0` and every API call alike: with its steps of at most
/// 0.1 (`kinematics::position`) it bounds a call to ~10^4 position solves (well under a
/// second), where an unbounded target such as 1e15 rad would never return. A longer way is
/// a sequence of calls, each from the last.
pub const MAX_CONTINUATION_DISTANCE: f64 = 1e3;

/// A drive effort law on one coordinate (N m for an angle, N for a displacement).
#[derive(Debug, Clone, PartialEq)]
pub enum DriveLaw {
    Constant(f64),
    /// Linear interpolation in time, held constant outside `t[0]..t[last]`.
    Table {
        t: Vec<f64>,
        effort: Vec<f64>,
    },
}

impl DriveLaw {
    /// The effort at time `t` (s). Inlined, a constant; a table's lookup out of line.
    #[inline]
    pub fn effort(&self, t: f64) -> f64 {
        match self {
            DriveLaw::Constant(value) => *value,
            DriveLaw::Table { t: times, effort } => table_effort(times, effort, t),
        }
    }
}

/// The effort at time `t` (s) of a table (`DriveLaw::Table`).
#[inline(never)]
fn table_effort(times: &[f64], effort: &[f64], t: f64) -> f64 {
    let last = times.len() - 1;
    if t <= times[0] {
        return effort[0];
    }
    if t >= times[last] {
        return effort[last];
    }
    let k = times.partition_point(|&ti| ti <= t).min(last);
    let s = (t - times[k - 1]) / (times[k] - times[k - 1]);
    effort[k - 1] + s * (effort[k] - effort[k - 1])
}

/// A point of a link: the link and the point's coordinates in the link frame (m).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Attachment {
    pub link: Link,
    pub s: [f64; 2],
}

/// Default simulation settings read from the model file.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct SimulateDefaults {
    pub t_end: Option<f64>,
    pub method: Option<String>,
    pub rtol: Option<f64>,
    pub atol: Option<f64>,
    pub dt: Option<f64>,
    pub output_dt: Option<f64>,
}

impl SimulateDefaults {
    /// The end time of a run when neither the model nor the caller gives one (s).
    pub const T_END: f64 = 1.0;
}

/// An immutable, validated planar mechanism.
#[derive(Debug, Clone, PartialEq)]
pub struct Mechanism {
    pub name: String,
    /// Where it was loaded from (a path or `<string>`), used in messages.
    pub source: String,
    /// The specification it was built from, kept so results can record their model.
    pub spec: MechanismSpec,
    /// Gravity (m/s^2).
    pub gravity: [f64; 2],
    /// Point names and drawn coordinates (m).
    pub points: Vec<(String, [f64; 2])>,
    /// Points the ground carries.
    pub ground_points: Vec<PointId>,
    pub bodies: Vec<Body>,
    pub pairs: Vec<Pair>,
    pub coordinates: Vec<Coordinate>,
    /// One drive law per coordinate (`None`: no drive).
    pub drives: Vec<Option<DriveLaw>>,
    /// One motion law per coordinate (`None`: the coordinate moves freely under its effort).
    pub motions: Vec<Option<MotionLaw>>,
    pub loads: Vec<Load>,
    /// One motor and transmission slot per coordinate (`None`: an ideal effort source).
    pub actuators: Vec<Option<Actuator>>,
    /// Redundant actuators on pairs that are not coordinates (the coordinates count as
    /// actuated too when there are any).
    pub pair_actuators: Vec<PairActuator>,
    /// Coulomb friction from the pairs' loads.
    pub friction: Vec<JointFriction>,
    /// Transmission, pair and link compliances (empty: rigid), for `crate::elastic`.
    pub compliance: compliance::Compliance,
    pub simulate: SimulateDefaults,
    /// Body coordinates in the drawing, 3n values [X, Y, phi] per body.
    pub x0: Vec<f64>,
    /// Characteristic length (m): the largest distance between two points; it scales
    /// tolerances and makes the singularity measure dimensionless.
    pub scale: f64,
    /// Where pair k's constraint rows start among all pair rows (`pair_rows`): p + 1
    /// offsets, the last one the number of pair rows.
    pub pair_row_start: Vec<usize>,
    /// Where each pair-constraint row goes in the position equations F; `None`
    /// for a redundant row (implied by the others, e.g. in a parallelogram), left out so
    /// that J stays square.
    pub row_slot: Vec<Option<usize>>,
    /// `row_slot` by pair: where each pair's rows go in F (unused entries None), for the
    /// assembler's hot loops.
    pub pair_slots: Vec<[Option<usize>; 2]>,
    /// Number of independent pair constraints kept: 3n - m.
    pub n_constraints: usize,
    /// Things a user should know about the model (redundant constraints...).
    pub warnings: Vec<String>,
}

impl Mechanism {
    /// The mechanism as drawn, with every check that needs no mechanics (the loader's
    /// `build` adds the mobility, the assembly and the simulation defaults).
    pub(crate) fn drawing(spec: MechanismSpec, source: &str) -> Result<Self, crate::ModelError> {
        build::drawing(spec, source)
    }
    /// Number of degrees of freedom m (= number of generalized coordinates).
    pub fn dof(&self) -> usize {
        self.coordinates.len()
    }
    /// Whether forward and inverse dynamics need the transmissions or the load-dependent
    /// friction (`dynamics::losses`).
    pub fn has_losses(&self) -> bool {
        !self.friction.is_empty()
            || self.actuators.iter().any(Option::is_some)
            || self.pair_actuators.iter().any(|a| a.drive.is_some())
    }
    /// The same mechanism with the raw relative coordinates of `pairs` (indices into `pairs`,
    /// revolute) as its coordinates, value 0 (`pairs::coordinate`), at rest, without drives,
    /// motions, actuators or friction: the kinematics of another chart of it
    /// (`kinematics::alt_charts`), not a model to simulate.
    pub fn with_pair_coordinates(&self, pairs: &[usize]) -> Mechanism {
        let coordinates = pairs
            .iter()
            .map(|&i| Coordinate {
                name: self.pairs[i].name.clone(),
                pair: PairId(i),
                kind: CoordinateKind::Angle,
                value: 0.0,
                q0: 0.0,
                qd0: 0.0,
                linear: pairs::linear_coordinate(&self.pairs[i]),
            })
            .collect();
        let m = pairs.len();
        Mechanism {
            coordinates,
            drives: vec![None; m],
            motions: vec![None; m],
            actuators: vec![None; m],
            pair_actuators: Vec::new(),
            friction: Vec::new(),
            ..self.clone()
        }
    }
    /// Number of actuators n_a: the coordinates, then the pair actuators.
    pub fn n_actuators(&self) -> usize {
        self.dof() + self.pair_actuators.len()
    }
    /// The actuators' names: the coordinates', then the pair actuators'.
    pub fn actuator_names(&self) -> Vec<String> {
        let coords = self.coordinates.iter().map(|c| c.name.clone());
        coords.chain(self.pair_actuators.iter().map(|a| a.name.clone())).collect()
    }
    /// Number of mobile bodies n.
    pub fn n_bodies(&self) -> usize {
        self.bodies.len()
    }
    /// Number of body coordinates, 3n.
    pub fn n_x(&self) -> usize {
        3 * self.bodies.len()
    }
    /// Number of pair-constraint rows of all pairs, redundant ones included.
    pub fn n_pair_rows(&self) -> usize {
        self.pair_row_start.last().copied().unwrap_or(0)
    }
    /// The rows of pair `k` among all pair-constraint rows (`0..n_pair_rows()`).
    #[inline]
    pub fn pair_rows(&self, k: PairId) -> std::ops::Range<usize> {
        self.pair_row_start[k.0]..self.pair_row_start[k.0 + 1]
    }
    /// A row placement (`row_slot`, or all rows) gathered by pair: entry k holds where pair
    /// k's rows go (None past its row count).
    pub fn slots_by_pair(&self, row_slot: &[Option<usize>]) -> Vec<[Option<usize>; 2]> {
        (0..self.pairs.len())
            .map(|k| {
                let mut slots = [None; 2];
                for (s, r) in slots.iter_mut().zip(&row_slot[self.pair_rows(PairId(k))]) {
                    *s = *r;
                }
                slots
            })
            .collect()
    }
    /// The pair a pair-constraint row belongs to.
    pub fn row_pair(&self, row: usize) -> PairId {
        PairId(self.pair_row_start.partition_point(|&s| s <= row) - 1)
    }
    pub fn coordinate_names(&self) -> Vec<&str> {
        self.coordinates.iter().map(|c| c.name.as_str()).collect()
    }
    pub fn body_names(&self) -> Vec<&str> {
        self.bodies.iter().map(|b| b.name.as_str()).collect()
    }
    pub fn pair_names(&self) -> Vec<&str> {
        self.pairs.iter().map(|p| p.name.as_str()).collect()
    }
    pub fn point_names(&self) -> Vec<&str> {
        self.points.iter().map(|p| p.0.as_str()).collect()
    }
    /// Start coordinates q0 and rates qd0.
    pub fn initial_state(&self) -> (Vec<f64>, Vec<f64>) {
        let q0 = self.coordinates.iter().map(|c| c.q0).collect();
        let qd0 = self.coordinates.iter().map(|c| c.qd0).collect();
        (q0, qd0)
    }
    /// Coordinate values in the drawing.
    pub fn drawn_q(&self) -> Vec<f64> {
        self.coordinates.iter().map(|c| c.value).collect()
    }
    /// Look a point up by name.
    pub fn point_id(&self, name: &str) -> Option<PointId> {
        self.points.iter().position(|p| p.0 == name).map(PointId)
    }
    /// The link that carries a point (ground first, then the bodies in order) and where, or
    /// None for a point no link carries (declared, unused).
    pub fn carrier(&self, point: PointId) -> Option<Attachment> {
        std::iter::once(Link::Ground)
            .chain((0..self.n_bodies()).map(|b| Link::Body(BodyId(b))))
            .find_map(|link| self.attachment(link, point))
    }
    /// Look a body up by name.
    pub fn body_id(&self, name: &str) -> Option<BodyId> {
        self.bodies.iter().position(|b| b.name == name).map(BodyId)
    }
    /// Where a link carries a point (the point's coordinates in the link frame), if it does.
    pub fn attachment(&self, link: Link, point: PointId) -> Option<Attachment> {
        match link {
            Link::Ground => self.ground_points.contains(&point).then(|| Attachment { link, s: self.points[point.0].1 }),
            Link::Body(b) => {
                self.bodies[b.0].points.iter().find(|(p, _)| *p == point).map(|&(_, s)| Attachment { link, s })
            }
        }
    }
    /// Link name (`ground` or the body's).
    pub fn link_name(&self, link: Link) -> &str {
        match link {
            Link::Ground => "ground",
            Link::Body(b) => &self.bodies[b.0].name,
        }
    }
}
