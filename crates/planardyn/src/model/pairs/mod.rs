//! Pair kinds: what each kind of kinematic pair contributes to the position equations,
//! one file a kind. The assembler (`constraints`, `system`, `dynamics::reactions`) walks the
//! pairs and asks them through the functions below; only this file's `dispatch!` looks at
//! the kind, and it calls the kind's module statically (no dynamic dispatch in the hot loop).
//!
//! A kind has 1 or 2 constraint rows ([`PairType::ROWS`]); the rows of all pairs are laid
//! out one pair after the other (`Mechanism::pair_rows`). Row values are passed as [`Rows`],
//! of which the first `ROWS` entries are meaningful.
//!
//! Adding a kind: a file here implementing [`PairType`], a variant of `model::PairKind`
//! with an arm in `dispatch!`, its `PairSpec` variant and validation in `model`, the schema
//! and `docs/model-format.md`.

pub mod frames;
pub mod gear;
pub mod prismatic;
pub mod revolute;
pub mod slot;

use crate::linalg::Sink;
use crate::model::{CoordinateKind, JointFriction, Mechanism, Pair, PairId, PairKind};
use frames::{link_columns, link_state, Projection};
use gear::Side;

/// Values of a pair's rows (the first `ROWS` entries).
pub type Rows = [f64; 2];

/// The relative coordinate a pair offers as an input (or to a pair spring).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Relative {
    /// phi_b - phi_a - (drawn value) (rad).
    Angle,
    /// Displacement of b's pair point along the unit direction `axis` fixed in a (m),
    /// measured from a's copy of the point.
    Along { axis: [f64; 2] },
}

/// How a pair is drawn at a configuration, in world coordinates (m).
#[derive(Debug, Clone, PartialEq)]
pub struct PairGeometry {
    /// `revolute`, `prismatic`, `gear`, `slot`.
    pub kind: &'static str,
    /// Pin joints (circles).
    pub pins: Vec<[f64; 2]>,
    /// Sliding blocks (squares).
    pub blocks: Vec<[f64; 2]>,
    /// Guides, slots and rack pitch lines: segments [from, to].
    pub lines: Vec<[[f64; 2]; 2]>,
    /// Pitch circles: centre and radius.
    pub circles: Vec<([f64; 2], f64)>,
}

impl PairGeometry {
    fn new(kind: &'static str) -> Self {
        PairGeometry { kind, pins: vec![], blocks: vec![], lines: vec![], circles: vec![] }
    }
}

/// The field of its own a Coulomb friction entry takes on a pair kind, beside `mu` (and the
/// pin radius of a pair that turns).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum FrictionField {
    /// None: the contact load is the reaction force.
    None,
    /// `length` (m): the guide's bearing length, over which the pair's couple presses the
    /// block's ends.
    Length,
    /// `pressure_angle` (rad): the teeth's, the mesh's normal load being its force over the
    /// angle's cosine. The friction's lever is the pitch-line travel, not a relative coordinate.
    PressureAngle,
}

/// What a pair kind provides. `x` holds the body coordinates, `trig` their [cos, sin]
/// (`constraints::body_trig`), `rows` where each of the kind's rows goes in F (None: a
/// redundant row, left out).
pub trait PairType {
    /// Name in the model file (`type:`).
    const NAME: &'static str;
    /// Number of constraint rows: 1 or 2.
    const ROWS: usize;
    /// Its letter in the type of an Assur group (`RRP`...): R and P for the lower pairs, G
    /// (gear) and S (pin-in-slot) for the one-row higher pairs.
    const LETTER: char;
    /// The field of its own a Coulomb friction entry on the kind takes (checked where the
    /// entry is read, model/loads/friction.rs; used by `contact_load`).
    const FRICTION_FIELD: FrictionField;
    /// Residual of the rows.
    fn residual(&self, pair: &Pair, x: &[f64], trig: &[[f64; 2]]) -> Rows;
    /// Gradients of the rows, added into `j`.
    fn jacobian<S: Sink>(&self, pair: &Pair, x: &[f64], trig: &[[f64; 2]], j: &mut S, rows: [Option<usize>; 2]);
    /// Second derivatives of the rows as bilinear forms gamma(u, v).
    fn gamma(&self, pair: &Pair, x: &[f64], trig: &[[f64; 2]], u: &[f64], v: &[f64]) -> Rows;
    /// Third derivatives of the rows as trilinear forms gamma3(u, v, t) (symmetric).
    fn gamma3(&self, pair: &Pair, x: &[f64], trig: &[[f64; 2]], u: &[f64], v: &[f64], t: &[f64]) -> Rows;
    /// Row scales: `inv_l` (1/L) for rows in metres, 1 for rows in radians.
    fn row_scales(&self, inv_l: f64) -> Rows;
    /// The columns of x each row may touch (its sparsity pattern), ascending.
    fn pattern(&self, pair: &Pair, row: usize) -> Vec<usize>;
    /// The relative coordinate, if the pair can be an input (None: it cannot).
    fn relative(&self) -> Option<Relative>;
    /// [F_x, F_y, M]: the force (N) and couple (N m) a exerts on b, reduced to b's pair
    /// point, from the rows' multipliers `mu` (the force on the bodies is Phi_x^T mu).
    fn reaction(&self, pair: &Pair, x: &[f64], mu: Rows) -> [f64; 3];
    /// What the drawings show, with `scale` the mechanism's characteristic length.
    fn geometry(&self, pair: &Pair, x: &[f64], scale: f64) -> PairGeometry;

