//! Resolving a model file's constructions (`construction.rs`) into the coordinates the
//! model holds: each constructed point from the points it refers to (in any order of the
//! file: a point is placed once the points it needs are), then each coordinate's drawn value
//! given as a measure of the drawing. Lengths in m, angles in rad (counter-clockwise from the
//! x axis), the drawing's y axis up.

use super::construction::{Circle, Construction, Crossing, PointSpec, Side, ValueSpec};
use super::spec::{CoordinateSpec, MechanismSpec, NamedMap, PairSpec};
use crate::units::Motion;
use crate::ModelError;
use indexmap::IndexMap;

type R<T> = Result<T, ModelError>;

/// The specification with every point at coordinates and every coordinate value a number.
pub fn resolve(spec: MechanismSpec<PointSpec, ValueSpec>, source: &str) -> R<MechanismSpec> {
    let err = |path: String, message: String| ModelError::Invalid { source_name: source.to_string(), path, message };
    let points = place_points(&spec.points, &err)?;
    let coordinates = spec
        .coordinates
        .into_iter()
        .enumerate()
        .map(|(i, c)| {
            let drawn = |v: &ValueSpec, field: &str| {
                drawn_value(v, &c.pair, &spec.pairs, &points, &format!("coordinates[{i}].{field}"), &err)
            };
            let value = drawn(&c.value, "value")?;
            let q0 = c.q0.as_ref().map(|v| drawn(v, "q0")).transpose()?;
            Ok(CoordinateSpec { name: c.name, pair: c.pair, value, q0, qd0: c.qd0, about: c.about })
        })
        .collect::<R<Vec<_>>>()?;
    Ok(MechanismSpec {
        name: spec.name,
        about: spec.about,
        units: spec.units,
        gravity: spec.gravity,
        points: NamedMap(points),
        ground: spec.ground,
        bodies: spec.bodies,
        pairs: spec.pairs,
        coordinates,
        drives: spec.drives,
        loads: spec.loads,
        actuators: spec.actuators,
        compliance: spec.compliance,
        simulate: spec.simulate,
    })
}

/// Every point at coordinates, in the file's order: passes over the constructed points,
/// each placing those whose references are placed, until none is left (or none can be:
/// then a reference is unknown, or points are constructed from each other).
fn place_points(
    points: &NamedMap<PointSpec>,
    err: &impl Fn(String, String) -> ModelError,
) -> R<IndexMap<String, [f64; 2]>> {
    let mut placed: IndexMap<String, Option<[f64; 2]>> = points
        .0
        .iter()
        .map(|(name, p)| (name.clone(), if let PointSpec::At(xy) = p { Some(*xy) } else { None }))
        .collect();
    loop {
        let mut progress = false;
        let mut waiting = None;
        for (name, p) in &points.0 {
            let PointSpec::By(how) = p else { continue };
            if placed[name].is_some() {
                continue;
            }
            let refs = references(how);
            let path = format!("points.{name}");
            if let Some(unknown) = refs.iter().find(|r| !placed.contains_key(**r)) {
                let known: Vec<&str> = placed.keys().map(String::as_str).collect();
                return Err(err(
                    path,
                    format!(
                        "unknown point '{unknown}'; points are: {} (use one of them, or add it to `points`)",
                        known.join(", ")
                    ),
                ));
            }
            let xy: Option<Vec<[f64; 2]>> = refs.iter().map(|r| placed[*r]).collect();
            match xy {
                Some(xy) => {
                    let at = construct(how, &xy).map_err(|m| err(path, m))?;
                    placed[name] = Some(at);
                    progress = true;
                }
                None => waiting = waiting.or(Some((name, refs))),
            }
        }
        match (waiting, progress) {
            (None, _) => break,
            (Some(_), true) => continue,
            (Some((name, refs)), false) => {
                let cycle: Vec<&str> = refs.into_iter().filter(|r| placed[*r].is_none()).collect();
                return Err(err(
                    format!("points.{name}"),
                    format!(
                        "'{name}' is constructed from {}, which cannot be placed before it (the constructions \
                         refer to each other); give one of them coordinates",
                        cycle.join(", ")
                    ),
                ));
            }
        }
    }
    Ok(placed.into_iter().map(|(name, xy)| (name, xy.expect("every point placed when the loop ends"))).collect())
}

