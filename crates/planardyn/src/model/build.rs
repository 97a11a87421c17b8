//! Validation of a [`MechanismSpec`] into a [`Mechanism`]: every name resolves, masses and
//! inertias are positive, the mobility equals the number of coordinates, the constraints are
//! independent in the drawing, and the mechanism assembles at its start coordinates.

use super::spec::{BodySpec, DriveSpec, LoadSpec, Location, PairSpec, PartSpec, SimulateSpec};
use super::*;
use crate::kinematics::assemble;
use crate::structure::constraint_rank;
use crate::ModelError;

/// Collects the context for error messages: the source name.
struct Ctx<'a> {
    source: &'a str,
    spec: &'a MechanismSpec,
}

type R<T> = Result<T, ModelError>;

/// Largest drawn coordinate accepted (m): beyond it squared lengths overflow and the
/// numbers cannot describe a machine.
const MAX_COORDINATE: f64 = 1e9;
/// Largest move from the drawing to `q0` (rad, or multiples of the drawing's size): the
/// continuation takes steps of 0.1, so this bounds the loading time (~10^4 steps).
const MAX_START_MOVE: f64 = 1e3;
/// Largest magnitude of any other number (SI): products of a few model numbers (m u^2,
/// qd^2 L, tau / A) then stay far from overflowing a double (1.8e308).
const MAX_MAGNITUDE: f64 = 1e30;
/// Smallest total mass (kg) and inertia (kg m^2) of a body: with efforts up to
/// MAX_MAGNITUDE the accelerations stay finite (the fuzz found NaN with 1e308 kg).
const MIN_MASS: f64 = 1e-30;

impl Ctx<'_> {
    fn err(&self, path: impl Into<String>, message: impl Into<String>) -> ModelError {
        ModelError::Invalid { source_name: self.source.to_string(), path: path.into(), message: message.into() }
    }
    fn point(&self, path: &str, name: &str) -> R<PointId> {
        self.spec.points.0.get_index_of(name).map(PointId).ok_or_else(|| {
            let known: Vec<&str> = self.spec.points.0.keys().map(String::as_str).collect();
            self.err(
                path,
                format!(
                    "unknown point '{name}'; points are: {} (use one of them, or add it to `points`)",
                    known.join(", ")
                ),
            )
        })
    }
    fn xy(&self, path: &str, name: &str) -> R<[f64; 2]> {
        self.point(path, name).map(|p| self.spec.points.0[p.0])
    }
    fn link(&self, path: &str, name: &str) -> R<Link> {
        if name == "ground" {
            return Ok(Link::Ground);
        }
        self.spec.bodies.0.get_index_of(name).map(|i| Link::Body(BodyId(i))).ok_or_else(|| {
            let known: Vec<&str> = self.spec.bodies.0.keys().map(String::as_str).collect();
            self.err(
                path,
                format!(
                    "unknown body '{name}'; bodies are: ground, {} (use one of them, or add it to `bodies`)",
                    known.join(", ")
                ),
            )
        })
    }
    /// A finite number of magnitude at most MAX_MAGNITUDE.
    fn finite(&self, path: &str, v: f64) -> R<f64> {
        if !v.is_finite() {
            return Err(self.err(path, format!("{v} is not a finite number; give a finite one")));
        }
        if v.abs() > MAX_MAGNITUDE {
            return Err(self.err(
                path,
                format!("{v:e} is beyond the largest magnitude accepted, {MAX_MAGNITUDE:e}: check the units (SI)"),
            ));
        }
        Ok(v)
    }
    fn non_negative(&self, path: &str, v: f64) -> R<f64> {
        if self.finite(path, v)? < 0.0 {
            return Err(self.err(path, format!("{v} is negative; it must be >= 0")));
        }
        Ok(v)
    }
}

pub(super) fn build(spec: MechanismSpec, source: &str) -> R<Mechanism> {
    let mut mech = drawing(spec, source)?;
    let spec = mech.spec.clone();
    let ctx = Ctx { source, spec: &spec };
    check_mobility(&ctx, &mut mech)?;
    check_assembly(&ctx, &mech)?;
    Ok(mech)
}