    // The friction hooks (docs/actuators.md, *Friction from the joint loads*; used by
    // `dynamics::friction` and `dynamics::losses`), without a default: a new kind states its
    // own, or does not compile.
    /// The load N (N) that presses the pair's surfaces together, from its reaction
    /// [F_x, F_y, M] (N, N m) and its friction entry `fr`.
    fn contact_load(&self, fr: &JointFriction, reaction: [f64; 3]) -> f64;
    /// The lever the friction acts along, on `side` of the pair (its relative coordinate; a
    /// gear mesh's pitch-line travel of the gear on `side`): its gradient along x added into
    /// row 0 of `j`; returns its rate at xd (rad/s or m/s).
    fn slip_lever<S: Sink>(&self, pair: &Pair, x: &[f64], xd: &[f64], side: Side, j: &mut S) -> f64;
    /// The side whose lever carries the friction under `reaction` at the lever's `rate`: a
    /// gear mesh's driver, `Side::A` for a kind with one lever.
    fn slip_side(&self, x: &[f64], reaction: [f64; 3], rate: f64) -> Side;

    // The relative coordinate (`relative`): its value less the drawn one, gradient (added into
    // row `row` of `j`), second and third derivatives as multilinear forms, and rate at xd.
    // Each kind writes its own: a revolute pair's from the two angles alone, a kind measured
    // along a guide by [`along_coordinate!`]; a kind without one returns 0 (never reached:
    // the model refuses a coordinate or a pair spring on it).
    fn coordinate(&self, pair: &Pair, x: &[f64]) -> f64;
    fn coordinate_grad<S: Sink>(&self, pair: &Pair, x: &[f64], j: &mut S, row: usize);
    fn coordinate_gamma(&self, pair: &Pair, x: &[f64], u: &[f64], v: &[f64]) -> f64;
    fn coordinate_gamma3(&self, pair: &Pair, x: &[f64], u: &[f64], v: &[f64], t: &[f64]) -> f64;
    fn coordinate_rate(&self, pair: &Pair, x: &[f64], xd: &[f64]) -> f64;
    /// The relative coordinate as a [`LinearCoordinate`] where it is one (a revolute pair's
    /// angle), else None.
    fn linear_coordinate(&self, pair: &Pair) -> Option<LinearCoordinate>;
}

/// The relative-coordinate methods of [`PairType`] for a kind whose coordinate is the
/// displacement of b's pair point along its `axis` field (fixed in a), measured from a's copy
/// of the point (`Relative::Along`): the prismatic pair and the pin in a slot. Out of line,
/// so that the dispatch below stays small enough to inline where a revolute pair's is a
/// subtraction (a drive's or a pair spring's effort and rate at every evaluation).
macro_rules! along_coordinate {
    () => {
        #[inline(never)]
        fn coordinate(&self, pair: &Pair, x: &[f64]) -> f64 {
            super::along(pair, self.axis, x).value()
        }
        #[inline(never)]
        fn coordinate_grad<S: Sink>(&self, pair: &Pair, x: &[f64], j: &mut S, row: usize) {
            super::along(pair, self.axis, x).grad(j, row, 1.0)
        }
        #[inline(never)]
        fn coordinate_gamma(&self, pair: &Pair, x: &[f64], u: &[f64], v: &[f64]) -> f64 {
            super::along(pair, self.axis, x).gamma(u, v)
        }
        #[inline(never)]
        fn coordinate_gamma3(&self, pair: &Pair, x: &[f64], u: &[f64], v: &[f64], t: &[f64]) -> f64 {
            super::along(pair, self.axis, x).gamma3(u, v, t)
        }
        #[inline(never)]
        fn coordinate_rate(&self, pair: &Pair, x: &[f64], xd: &[f64]) -> f64 {
            super::along(pair, self.axis, x).rate(xd)
        }
        // The displacement along a turning guide is not linear in x.
        fn linear_coordinate(&self, _pair: &Pair) -> Option<super::LinearCoordinate> {
            None
        }
    };
}
pub(crate) use along_coordinate;