/// The names of the points a construction is drawn from, in the order `construct` takes them.
fn references(how: &Construction) -> Vec<&str> {
    match how {
        Construction::Polar { from, relative_to, .. } => {
            let mut refs = vec![from.as_str()];
            refs.extend(relative_to.iter().flatten().map(String::as_str));
            refs
        }
        Construction::Circles { circles: [a, b], .. } => vec![&a.0, &b.0],
        Construction::Along { along: [a, b], .. } => vec![a, b],
        Construction::LineCircle { line: [p, q], circle, .. } => vec![p, q, &circle.0],
    }
}

/// Where a construction puts its point, from the coordinates of its references (in the
/// order of `references`); the message of an error says what is wrong and the fix.
fn construct(how: &Construction, xy: &[[f64; 2]]) -> Result<[f64; 2], String> {
    match how {
        Construction::Polar { length, angle, relative_to, .. } => {
            finite("length", *length)?;
            finite("angle", *angle)?;
            let base = match relative_to {
                Some([p, q]) => direction(xy[1], xy[2], &format!("relative_to [{p}, {q}]"))?.1,
                None => 0.0,
            };
            let (s, c) = (angle + base).sin_cos();
            Ok([xy[0][0] + length * c, xy[0][1] + length * s])
        }
        Construction::Circles { circles: [a, b], side } => circles(a, b, xy[0], xy[1], *side),
        Construction::Along { along: [a, b], distance, fraction } => {
            let d = [xy[1][0] - xy[0][0], xy[1][1] - xy[0][1]];
            let t = match (distance, fraction) {
                (Some(distance), _) => {
                    finite("distance", *distance)? / direction(xy[0], xy[1], &format!("along [{a}, {b}]"))?.0
                }
                (None, Some(fraction)) => finite("fraction", *fraction)?,
                (None, None) => unreachable!("the parser requires distance or fraction"),
            };
            Ok([xy[0][0] + t * d[0], xy[0][1] + t * d[1]])
        }
        Construction::LineCircle { line: [p, q], circle, crossing } => {
            let (length, _) = direction(xy[0], xy[1], &format!("line [{p}, {q}]"))?;
            let u = [(xy[1][0] - xy[0][0]) / length, (xy[1][1] - xy[0][1]) / length];
            let r = radius(circle)?;
            let w = [xy[0][0] - xy[2][0], xy[0][1] - xy[2][1]];
            let b = w[0] * u[0] + w[1] * u[1];
            let disc = b * b - (w[0] * w[0] + w[1] * w[1] - r * r);
            if disc < 0.0 {
                let miss = (w[0] * u[1] - w[1] * u[0]).abs() - r;
                return Err(format!(
                    "the line {p} -> {q} misses the circle of radius {} m about {}: it passes {miss:.6e} m outside it; \
                     lengthen the radius by at least that or move the line",
                    short(r),
                    circle.0
                ));
            }
            let s = -b + if *crossing == Crossing::First { -disc.sqrt() } else { disc.sqrt() };
            Ok([xy[0][0] + s * u[0], xy[0][1] + s * u[1]])
        }
    }
}