/// Every check but the mobility and the assembly: the mechanism as drawn, all its pair rows
/// kept, which the structural analysis of a model the loader refuses reads.
pub(super) fn drawing(spec: MechanismSpec, source: &str) -> R<Mechanism> {
    let ctx = Ctx { source, spec: &spec };
    if let Some(units) = &spec.units {
        if units != "SI" {
            return Err(ctx.err("units", format!("'{units}' is not supported; use SI (m, kg, s, rad)")));
        }
    }
    let gravity = [ctx.finite("gravity[0]", spec.gravity[0])?, ctx.finite("gravity[1]", spec.gravity[1])?];
    let mut points = Vec::new();
    for (name, xy) in &spec.points.0 {
        let path = format!("points.{name}");
        if name == "ground" {
            return Err(ctx.err(path, "'ground' is the fixed body's name; rename the point"));
        }
        let p = [ctx.finite(&path, xy[0])?, ctx.finite(&path, xy[1])?];
        if p[0].abs().max(p[1].abs()) > MAX_COORDINATE {
            return Err(ctx.err(
                path,
                format!("{p:?} is more than {MAX_COORDINATE:e} m from the origin: check the units (SI: metres)"),
            ));
        }
        points.push((name.clone(), p));
    }
    let mut ground_points = Vec::new();
    for (k, name) in spec.ground.iter().enumerate() {
        let p = ctx.point(&format!("ground[{k}]"), name)?;
        if ground_points.contains(&p) {
            return Err(ctx.err(format!("ground[{k}]"), format!("point '{name}' is listed twice; list it once")));
        }
        ground_points.push(p);
    }
    let bodies = spec.bodies.0.iter().map(|(name, b)| build_body(&ctx, name, b)).collect::<R<Vec<_>>>()?;
    let mut mech = Mechanism {
        name: spec.name.clone(),
        source: source.to_string(),
        spec: spec.clone(),
        gravity,
        points,
        ground_points,
        bodies,
        pairs: Vec::new(),
        coordinates: Vec::new(),
        drives: Vec::new(),
        loads: Vec::new(),
        simulate: SimulateDefaults::default(),
        x0: Vec::new(),
        scale: 1.0,
        row_slot: (0..2 * spec.pairs.len()).map(Some).collect(),
        n_constraints: 2 * spec.pairs.len(),
        warnings: Vec::new(),
    };
    mech.x0 = mech.bodies.iter().flat_map(|b| [b.com0[0], b.com0[1], b.angle0]).collect();
    mech.scale = characteristic_length(&mech.points);
    for (k, p) in spec.pairs.iter().enumerate() {
        let pair = build_pair(&ctx, &mech, k, p)?;
        if mech.pairs.iter().any(|q| q.name == pair.name) {
            return Err(ctx.err(
                format!("pairs[{k}].name"),
                format!("duplicate pair name '{}'; rename one of the two", pair.name),
            ));
        }
        mech.pairs.push(pair);
    }
    build_coordinates(&ctx, &mut mech)?;
    mech.drives = build_drives(&ctx, &mech, &spec.drives)?;
    mech.loads = spec.loads.iter().enumerate().map(|(k, l)| build_load(&ctx, &mech, k, l)).collect::<R<_>>()?;
    mech.simulate = build_simulate(&ctx, spec.simulate.as_ref())?;
    Ok(mech)
}

