//! The checks of a [`MechanismSpec`] that need no mechanics, into the [`Mechanism`] as drawn:
//! every name resolves, masses and inertias are positive, numbers are finite and in range,
//! each pair, coordinate, drive, load and actuator is well formed. The loader adds the checks
//! that need kinematics (the mobility, the assembly at q0) and the simulation settings
//! (`crate::loader`).

use super::checks::{pair_id, Ctx, R};
use super::loads;
use super::pairs::frames::rotate;
use super::pairs::{self, gear::Gear, gear::Mesh, slot::Slot};
use super::spec::{BodySpec, CoordinateSpec, DriveSpec, Location, MotionSpec, PairSpec, PartSpec};
use super::*;

mod actuators;

/// Largest drawn coordinate accepted (m): beyond it squared lengths overflow and the
/// numbers cannot describe a machine.
const MAX_COORDINATE: f64 = 1e9;
/// Smallest total mass (kg) and inertia (kg m^2) of a body: with efforts up to
/// MAX_MAGNITUDE the accelerations stay finite (the fuzz found NaN with 1e308 kg).
const MIN_MASS: f64 = 1e-30;

/// Every check that needs no mechanics: the mechanism as drawn, all its pair rows kept
/// (the loader leaves out the redundant ones), without simulation defaults (the loader's).
pub(super) fn drawing(spec: MechanismSpec, source: &str) -> R<Mechanism> {
    let ctx = context(source, &spec);
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
    let scale = characteristic_length(&points);
    let bodies = spec.bodies.0.iter().map(|(name, b)| build_body(&ctx, name, b, scale)).collect::<R<Vec<_>>>()?;
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
        motions: Vec::new(),
        loads: Vec::new(),
        actuators: Vec::new(),
        pair_actuators: Vec::new(),
        friction: Vec::new(),
        compliance: Default::default(),
        simulate: SimulateDefaults::default(),
        x0: Vec::new(),
        scale: 1.0,
        pair_row_start: vec![0],
        row_slot: Vec::new(),
        pair_slots: Vec::new(),
        n_constraints: 0,
        warnings: Vec::new(),
    };
    mech.x0 = mech.bodies.iter().flat_map(|b| [b.com0[0], b.com0[1], b.angle0]).collect();
    mech.scale = scale;
    // The names so far, for the duplicate check (a scan of the pairs before each would be
    // quadratic in their number).
    let mut pair_names = std::collections::HashSet::new();
    for (k, p) in spec.pairs.iter().enumerate() {
        let pair = build_pair(&ctx, &mech, k, p)?;
        if !pair_names.insert(pair.name.clone()) {
            return Err(ctx.err(
                format!("pairs[{k}].name"),
                format!("duplicate pair name '{}'; rename one of the two", pair.name),
            ));
        }
        let start = mech.n_pair_rows();
        mech.pair_row_start.push(start + pairs::n_rows(&pair.kind));
        mech.pairs.push(pair);
    }
    mech.n_constraints = mech.n_pair_rows();
    mech.row_slot = (0..mech.n_constraints).map(Some).collect();
    mech.pair_slots = mech.slots_by_pair(&mech.row_slot);
    build_coordinates(&ctx, &mut mech, &spec.coordinates)?;
    warn_degree_like_angles(&mut mech);
    (mech.drives, mech.motions) = build_drives(&ctx, &mech, &spec.drives)?;
    let path = |k: usize| format!("loads[{k}]");
    let entries = || spec.loads.iter().enumerate();
    mech.loads = entries().filter_map(|(k, l)| loads::build(l, &ctx, &mech, &path(k)).transpose()).collect::<R<_>>()?;
    mech.friction =
        entries().filter_map(|(k, l)| loads::friction(l, &ctx, &mech, &path(k)).transpose()).collect::<R<_>>()?;
    (mech.actuators, mech.pair_actuators) = actuators::build_actuators(&ctx, &mech, &spec.actuators)?;
    mech.compliance = super::compliance::build(&ctx, &mech, spec.compliance.as_ref())?;
    Ok(mech)
}