/// Call `$body` with `$t` bound to the pair kind's [`PairType`] value.
macro_rules! dispatch {
    ($kind:expr, $t:ident => $body:expr) => {
        match $kind {
            PairKind::Revolute => {
                let $t = revolute::Revolute;
                $body
            }
            PairKind::Prismatic { axis } => {
                let $t = prismatic::Prismatic { axis: *axis };
                $body
            }
            PairKind::Gear(g) => {
                let $t = *g;
                $body
            }
            PairKind::Slot(s) => {
                let $t = *s;
                $body
            }
        }
    };
}

/// Type name of a pair's kind (as in the model file).
pub fn kind_name(pair: &Pair) -> &'static str {
    fn name<T: PairType>(_: &T) -> &'static str {
        T::NAME
    }
    dispatch!(&pair.kind, t => name(&t))
}

/// Letter of a pair kind in an Assur group's type.
pub fn letter(kind: &PairKind) -> char {
    fn letter<T: PairType>(_: &T) -> char {
        T::LETTER
    }
    dispatch!(kind, t => letter(&t))
}

/// The friction entry's field of its own on a pair kind.
pub fn friction_field(kind: &PairKind) -> FrictionField {
    fn field<T: PairType>(_: &T) -> FrictionField {
        T::FRICTION_FIELD
    }
    dispatch!(kind, t => field(&t))
}

/// Number of constraint rows of a pair.
#[inline]
pub fn n_rows(kind: &PairKind) -> usize {
    fn rows<T: PairType>(_: &T) -> usize {
        T::ROWS
    }
    dispatch!(kind, t => rows(&t))
}

#[inline]
pub fn residual(pair: &Pair, x: &[f64], trig: &[[f64; 2]]) -> Rows {
    dispatch!(&pair.kind, t => t.residual(pair, x, trig))
}

#[inline]
pub fn jacobian<S: Sink>(pair: &Pair, x: &[f64], trig: &[[f64; 2]], j: &mut S, rows: [Option<usize>; 2]) {
    dispatch!(&pair.kind, t => t.jacobian(pair, x, trig, j, rows))
}

#[inline]
pub fn gamma(pair: &Pair, x: &[f64], trig: &[[f64; 2]], u: &[f64], v: &[f64]) -> Rows {
    dispatch!(&pair.kind, t => t.gamma(pair, x, trig, u, v))
}

#[inline]
pub fn gamma3(pair: &Pair, x: &[f64], trig: &[[f64; 2]], u: &[f64], v: &[f64], t: &[f64]) -> Rows {
    dispatch!(&pair.kind, k => k.gamma3(pair, x, trig, u, v, t))
}

#[inline]
pub fn row_scales(pair: &Pair, inv_l: f64) -> Rows {
    dispatch!(&pair.kind, t => t.row_scales(inv_l))
}

pub fn pattern(pair: &Pair, row: usize) -> Vec<usize> {
    dispatch!(&pair.kind, t => t.pattern(pair, row))
}

#[inline]
pub fn relative(pair: &Pair) -> Option<Relative> {
    dispatch!(&pair.kind, t => t.relative())
}

pub fn reaction(pair: &Pair, x: &[f64], mu: Rows) -> [f64; 3] {
    dispatch!(&pair.kind, t => t.reaction(pair, x, mu))
}

/// What the drawings show of a pair at body coordinates x.
pub fn geometry(pair: &Pair, x: &[f64], scale: f64) -> PairGeometry {
    dispatch!(&pair.kind, t => t.geometry(pair, x, scale))
}

/// What the drawings show of every pair of a mechanism at body coordinates x (3n).
pub fn pair_geometry(mech: &Mechanism, x: &[f64]) -> Vec<PairGeometry> {
    mech.pairs.iter().map(|p| geometry(p, x, mech.scale)).collect()
}