/// Mass, inertia and centre of mass of one part.
fn part_inertia(ctx: &Ctx, path: &str, p: &PartSpec) -> R<(f64, f64, [f64; 2])> {
    let mass = ctx.finite(&format!("{path}.mass"), p.mass)?;
    if !(mass > 0.0) {
        return Err(ctx.err(format!("{path}.mass"), format!("mass must be > 0 kg, got {mass}")));
    }
    let kinds = [p.com.is_some(), p.uniform_bar.is_some(), p.point_mass.is_some()];
    if kinds.iter().filter(|&&k| k).count() != 1 {
        return Err(
            ctx.err(path, "give exactly one of `com` (with `inertia`), `uniform_bar: [P, Q]` or `point_mass: P`")
        );
    }
    if let Some([a, b]) = &p.uniform_bar {
        if p.inertia.is_some() {
            return Err(ctx.err(format!("{path}.inertia"), "a uniform bar's inertia is m L^2/12; remove `inertia`"));
        }
        let (pa, pb) = (ctx.xy(&format!("{path}.uniform_bar[0]"), a)?, ctx.xy(&format!("{path}.uniform_bar[1]"), b)?);
        let l2 = (pb[0] - pa[0]).powi(2) + (pb[1] - pa[1]).powi(2);
        return Ok((mass, mass * l2 / 12.0, [(pa[0] + pb[0]) / 2.0, (pa[1] + pb[1]) / 2.0]));
    }
    if let Some(pt) = &p.point_mass {
        if p.inertia.is_some() {
            return Err(
                ctx.err(format!("{path}.inertia"), "a point mass has no inertia; remove `inertia` or use `com`")
            );
        }
        return Ok((mass, 0.0, ctx.xy(&format!("{path}.point_mass"), pt)?));
    }
    let inertia = p.inertia.ok_or_else(|| {
        ctx.err(format!("{path}.inertia"), "missing: add the moment of inertia about the centre of mass (kg m^2)")
    })?;
    let inertia = ctx.non_negative(&format!("{path}.inertia"), inertia)?;
    let com = match p.com.as_ref().expect("checked above") {
        Location::Coords(c) => [ctx.finite(&format!("{path}.com"), c[0])?, ctx.finite(&format!("{path}.com"), c[1])?],
        Location::Point(name) => ctx.xy(&format!("{path}.com"), name)?,
    };
    Ok((mass, inertia, com))
}

fn build_body(ctx: &Ctx, name: &str, b: &BodySpec) -> R<Body> {
    let path = format!("bodies.{name}");
    if name == "ground" {
        return Err(ctx.err(&path, "'ground' is the fixed body; list its points under the top-level `ground`"));
    }
    if b.points.is_empty() {
        return Err(ctx.err(format!("{path}.points"), "a body must carry at least one point"));
    }
    let own = PartSpec {
        mass: b.mass.unwrap_or(f64::NAN),
        inertia: b.inertia,
        com: b.com.clone(),
        uniform_bar: b.uniform_bar.clone(),
        point_mass: None,
    };
    let parts: Vec<(f64, f64, [f64; 2])> = match &b.parts {
        Some(parts) => {
            if b.mass.is_some() || b.inertia.is_some() || b.com.is_some() || b.uniform_bar.is_some() {
                return Err(ctx.err(&path, "give either `parts` or the body's own mass properties, not both"));
            }
            if parts.is_empty() {
                return Err(ctx.err(
                    format!("{path}.parts"),
                    "empty list of parts; add a part, or remove `parts` and give the body's own mass",
                ));
            }
            parts
                .iter()
                .enumerate()
                .map(|(k, p)| part_inertia(ctx, &format!("{path}.parts[{k}]"), p))
                .collect::<R<_>>()?
        }
        None => {
            if b.mass.is_none() {
                return Err(ctx.err(format!("{path}.mass"), "missing: add the body's mass (kg), or `parts`"));
            }
            vec![part_inertia(ctx, &path, &own)?]
        }
    };
    let mass: f64 = parts.iter().map(|p| p.0).sum();
    if !(mass >= MIN_MASS) {
        return Err(ctx.err(format!("{path}.mass"), format!("mass must be > 0 kg (at least {MIN_MASS:e}), got {mass}")));
    }
    let com = [
        parts.iter().map(|p| p.0 * p.2[0]).sum::<f64>() / mass,
        parts.iter().map(|p| p.0 * p.2[1]).sum::<f64>() / mass,
    ];
    let inertia: f64 = parts.iter().map(|(m, i, c)| i + m * ((c[0] - com[0]).powi(2) + (c[1] - com[1]).powi(2))).sum();
    if !(inertia >= MIN_MASS) {
        return Err(ctx.err(
            format!("{path}.inertia"),
            format!("the moment of inertia about the centre of mass must be > 0 kg m^2 (at least {MIN_MASS:e}), got {inertia}"),
        ));
    }
    let mut ids = Vec::new();
    for (k, p) in b.points.iter().enumerate() {
        let id = ctx.point(&format!("{path}.points[{k}]"), p)?;
        if ids.contains(&id) {
            return Err(ctx.err(format!("{path}.points[{k}]"), format!("point '{p}' is listed twice; list it once")));
        }
        ids.push(id);
    }
    let xy = |id: PointId| ctx.spec.points.0[id.0];
    let angle0 = match ids.as_slice() {
        [p0, p1, ..] => {
            let (a, b) = (xy(*p0), xy(*p1));
            let (dx, dy) = (b[0] - a[0], b[1] - a[1]);
            if dx.hypot(dy) == 0.0 {
                return Err(ctx.err(
                    format!("{path}.points"),
                    "the first two points coincide, so they do not define the body's angle; list another point second",
                ));
            }
            dy.atan2(dx)
        }
        _ => 0.0,
    };
    let (c, s) = (angle0.cos(), angle0.sin());
    let points = ids
        .iter()
        .map(|&id| {
            let p = xy(id);
            let (dx, dy) = (p[0] - com[0], p[1] - com[1]);
            (id, [c * dx + s * dy, -s * dx + c * dy])
        })
        .collect();
    Ok(Body { name: name.to_string(), mass, inertia, com0: com, angle0, points })
}