/// Largest distance from a centre of mass to the nearest point of its body, in lengths of
/// the drawing: the body's points are stored relative to it, and 1e6 L keeps them to about
/// 2e-10 L, well within what the rank test of the drawing resolves (1e9 L defeats it).
const MAX_COM_OFFSET: f64 = 1e6;

/// Every centre of mass given as coordinates lies near its body: far outside the drawing it
/// is a typing or units error (and ruins the precision of the body's points).
fn check_com_near(
    ctx: &Ctx,
    name: &str,
    b: &BodySpec,
    parts: &[(f64, f64, [f64; 2])],
    points: impl Iterator<Item = [f64; 2]> + Clone,
    scale: f64,
) -> R<()> {
    let far = |c: [f64; 2]| {
        let d = points.clone().map(|p| (p[0] - c[0]).hypot(p[1] - c[1])).fold(f64::INFINITY, f64::min);
        (d > MAX_COM_OFFSET * scale).then_some(d)
    };
    for (k, part) in parts.iter().enumerate() {
        if let Some(d) = far(part.2) {
            let field =
                if b.parts.is_some() { format!("bodies.{name}.parts[{k}].com") } else { format!("bodies.{name}.com") };
            return Err(ctx.err(
                field,
                format!(
                    "the centre of mass [{}, {}] is {d:.3e} m from the nearest point of body '{name}', more than \
                     {MAX_COM_OFFSET:e} times the size of the drawing ({scale} m): it is far outside the drawing; \
                     check its coordinates and units (SI: metres), and give it in the same frame as `points`",
                    part.2[0], part.2[1],
                ),
            ));
        }
    }
    Ok(())
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
        // Named here: the body's inertia check would report an `inertia` the user never gave.
        if l2 == 0.0 {
            return Err(ctx.err(
                format!("{path}.uniform_bar"),
                format!(
                    "the bar's ends {a} and {b} are at the same place, a bar of length 0 with no moment of inertia; \
                     name the bar's two ends, or give a point mass (`point_mass: {a}`) or `com` with `inertia`"
                ),
            ));
        }
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

fn build_body(ctx: &Ctx, name: &str, b: &BodySpec, scale: f64) -> R<Body> {
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
    let xy = |id: PointId| ctx.points[id.0];
    check_com_near(ctx, name, b, &parts, ids.iter().map(|&id| xy(id)), scale)?;
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
        PairSpec::Revolute { name, at, bodies }
        | PairSpec::Prismatic { name, at, bodies, .. }
        | PairSpec::Slot { name, at, bodies, .. } => (name, at.as_str(), bodies),
        PairSpec::Gear { name, bodies, centers, .. } => {
            let at = centers.first().ok_or_else(|| {
                ctx.err(format!("{path}.centers"), "empty: give the gear centres [A, B] (a rack and pinion: [A])")
            })?;
            (name, at.as_str(), bodies)
        }
    };
    let a = ctx.link(&format!("{path}.bodies[0]"), &bodies[0])?;
    let b = ctx.link(&format!("{path}.bodies[1]"), &bodies[1])?;
    if a == b {
        return Err(ctx.err(format!("{path}.bodies"), "a pair must join two different bodies; name two"));
    }
    let point = ctx.point(&format!("{path}.at"), at)?;
    let angle = |l: Link| match l {
        Link::Ground => 0.0,
        Link::Body(id) => mech.bodies[id.0].angle0,
    };
    // A slider's guide and a slot pass through the pair point in the drawing: the guide
    // body need not list it (its copy is placed where the drawing puts it).
    let guided = |point: PointId| {
        mech.attachment(a, point).map_or_else(|| local_coords(mech, a, mech.points[point.0].1), |at| at.s)
    };
    let carried_b = |point: PointId| carried(ctx, mech, &format!("{path}.at"), b, &bodies[1], point);
    let (kind, sa, sb) = match p {
        PairSpec::Revolute { .. } => {
            (PairKind::Revolute, carried(ctx, mech, &format!("{path}.at"), a, &bodies[0], point)?, carried_b(point)?)
        }
        PairSpec::Prismatic { axis, along, .. } => {
            let axis = guide_axis(ctx, &path, axis.as_ref(), along.as_ref(), angle(a))?;
            (PairKind::Prismatic { axis }, guided(point), carried_b(point)?)
        }
        PairSpec::Slot { axis, along, .. } => {
            let axis_a = guide_axis(ctx, &path, axis.as_ref(), along.as_ref(), angle(a))?;
            let ends = match along {
                Some(ends) => [ctx.xy(&path, &ends[0])?, ctx.xy(&path, &ends[1])?],
                None => {
                    // Drawn +-0.3 L about the pin.
                    let (p, d) = (mech.points[point.0].1, rotate(angle(a), axis_a));
                    let h = 0.3 * mech.scale;
                    [[p[0] - h * d[0], p[1] - h * d[1]], [p[0] + h * d[0], p[1] + h * d[1]]]
                }
            };
            let slot = Slot { axis: axis_a, ends: ends.map(|e| local_coords(mech, a, e)) };
            (PairKind::Slot(slot), guided(point), carried_b(point)?)
        }
        PairSpec::Gear { centers, radii, internal, carrier, rack, .. } => {
            let gear =
                GearSpec { centers, radii, internal: *internal, carrier: carrier.as_deref(), rack: rack.as_ref() };
            build_gear(ctx, mech, &path, [a, b], bodies, gear)?
        }
    };
    let name = name.clone().unwrap_or_else(|| format!("{}-{}@{at}", bodies[0], bodies[1]));
    Ok(Pair { name, kind, a, b, point, sa, sb, rel_angle0: angle(b) - angle(a) })
}