/// The kind of generalized coordinate a pair's relative coordinate is, if it has one.
pub fn coordinate_kind(pair: &Pair) -> Option<CoordinateKind> {
    relative(pair).map(|r| match r {
        Relative::Angle => CoordinateKind::Angle,
        Relative::Along { .. } => CoordinateKind::Displacement,
    })
}

/// The columns the relative coordinate's gradient may touch: both links' angles for an
/// angle, all their columns for a displacement.
pub fn coordinate_pattern(pair: &Pair) -> Vec<usize> {
    let angle_only = relative(pair) == Some(Relative::Angle);
    let mut cols: Vec<usize> = link_columns(pair.a, angle_only).chain(link_columns(pair.b, angle_only)).collect();
    cols.sort_unstable();
    cols
}

/// The projection along `axis` (fixed in a) of b's pair point.
fn along(pair: &Pair, axis: [f64; 2], x: &[f64]) -> Projection {
    Projection::new(pair.sa, pair.sb, axis, link_state(pair.a, x), link_state(pair.b, x))
}

/// Relative coordinate of a pair from the drawing: angle (rad) or displacement (m).
#[inline(always)]
pub fn coordinate(pair: &Pair, x: &[f64]) -> f64 {
    dispatch!(&pair.kind, t => t.coordinate(pair, x))
}

/// |F| (N) of a reaction [F_x, F_y, M]: the contact load of the kinds without a couple's
/// share in it.
#[inline]
fn reaction_force(reaction: [f64; 3]) -> f64 {
    reaction[0].hypot(reaction[1])
}

/// The friction lever of a kind whose friction acts along its relative coordinate: the
/// coordinate's gradient added into row 0 of `j`; returns its rate at xd.
#[inline]
fn coordinate_lever<T: PairType, S: Sink>(t: &T, pair: &Pair, x: &[f64], xd: &[f64], j: &mut S) -> f64 {
    t.coordinate_grad(pair, x, j, 0);
    t.coordinate_rate(pair, x, xd)
}

/// [`PairType::contact_load`] of the pair's kind.
#[inline]
pub fn contact_load(pair: &Pair, fr: &JointFriction, reaction: [f64; 3]) -> f64 {
    dispatch!(&pair.kind, t => t.contact_load(fr, reaction))
}

/// [`PairType::slip_lever`] of the pair's kind.
#[inline]
pub fn slip_lever<S: Sink>(pair: &Pair, x: &[f64], xd: &[f64], side: Side, j: &mut S) -> f64 {
    dispatch!(&pair.kind, t => t.slip_lever(pair, x, xd, side, j))
}

/// [`PairType::slip_side`] of the pair's kind.
#[inline]
pub fn slip_side(pair: &Pair, x: &[f64], reaction: [f64; 3], rate: f64) -> Side {
    dispatch!(&pair.kind, t => t.slip_side(x, reaction, rate))
}

/// Gradient of [`coordinate`], added into row `row` of `j`.
#[inline(always)]
pub fn coordinate_grad<S: Sink>(pair: &Pair, x: &[f64], j: &mut S, row: usize) {
    dispatch!(&pair.kind, t => t.coordinate_grad(pair, x, j, row))
}

/// Second derivative of [`coordinate`] as a bilinear form.
#[inline]
pub fn coordinate_gamma(pair: &Pair, x: &[f64], u: &[f64], v: &[f64]) -> f64 {
    dispatch!(&pair.kind, t => t.coordinate_gamma(pair, x, u, v))
}

/// Third derivative of [`coordinate`] as a trilinear form.
#[inline]
pub fn coordinate_gamma3(pair: &Pair, x: &[f64], u: &[f64], v: &[f64], t: &[f64]) -> f64 {
    dispatch!(&pair.kind, k => k.coordinate_gamma3(pair, x, u, v, t))
}

/// f += effort * (a pair coordinate's gradient), as the kind writes the gradient's entries.
struct Effort<'a> {
    f: &'a mut [f64],
    effort: f64,
}

impl Sink for Effort<'_> {
    #[inline(always)]
    fn add(&mut self, _row: usize, col: usize, v: f64) {
        self.f[col] += self.effort * v;
    }
}