fn build_pair(ctx: &Ctx, mech: &Mechanism, k: usize, p: &PairSpec) -> R<Pair> {
    let path = format!("pairs[{k}]");
    let (name, at, bodies) = match p {
        PairSpec::Revolute { name, at, bodies } | PairSpec::Prismatic { name, at, bodies, .. } => (name, at, bodies),
    };
    let a = ctx.link(&format!("{path}.bodies[0]"), &bodies[0])?;
    let b = ctx.link(&format!("{path}.bodies[1]"), &bodies[1])?;
    if a == b {
        return Err(ctx.err(format!("{path}.bodies"), "a pair must join two different bodies; name two"));
    }
    let point = ctx.point(&format!("{path}.at"), at)?;
    let carried = |link: Link, i: usize| {
        mech.attachment(link, point).ok_or_else(|| {
            let fix = if link == Link::Ground {
                "add it to the top-level `ground` list"
            } else {
                "add it to that body's `points`"
            };
            ctx.err(format!("{path}.at"), format!("'{}' does not carry point '{at}' ({}: {fix})", bodies[i], bodies[i]))
        })
    };
    // A slider's guide passes through the pair point in the drawing: the guide body need not
    // list it (its copy is placed where the drawing puts it).
    let sa = match p {
        PairSpec::Prismatic { .. } => {
            mech.attachment(a, point).map_or_else(|| local_coords(mech, a, mech.points[point.0].1), |at| at.s)
        }
        PairSpec::Revolute { .. } => carried(a, 0)?.s,
    };
    let sb = carried(b, 1)?.s;
    let angle = |l: Link| match l {
        Link::Ground => 0.0,
        Link::Body(id) => mech.bodies[id.0].angle0,
    };
    let kind = match p {
        PairSpec::Revolute { .. } => PairKind::Revolute,
        PairSpec::Prismatic { axis, along, .. } => {
            let d = match (axis, along) {
                (Some(d), None) => *d,
                (None, Some([from, to])) => {
                    let (pf, pt) =
                        (ctx.xy(&format!("{path}.along[0]"), from)?, ctx.xy(&format!("{path}.along[1]"), to)?);
                    [pt[0] - pf[0], pt[1] - pf[1]]
                }
                _ => {
                    return Err(
                        ctx.err(&path, "give a prismatic pair exactly one of `axis: [dx, dy]` or `along: [P, Q]`")
                    )
                }
            };
            let len = d[0].hypot(d[1]);
            if !(len > 0.0 && len.is_finite()) {
                return Err(ctx.err(
                    &path,
                    "the guide direction has zero length; give a non-zero `axis`, or two distinct `along` points",
                ));
            }
            let (c, s) = (angle(a).cos(), angle(a).sin());
            let (ux, uy) = (d[0] / len, d[1] / len);
            PairKind::Prismatic { axis: [c * ux + s * uy, -s * ux + c * uy] }
        }
    };
    let name = name.clone().unwrap_or_else(|| format!("{}-{}@{at}", bodies[0], bodies[1]));
    Ok(Pair { name, kind, a, b, point, sa, sb, rel_angle0: angle(b) - angle(a) })
}