/// Where `link` (named `link_name`) carries `point`, or an error at `path` saying how to fix it.
fn carried(ctx: &Ctx, mech: &Mechanism, path: &str, link: Link, link_name: &str, point: PointId) -> R<[f64; 2]> {
    mech.attachment(link, point).map(|at| at.s).ok_or_else(|| {
        let fix = if link == Link::Ground {
            "add it to the top-level `ground` list"
        } else {
            "add it to that body's `points`"
        };
        let name = &mech.points[point.0].0;
        ctx.err(path, format!("'{link_name}' does not carry point '{name}' ({link_name}: {fix})"))
    })
}

/// The unit guide direction of a prismatic or slot pair in a's frame (a drawn at angle
/// `angle_a`), from exactly one of `axis` or `along`.
fn guide_axis(
    ctx: &Ctx,
    path: &str,
    axis: Option<&[f64; 2]>,
    along: Option<&[String; 2]>,
    angle_a: f64,
) -> R<[f64; 2]> {
    let d = match (axis, along) {
        (Some(d), None) => [ctx.finite(&format!("{path}.axis"), d[0])?, ctx.finite(&format!("{path}.axis"), d[1])?],
        (None, Some([from, to])) => {
            let (pf, pt) = (ctx.xy(&format!("{path}.along[0]"), from)?, ctx.xy(&format!("{path}.along[1]"), to)?);
            [pt[0] - pf[0], pt[1] - pf[1]]
        }
        _ => return Err(ctx.err(path, "give exactly one of `axis: [dx, dy]` or `along: [P, Q]` for the guide")),
    };
    let len = d[0].hypot(d[1]);
    if !(len > 0.0 && len.is_finite()) {
        return Err(ctx
            .err(path, "the guide direction has zero length; give a non-zero `axis`, or two distinct `along` points"));
    }
    Ok(rotate(-angle_a, [d[0] / len, d[1] / len]))
}

/// Largest mismatch (relative to the centre distance) between a gear pair's drawn centres
/// and its pitch radii: the drawing's digits, not a tolerance of the solver.
const GEAR_FIT: f64 = 1e-6;

/// The fields of a gear pair's `PairSpec`.
struct GearSpec<'a> {
    centers: &'a [String],
    radii: &'a [f64],
    internal: bool,
    carrier: Option<&'a str>,
    rack: Option<&'a [String; 2]>,
}