/// A generalized effort on a pair's relative coordinate, `effort(value, rate)` of the
/// coordinate's value and rate at (x, xd), added along its gradient into f (3n values; a
/// revolute pair's -1 and +1 on its links' angles: f - effort and f + effort, exactly).
/// One dispatch on the kind for the three (a pair spring's or a drive's, at every
/// evaluation). Returns the effort and the rate.
#[inline(always)]
pub fn add_coordinate_effort(
    pair: &Pair,
    x: &[f64],
    xd: &[f64],
    f: &mut [f64],
    effort: impl FnOnce(f64, f64) -> f64,
) -> (f64, f64) {
    dispatch!(&pair.kind, t => {
        let rate = t.coordinate_rate(pair, x, xd);
        let effort = effort(t.coordinate(pair, x), rate);
        t.coordinate_grad(pair, x, &mut Effort { f, effort }, 0);
        (effort, rate)
    })
}

/// A relative coordinate that is a difference of two entries of x, less its drawn value: a
/// revolute pair's angle x[plus] - x[minus] - offset (the ground's angle 0: no column), its
/// gradient +1 at `plus` and -1 at `minus`, its rate the same difference along xd. Its columns
/// are found once, where the model is built (`PairType::linear_coordinate`), for the efforts
/// of [`LinearCoordinate::add_effort`] at every evaluation.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LinearCoordinate {
    pub minus: Option<usize>,
    pub plus: Option<usize>,
    pub offset: f64,
}

impl LinearCoordinate {
    /// [`add_coordinate_effort`] of the pair whose coordinate this is: the same operations
    /// (rate, value, then f - effort at `minus` and f + effort at `plus`, as the gradient's
    /// -1 and +1 times the effort), so the same numbers.
    #[inline(always)]
    pub fn add_effort(&self, x: &[f64], xd: &[f64], f: &mut [f64], effort: impl FnOnce(f64, f64) -> f64) -> (f64, f64) {
        let add = |minus: Option<usize>, plus: Option<usize>| {
            let at = |v: &[f64], c: Option<usize>| c.map_or(0.0, |c| v[c]);
            let rate = at(xd, plus) - at(xd, minus);
            let effort = effort(at(x, plus) - at(x, minus) - self.offset, rate);
            // f + effort * -1 and f + effort * 1 of the generic code: f - effort and f + effort.
            if let Some(c) = minus {
                f[c] -= effort;
            }
            if let Some(c) = plus {
                f[c] += effort;
            }
            (effort, rate)
        };
        // One test of which links are the ground, each case's code without any.
        match (self.minus, self.plus) {
            (Some(a), Some(b)) => add(Some(a), Some(b)),
            (None, Some(b)) => add(None, Some(b)),
            (a, None) => add(a, None),
        }
    }
}

/// A pair's relative coordinate as a [`LinearCoordinate`], where it is one.
pub fn linear_coordinate(pair: &Pair) -> Option<LinearCoordinate> {
    dispatch!(&pair.kind, t => t.linear_coordinate(pair))
}

/// [`add_coordinate_effort`] of pair `pair` of `pairs`, through `linear` where the coordinate
/// is one (the pair's own [`linear_coordinate`]).
#[inline(always)]
pub fn add_effort(
    linear: Option<&LinearCoordinate>,
    pairs: &[Pair],
    pair: PairId,
    x: &[f64],
    xd: &[f64],
    f: &mut [f64],
    effort: impl FnOnce(f64, f64) -> f64,
) -> (f64, f64) {
    match linear {
        Some(l) => l.add_effort(x, xd, f, effort),
        None => add_coordinate_effort(&pairs[pair.0], x, xd, f, effort),
    }
}

/// Rate of [`coordinate`]: its gradient times xd.
#[inline(always)]
pub fn coordinate_rate(pair: &Pair, x: &[f64], xd: &[f64]) -> f64 {
    dispatch!(&pair.kind, t => t.coordinate_rate(pair, x, xd))
}

/// The block drawn on a guide of direction `axis` (in a's frame) through b's pair point:
/// the guide +-0.3 L about it.
fn guide(pair: &Pair, axis: [f64; 2], x: &[f64], scale: f64, g: &mut PairGeometry) {
    let (a, b) = (link_state(pair.a, x), link_state(pair.b, x));
    let p = b.point(pair.sb);
    let d = a.rot(axis);
    let h = 0.3 * scale;
    g.blocks.push(p);
    g.lines.push([[p[0] - h * d[0], p[1] - h * d[1]], [p[0] + h * d[0], p[1] + h * d[1]]]);
}