/// Coordinates in a link's frame of a drawn point.
fn local_coords(mech: &Mechanism, link: Link, p: [f64; 2]) -> [f64; 2] {
    match link {
        Link::Ground => p,
        Link::Body(b) => {
            let body = &mech.bodies[b.0];
            let (c, s) = (body.angle0.cos(), body.angle0.sin());
            let (dx, dy) = (p[0] - body.com0[0], p[1] - body.com0[1]);
            [c * dx + s * dy, -s * dx + c * dy]
        }
    }
}

fn pair_id(ctx: &Ctx, mech: &Mechanism, path: &str, name: &str) -> R<PairId> {
    mech.pairs.iter().position(|p| p.name == name).map(PairId).ok_or_else(|| {
        ctx.err(
            path,
            format!("unknown pair '{name}'; pairs are: {} (give the pair a `name`)", mech.pair_names().join(", ")),
        )
    })
}

fn build_coordinates(ctx: &Ctx, mech: &mut Mechanism) -> R<()> {
    for (k, c) in ctx.spec.coordinates.iter().enumerate() {
        let path = format!("coordinates[{k}]");
        if mech.coordinates.iter().any(|d| d.name == c.name) || c.name.is_empty() {
            return Err(ctx.err(
                format!("{path}.name"),
                format!("coordinate name '{}' is empty or used twice; give each coordinate its own name", c.name),
            ));
        }
        let pair = pair_id(ctx, mech, &format!("{path}.pair"), &c.pair)?;
        if mech.coordinates.iter().any(|d| d.pair == pair) {
            return Err(ctx.err(
                format!("{path}.pair"),
                format!("pair '{}' already has a coordinate; remove one of the two", c.pair),
            ));
        }
        let kind = match mech.pairs[pair.0].kind {
            PairKind::Revolute => CoordinateKind::Angle,
            PairKind::Prismatic { .. } => CoordinateKind::Displacement,
        };
        let value = ctx.finite(&format!("{path}.value"), c.value)?;
        let q0 = ctx.finite(&format!("{path}.q0"), c.q0.unwrap_or(value))?;
        let unit = if kind == CoordinateKind::Angle { 1.0 } else { mech.scale };
        if (q0 - value).abs() > MAX_START_MOVE * unit {
            return Err(ctx.err(format!("{path}.q0"), format!("q0 = {q0} is more than {MAX_START_MOVE:e} (rad, or lengths of the drawing) from the drawn value {value}: the assembly follows the drawing there step by step; draw the mechanism nearer its start")));
        }
        let qd0 = ctx.finite(&format!("{path}.qd0"), c.qd0)?;
        mech.coordinates.push(Coordinate { name: c.name.clone(), pair, kind, value, q0, qd0 });
    }
    Ok(())
}

fn coordinate_index(ctx: &Ctx, mech: &Mechanism, path: &str, name: &str) -> R<usize> {
    mech.coordinates.iter().position(|c| c.name == name).ok_or_else(|| {
        ctx.err(
            path,
            format!(
                "unknown coordinate '{name}'; coordinates are: {} (use one of them)",
                mech.coordinate_names().join(", ")
            ),
        )
    })
}