/// A gear pair's kind and its two pair points (the centres; for a rack, the pitch line's
/// first point on b).
fn build_gear(
    ctx: &Ctx,
    mech: &Mechanism,
    path: &str,
    [a, b]: [Link; 2],
    bodies: &[String; 2],
    spec: GearSpec,
) -> R<(PairKind, [f64; 2], [f64; 2])> {
    let GearSpec { centers, radii, internal, carrier, rack } = spec;
    let carrier_name = carrier.unwrap_or("ground");
    let c = ctx.link(&format!("{path}.carrier"), carrier_name)?;
    if c == a || c == b {
        return Err(ctx.err(
            format!("{path}.carrier"),
            format!("the carrier '{carrier_name}' is one of the two gears; name the link holding both gear centres (default: ground)"),
        ));
    }
    let n = if rack.is_some() { 1 } else { 2 };
    let what = if rack.is_some() { "a rack and pinion takes the pinion's: [A]" } else { "two gears take [A, B]" };
    if centers.len() != n {
        return Err(ctx.err(format!("{path}.centers"), format!("{} centre(s) given; {what}", centers.len())));
    }
    if radii.len() != n {
        return Err(ctx.err(
            format!("{path}.radii"),
            format!("{} radius(es) given; give one pitch radius per centre ({what})", radii.len()),
        ));
    }
    for (i, &r) in radii.iter().enumerate() {
        if ctx.finite(&format!("{path}.radii[{i}]"), r)? <= 0.0 {
            return Err(ctx.err(format!("{path}.radii[{i}]"), format!("pitch radius {r} must be > 0 m")));
        }
    }
    let angle = |l: Link| match l {
        Link::Ground => 0.0,
        Link::Body(id) => mech.bodies[id.0].angle0,
    };
    let centre = |i: usize, link: Link, name: &str| -> R<(PointId, [f64; 2])> {
        let at = format!("{path}.centers[{i}]");
        let id = ctx.point(&at, &centers[i])?;
        carried(ctx, mech, &at, c, carrier_name, id).map_err(|_| {
            ctx.err(&at, format!("the carrier '{carrier_name}' does not carry centre '{}': a gear's centre is fixed in the carrier (pin the gear to it); add the point to the carrier, or name the right `carrier`", centers[i]))
        })?;
        Ok((id, carried(ctx, mech, &at, link, name, id)?))
    };
    let (pa_id, sa) = centre(0, a, &bodies[0])?;
    let pa = mech.points[pa_id.0].1;
    let ra = radii[0];
    let turn_a = angle(a) - angle(c);
    let (mesh, sb, offset) = match rack {
        None => {
            let (pb_id, sb) = centre(1, b, &bodies[1])?;
            let pb = mech.points[pb_id.0].1;
            let rb = if internal { -radii[1] } else { radii[1] };
            let d = (pb[0] - pa[0]).hypot(pb[1] - pa[1]);
            let (fit, how) =
                if internal { ((ra + rb).abs(), "|r_a - r_b| (internal)") } else { (ra + rb, "r_a + r_b") };
            if !(fit > 0.0 && (d - fit).abs() <= GEAR_FIT * d) {
                return Err(ctx.err(
                    format!("{path}.radii"),
                    format!("the pitch circles do not touch in the drawing: the centres are {d} m apart but {how} = {fit} m; change `radii` (or the centre points{})", if internal { "; internal gears need different radii" } else { "; for a ring gear add `internal: true`" }),
                ));
            }
            (Mesh::Gear { rb }, sb, ra * turn_a + rb * (angle(b) - angle(c)))
        }
        Some([p, q]) => {
            if internal {
                return Err(ctx.err(format!("{path}.internal"), "a rack has no internal mesh; remove `internal`"));
            }
            let (pid, qid) = (ctx.point(&format!("{path}.rack[0]"), p)?, ctx.point(&format!("{path}.rack[1]"), q)?);
            let sb = carried(ctx, mech, &format!("{path}.rack[0]"), b, &bodies[1], pid)?;
            let end = carried(ctx, mech, &format!("{path}.rack[1]"), b, &bodies[1], qid)?;
            let (pp, pq) = (mech.points[pid.0].1, mech.points[qid.0].1);
            let len = (pq[0] - pp[0]).hypot(pq[1] - pp[1]);
            if len == 0.0 {
                return Err(ctx.err(
                    format!("{path}.rack"),
                    "the rack's two points coincide; give two distinct points of its pitch line",
                ));
            }
            let t = [(pq[0] - pp[0]) / len, (pq[1] - pp[1]) / len];
            // The pinion's centre is r_a from the pitch line; n points from it to the line.
            let h = (pp[0] - pa[0]) * t[1] - (pp[1] - pa[1]) * t[0];
            if ((h.abs() - ra).abs()) > GEAR_FIT * ra.max(h.abs()) {
                return Err(ctx.err(
                    format!("{path}.radii"),
                    format!("the pinion's pitch circle does not touch the rack's pitch line in the drawing: its centre is {} m from the line but r_a = {ra} m; change `radii[0]` or the points", h.abs()),
                ));
            }
            // n = -sign(h) E t, so sigma = n x t = sign(h).
            let sign = if h > 0.0 { 1.0 } else { -1.0 };
            let mesh = Mesh::Rack { sign, axis: rotate(-angle(c), t), sc: local_coords(mech, c, pp), end };
            (mesh, sb, sign * ra * turn_a)
        }
    };
    Ok((PairKind::Gear(Gear { carrier: c, ra, mesh, offset }), sa, sb))
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

/// The context of the checks of `spec`; `source` names it in messages.
pub(crate) fn context<'a>(source: &'a str, spec: &'a MechanismSpec) -> Ctx<'a> {
    Ctx {
        source,
        points: &spec.points.0,
        bodies: spec.bodies.0.keys().map(String::as_str).collect(),
        named_pairs: spec.pairs.iter().enumerate().filter_map(|(k, p)| Some((pair_name(p).as_deref()?, k))).collect(),
    }
}

fn pair_name(p: &PairSpec) -> &Option<String> {
    match p {
        PairSpec::Revolute { name, .. }
        | PairSpec::Prismatic { name, .. }
        | PairSpec::Slot { name, .. }
        | PairSpec::Gear { name, .. } => name,
    }
}

fn build_coordinates(ctx: &Ctx, mech: &mut Mechanism, coordinates: &[CoordinateSpec]) -> R<()> {
    // The names and pairs taken so far (scans of the coordinates before each would be
    // quadratic in their number).
    let (mut names, mut taken) = (std::collections::HashSet::new(), vec![false; mech.pairs.len()]);
    for (k, c) in coordinates.iter().enumerate() {
        let path = format!("coordinates[{k}]");
        if !names.insert(c.name.as_str()) || c.name.is_empty() {
            return Err(ctx.err(
                format!("{path}.name"),
                format!("coordinate name '{}' is empty or used twice; give each coordinate its own name", c.name),
            ));
        }
        let pair = pair_id(ctx, mech, &format!("{path}.pair"), &c.pair)?;
        if std::mem::replace(&mut taken[pair.0], true) {
            return Err(ctx.err(
                format!("{path}.pair"),
                format!("pair '{}' already has a coordinate; remove one of the two", c.pair),
            ));
        }
        let kind = pairs::coordinate_kind(&mech.pairs[pair.0]).ok_or_else(|| {
            ctx.err(
                format!("{path}.pair"),
                format!(
                    "'{}' is a {} pair, which has no relative coordinate of its own; make the coordinate the revolute pair of one of its gears",
                    c.pair,
                    pairs::kind_name(&mech.pairs[pair.0])
                ),
            )
        })?;
        let value = ctx.finite(&format!("{path}.value"), c.value)?;
        let q0 = ctx.finite(&format!("{path}.q0"), c.q0.unwrap_or(value))?;
        let unit = if kind == CoordinateKind::Angle { 1.0 } else { mech.scale };
        if (q0 - value).abs() > MAX_CONTINUATION_DISTANCE * unit {
            return Err(ctx.err(format!("{path}.q0"), format!("q0 = {q0} is more than {MAX_CONTINUATION_DISTANCE:e} (rad, or lengths of the drawing) from the drawn value {value}: the assembly follows the drawing there step by step; draw the mechanism nearer its start")));
        }
        let qd0 = ctx.finite(&format!("{path}.qd0"), c.qd0)?;
        let linear = pairs::linear_coordinate(&mech.pairs[pair.0]);
        mech.coordinates.push(Coordinate { name: c.name.clone(), pair, kind, value, q0, qd0, linear });
    }
    Ok(())
}

/// An angle beyond a full turn is legal (angles are unwrapped) but, in a drawing, more often
/// degrees written where radians are meant (`value: 30`): say so, with the radian value.
fn warn_degree_like_angles(mech: &mut Mechanism) {
    let mut found = Vec::new();
    for (k, c) in mech.coordinates.iter().enumerate() {
        if c.kind != CoordinateKind::Angle {
            continue;
        }
        let given_q0 = (c.q0 != c.value).then_some(("q0", c.q0));
        for (field, v) in std::iter::once(("value", c.value)).chain(given_q0) {
            if v.abs() > std::f64::consts::TAU {
                found.push(format!(
                    "coordinates[{k}].{field} of angle '{}' is {v} rad, more than a full turn (2 pi = 6.283 rad): \
                     angles are in radians; if {v} is in degrees, write {:.6}",
                    c.name,
                    v.to_radians()
                ));
            }
        }
    }
    mech.warnings.extend(found);
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

/// Effort laws and motion laws, one slot per coordinate (a coordinate has at most one).
type DriveLaws = (Vec<Option<DriveLaw>>, Vec<Option<MotionLaw>>);

fn build_drives(ctx: &Ctx, mech: &Mechanism, drives: &[DriveSpec]) -> R<DriveLaws> {
    let (mut efforts, mut motions) = (vec![None; mech.dof()], vec![None; mech.dof()]);
    for (k, d) in drives.iter().enumerate() {
        let path = format!("drives[{k}]");
        let i = coordinate_index(ctx, mech, &format!("{path}.coordinate"), &d.coordinate)?;
        if efforts[i].is_some() || motions[i].is_some() {
            return Err(ctx.err(
                format!("{path}.coordinate"),
                format!("coordinate '{}' already has a drive; remove one of the two", d.coordinate),
            ));
        }
        match (&d.effort, &d.table, &d.motion) {
            (Some(e), None, None) => efforts[i] = Some(DriveLaw::Constant(ctx.finite(&format!("{path}.effort"), *e)?)),
            (None, Some(table), None) => {
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
                efforts[i] = Some(DriveLaw::Table { t: table.t.clone(), effort: table.effort.clone() });
            }
            (None, None, Some(motion)) => motions[i] = Some(build_motion(ctx, &format!("{path}.motion"), motion)?),
            _ => {
                return Err(ctx.err(
                    &path,
                    "give exactly one of `effort` (a constant), `table: {t, effort}` or `motion: {speed}` / \
                     `motion: {table: {t, q}}`",
                ))
            }
        }
    }
    Ok((efforts, motions))
}

/// A motion law: `speed` (rad/s or m/s) or `table: {t, q}` (s; rad or m).
fn build_motion(ctx: &Ctx, path: &str, m: &MotionSpec) -> R<MotionLaw> {
    match (&m.speed, &m.table) {
        (Some(w), None) => Ok(MotionLaw::Speed(ctx.finite(&format!("{path}.speed"), *w)?)),
        (None, Some(table)) => {
            let (n, nq) = (table.t.len(), table.q.len());
            if n < 2 || n != nq {
                return Err(ctx.err(
                    format!("{path}.table"),
                    format!("`t` and `q` must have the same length, 2 or more; got {n} and {nq}"),
                ));
            }
            for (j, (&t, &q)) in table.t.iter().zip(&table.q).enumerate() {
                ctx.finite(&format!("{path}.table.t[{j}]"), t)?;
                ctx.finite(&format!("{path}.table.q[{j}]"), q)?;
                if j > 0 && t <= table.t[j - 1] {
                    return Err(ctx.err(format!("{path}.table.t[{j}]"), "times must increase strictly"));
                }
            }
            let spline = Spline::new(&table.t, &table.q).map_err(|e| ctx.err(format!("{path}.table"), e))?;
            Ok(MotionLaw::Table(spline))
        }
        _ => Err(ctx.err(
            path,
            "give exactly one of `speed` (rad/s or m/s, from the start value) or `table: {t, q}` (s; rad or m)",
        )),
    }
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