/// The point at r_A from A and r_B from B on the `side` of the directed line A -> B: with
/// e = (B - A)/d and its left normal n = (-e_y, e_x), A + a e +- h n, a = (d^2 + r_A^2 -
/// r_B^2)/(2 d), h = sqrt(r_A^2 - a^2).
fn circles(ca: &Circle, cb: &Circle, a: [f64; 2], b: [f64; 2], side: Side) -> Result<[f64; 2], String> {
    let (ra, rb) = (radius(ca)?, radius(cb)?);
    let (d, _) = direction(a, b, &format!("the centres {} and {}", ca.0, cb.0))?;
    let (ra_, rb_, d_) = (short(ra), short(rb), short(d));
    let meet = |gap: f64, how: &str| {
        format!(
            "the circles of radius {ra_} m about {} and {rb_} m about {} do not meet: their centres are {d_} m \
             apart, {how} by {gap:.6e} m; change a radius by at least that, or move a centre",
            ca.0, cb.0
        )
    };
    if d > ra + rb {
        return Err(meet(d - (ra + rb), &format!("more than the sum of the radii {}", short(ra + rb))));
    }
    if d < (ra - rb).abs() {
        let difference = short((ra - rb).abs());
        return Err(meet(
            (ra - rb).abs() - d,
            &format!("one lies inside the other: less than the difference of the radii {difference}"),
        ));
    }
    let e = [(b[0] - a[0]) / d, (b[1] - a[1]) / d];
    let along = (d * d + ra * ra - rb * rb) / (2.0 * d);
    let h = (ra * ra - along * along).max(0.0).sqrt() * if side == Side::Left { 1.0 } else { -1.0 };
    Ok([a[0] + along * e[0] - h * e[1], a[1] + along * e[1] + h * e[0]])
}

/// A number for a message: rounded to 12 significant digits, so that the round-off of the
/// drawing's arithmetic (0.1 + 0.05 = 0.15000000000000002) does not show.
fn short(v: f64) -> f64 {
    format!("{v:.11e}").parse().unwrap_or(v)
}

/// The length (m) and angle (rad) of the line p -> q; an error naming `what` when p = q.
fn direction(p: [f64; 2], q: [f64; 2], what: &str) -> Result<(f64, f64), String> {
    let (dx, dy) = (q[0] - p[0], q[1] - p[1]);
    let length = dx.hypot(dy);
    if !(length > 0.0 && length.is_finite()) {
        return Err(format!("{what}: the two points coincide, so they give no direction; give two distinct points"));
    }
    Ok((length, dy.atan2(dx)))
}

fn radius(c: &Circle) -> Result<f64, String> {
    match finite("radius", c.1)? {
        r if r > 0.0 => Ok(r),
        r => Err(format!("the radius about {} is {r}; give a positive length", c.0)),
    }
}

fn finite(what: &str, v: f64) -> Result<f64, String> {
    if v.is_finite() {
        Ok(v)
    } else {
        Err(format!("its {what} is {v}; give a finite number"))
    }
}

/// A coordinate's drawn value: its number (with a unit that fits its pair's motion), or the
/// angle (rad, in (-pi, pi]) or distance (m) of a line of the drawing.
fn drawn_value(
    value: &ValueSpec,
    pair: &str,
    pairs: &[PairSpec],
    points: &IndexMap<String, [f64; 2]>,
    path: &str,
    err: &impl Fn(String, String) -> ModelError,
) -> R<f64> {
    let line = |[p, q]: &[String; 2]| -> R<(f64, f64)> {
        let xy = |name: &String| {
            points.get(name).copied().ok_or_else(|| {
                let known: Vec<&str> = points.keys().map(String::as_str).collect();
                err(path.into(), format!("unknown point '{name}'; points are: {} (use one of them)", known.join(", ")))
            })
        };
        direction(xy(p)?, xy(q)?, &format!("[{p}, {q}]")).map_err(|m| err(path.into(), m))
    };
    match value {
        ValueSpec::Number(v, unit) => {
            let motion = pairs.iter().find(|p| p.name() == Some(pair)).and_then(PairSpec::motion);
            match (unit, motion) {
                (Some(unit), Some(motion)) if *unit != motion => Err(err(
                    path.into(),
                    format!(
                        "the pair '{pair}' {}, so its value is {}; give it in {}",
                        if motion == Motion::Rotation { "turns" } else { "slides" },
                        if motion == Motion::Rotation { "an angle" } else { "a length" },
                        if motion == Motion::Rotation { "rad or deg" } else { "m or mm" },
                    ),
                )),
                _ => Ok(*v),
            }
        }
        ValueSpec::Angle(ends) => line(ends).map(|(_, angle)| angle),
        ValueSpec::Distance(ends) => line(ends).map(|(length, _)| length),
    }
}