fn build_drives(ctx: &Ctx, mech: &Mechanism, drives: &[DriveSpec]) -> R<Vec<Option<DriveLaw>>> {
    let mut out = vec![None; mech.dof()];
    for (k, d) in drives.iter().enumerate() {
        let path = format!("drives[{k}]");
        let i = coordinate_index(ctx, mech, &format!("{path}.coordinate"), &d.coordinate)?;
        if out[i].is_some() {
            return Err(ctx.err(
                format!("{path}.coordinate"),
                format!("coordinate '{}' already has a drive; remove one of the two", d.coordinate),
            ));
        }
        out[i] = Some(match (&d.effort, &d.table) {
            (Some(e), None) => DriveLaw::Constant(ctx.finite(&format!("{path}.effort"), *e)?),
            (None, Some(table)) => {
                let n = table.t.len();
                if n == 0 || n != table.effort.len() {
                    return Err(
                        ctx.err(format!("{path}.table"), "`t` and `effort` must be non-empty and of equal length")
                    );
                }
                for (j, (&t, &e)) in table.t.iter().zip(&table.effort).enumerate() {
                    ctx.finite(&format!("{path}.table.t[{j}]"), t)?;
                    ctx.finite(&format!("{path}.table.effort[{j}]"), e)?;
                    if j > 0 && t <= table.t[j - 1] {
                        return Err(ctx.err(format!("{path}.table.t[{j}]"), "times must increase strictly"));
                    }
                }
                DriveLaw::Table { t: table.t.clone(), effort: table.effort.clone() }
            }
            _ => return Err(ctx.err(&path, "give exactly one of `effort` (a constant) or `table: {t, effort}`")),
        });
    }
    Ok(out)
}

fn body_point(ctx: &Ctx, mech: &Mechanism, path: &str, body: &str, point: &str) -> R<Attachment> {
    let link = ctx.link(&format!("{path}.body"), body)?;
    let id = ctx.point(&format!("{path}.at"), point)?;
    mech.attachment(link, id)
        .ok_or_else(|| ctx.err(path, format!("body '{body}' does not carry point '{point}'; add it to its points")))
}

fn build_load(ctx: &Ctx, mech: &Mechanism, k: usize, l: &LoadSpec) -> R<Load> {
    let path = format!("loads[{k}]");
    let mobile = |name: &str| match ctx.link(&format!("{path}.body"), name)? {
        Link::Body(b) => Ok(b),
        Link::Ground => Err(ctx.err(format!("{path}.body"), "a load on the ground does nothing; name a mobile body")),
    };
    Ok(match l {
        LoadSpec::Force { body, at, value } => {
            mobile(body)?;
            Load::Force {
                at: body_point(ctx, mech, &path, body, at)?,
                value: [
                    ctx.finite(&format!("{path}.value"), value[0])?,
                    ctx.finite(&format!("{path}.value"), value[1])?,
                ],
            }
        }
        LoadSpec::Torque { body, value } => {
            Load::Torque { body: mobile(body)?, value: ctx.finite(&format!("{path}.value"), *value)? }
        }
        LoadSpec::Spring { between, stiffness, damping, rest_length } => {
            let e0 = body_point(ctx, mech, &format!("{path}.between[0]"), &between[0][0], &between[0][1])?;
            let e1 = body_point(ctx, mech, &format!("{path}.between[1]"), &between[1][0], &between[1][1])?;
            let (p0, p1) = (ctx.xy(&path, &between[0][1])?, ctx.xy(&path, &between[1][1])?);
            let drawn = (p1[0] - p0[0]).hypot(p1[1] - p0[1]);
            Load::Spring {
                ends: [e0, e1],
                stiffness: ctx.non_negative(&format!("{path}.stiffness"), *stiffness)?,
                damping: ctx.non_negative(&format!("{path}.damping"), *damping)?,
                rest_length: ctx.non_negative(&format!("{path}.rest_length"), rest_length.unwrap_or(drawn))?,
            }
        }
        LoadSpec::TorsionalSpring { pair, stiffness, damping, rest } => Load::PairSpring {
            pair: pair_id(ctx, mech, &format!("{path}.pair"), pair)?,
            stiffness: ctx.non_negative(&format!("{path}.stiffness"), *stiffness)?,
            damping: ctx.non_negative(&format!("{path}.damping"), *damping)?,
            rest: ctx.finite(&format!("{path}.rest"), *rest)?,
        },
        LoadSpec::Friction { pair, viscous } => Load::PairSpring {
            pair: pair_id(ctx, mech, &format!("{path}.pair"), pair)?,
            stiffness: 0.0,
            damping: ctx.non_negative(&format!("{path}.viscous"), *viscous)?,
            rest: 0.0,
        },
    })
}

fn build_simulate(ctx: &Ctx, s: Option<&SimulateSpec>) -> R<SimulateDefaults> {
    let Some(s) = s else { return Ok(SimulateDefaults::default()) };
    let positive = |field: &str, v: Option<f64>| -> R<Option<f64>> {
        match v {
            Some(x) if !(x > 0.0 && x.is_finite()) => {
                Err(ctx.err(format!("simulate.{field}"), format!("{x} must be a positive number")))
            }
            _ => Ok(v),
        }
    };
    if let Some(m) = &s.method {
        m.parse::<crate::integrate::Method>().map_err(|e| ctx.err("simulate.method", e))?;
    }
    Ok(SimulateDefaults {
        t_end: positive("t_end", s.t_end)?,
        method: s.method.clone(),
        rtol: positive("rtol", s.rtol)?,
        atol: positive("atol", s.atol)?,
        dt: positive("dt", s.dt)?,
        output_dt: positive("output_dt", s.output_dt)?,
    })
}

/// The mobility, 3n minus the rank of the pair constraints in the drawing, must equal the
/// number of coordinates; the Chebyshev-Grubler count 3n - 2p explains a mismatch.
/// Redundant constraints (rank < 2p with the right mobility, as in a parallelogram) are
/// left out of the position equations and reported in `warnings`.
fn check_mobility(ctx: &Ctx, mech: &mut Mechanism) -> R<()> {
    let (n, p, m) = (mech.n_bodies() as i64, mech.pairs.len() as i64, mech.dof() as i64);
    if m == 0 {
        return Err(ctx.err("coordinates", "no generalized coordinates: name at least one input pair"));
    }
    let cr = constraint_rank(mech, &mech.x0);
    let (grubler, mobility) = (3 * n - 2 * p, 3 * n - cr.rank as i64);
    if mobility != m {
        let message = if mobility == grubler {
            format!(
                "the mechanism has mobility 3n - 2p = 3*{n} - 2*{p} = {mobility} but {m} coordinate(s) are given; \
                 give exactly {mobility} coordinate(s), or check the pairs (each revolute or prismatic pair removes 2 freedoms)"
            )
        } else {
            format!(
                "the {} pair constraints have rank {} in the drawing, so it has mobility 3n - rank = {mobility} \
                 (Chebyshev-Grubler: 3n - 2p = {grubler}), but {m} coordinate(s) are given: the drawing is at a \
                 singular (folded) configuration, or has redundant constraints; draw it away from singular positions",
                2 * p,
                cr.rank
            )
        };
        return Err(ctx.err("coordinates", message));
    }
    if cr.rank < 2 * p as usize {
        mech.row_slot = vec![None; 2 * p as usize];
        for (slot, &row) in cr.independent_rows.iter().enumerate() {
            mech.row_slot[row] = Some(slot);
        }
        mech.n_constraints = cr.rank;
        for stress in &cr.self_stresses {
            let names: Vec<&str> = stress.pairs.iter().map(|&k| mech.pairs[k.0].name.as_str()).collect();
            mech.warnings.push(format!(
                "redundant constraints among pairs {}: one of their constraint equations is implied by the others \
                 and left out (Chebyshev-Grubler counts {grubler} degree(s) of freedom, the rank shows {mobility}); \
                 the reactions shared by these pairs are statically indeterminate",
                names.join(", ")
            ));
        }
    }
    Ok(())
}

/// The mechanism must assemble at its start coordinates (the drawing, or `q0`).
fn check_assembly(ctx: &Ctx, mech: &Mechanism) -> R<()> {
    let (q0, _) = mech.initial_state();
    assemble(mech, &q0).map(|_| ()).map_err(|e| ctx.err("coordinates", format!("cannot start at q0 = {q0:?}: {e}")))
}

fn characteristic_length(points: &[(String, [f64; 2])]) -> f64 {
    let xy: Vec<[f64; 2]> = points.iter().map(|p| p.1).collect();
    let l = super::diameter::diameter(&xy);
    if l > 0.0 {
        l
    } else {
        1.0
    }
}
