//! What every check of a model entry uses: the error that names the source and the field,
//! numbers finite and in range, and the names the entries refer to (points, bodies, pairs)
//! resolved, with the valid ones listed and the fix when a name is unknown. Below the
//! specification (`spec`) and the checks of its parts (`build`, the load kinds in `loads`).

use super::pairs;
use super::{Attachment, BodyId, Link, Mechanism, PairId, PointId};
use crate::ModelError;
use indexmap::{IndexMap, IndexSet};
use std::collections::HashMap;

/// The context of the checks of one specification (`build::context`).
pub(crate) struct Ctx<'a> {
    /// Where the model comes from (a path or `<string>`), for messages.
    pub source: &'a str,
    /// The points by name with their drawn coordinates (m), and the bodies' names, in file order.
    pub points: &'a IndexMap<String, [f64; 2]>,
    pub bodies: IndexSet<&'a str>,
    /// The pairs given a `name`, by it: their index in file order (a made-up name, for an
    /// unnamed pair, may not be referred to). A lookup per reference, not a scan of the pairs:
    /// the coordinates alone refer to O(pairs) of them.
    pub named_pairs: HashMap<&'a str, usize>,
}

pub(crate) type R<T> = Result<T, ModelError>;

/// Largest magnitude of any other number (SI): products of a few model numbers (m u^2,
/// qd^2 L, tau / A) then stay far from overflowing a double (1.8e308).
const MAX_MAGNITUDE: f64 = 1e30;
impl Ctx<'_> {
    pub(crate) fn err(&self, path: impl Into<String>, message: impl Into<String>) -> ModelError {
        ModelError::Invalid { source_name: self.source.to_string(), path: path.into(), message: message.into() }
    }
    pub(crate) fn point(&self, path: &str, name: &str) -> R<PointId> {
        self.points.get_index_of(name).map(PointId).ok_or_else(|| {
            let known: Vec<&str> = self.points.keys().map(String::as_str).collect();
            self.err(
                path,
                format!(
                    "unknown point '{name}'; points are: {} (use one of them, or add it to `points`)",
                    known.join(", ")
                ),
            )
        })
    }
    pub(crate) fn xy(&self, path: &str, name: &str) -> R<[f64; 2]> {
        self.point(path, name).map(|p| self.points[p.0])
    }
    pub(crate) fn link(&self, path: &str, name: &str) -> R<Link> {
        if name == "ground" {
            return Ok(Link::Ground);
        }
        self.bodies.get_index_of(name).map(|i| Link::Body(BodyId(i))).ok_or_else(|| {
            let known: Vec<&str> = self.bodies.iter().copied().collect();
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
    pub(crate) fn finite(&self, path: &str, v: f64) -> R<f64> {
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
    pub(crate) fn non_negative(&self, path: &str, v: f64) -> R<f64> {
        if self.finite(path, v)? < 0.0 {
            return Err(self.err(path, format!("{v} is negative; it must be >= 0")));
        }
        Ok(v)
    }
}

/// A pair referenced by the `name` it was given: the name made up for an unnamed pair
/// (`a-b@at`) is for messages and results only, and changes when the file is edited.
pub(crate) fn pair_id(ctx: &Ctx, mech: &Mechanism, path: &str, name: &str) -> R<PairId> {
    if let Some(&k) = ctx.named_pairs.get(name) {
        return Ok(PairId(k));
    }
    Err(match mech.pairs.iter().position(|p| p.name == name) {
        Some(k) => ctx.err(
            path,
            format!(
                "'{name}' is the name made up for the unnamed pairs[{k}], which a model may not refer to; \
                 give that pair a `name:` and refer to it by that name"
            ),
        ),
        None => ctx.err(
            path,
            format!("unknown pair '{name}'; pairs are: {} (give the pair a `name`)", mech.pair_names().join(", ")),
        ),
    })
}

/// A pair with a relative motion of its own (for a pair spring or friction).
pub(crate) fn relative_pair(ctx: &Ctx, mech: &Mechanism, path: &str, name: &str) -> R<PairId> {
    let id = pair_id(ctx, mech, path, name)?;
    match pairs::relative(&mech.pairs[id.0]) {
        Some(_) => Ok(id),
        None => Err(ctx.err(
            path,
            format!(
                "'{name}' is a {} pair, which has no relative motion of its own; put the spring or viscous friction on the revolute pair of one of its gears",
                pairs::kind_name(&mech.pairs[id.0])
            ),
        )),
    }
}

/// The point `point` of the body `body` (`{path}.body`, `{path}.at` in messages).
pub(crate) fn body_point(ctx: &Ctx, mech: &Mechanism, path: &str, body: &str, point: &str) -> R<Attachment> {
    let link = ctx.link(&format!("{path}.body"), body)?;
    let id = ctx.point(&format!("{path}.at"), point)?;
    mech.attachment(link, id)
        .ok_or_else(|| ctx.err(path, format!("body '{body}' does not carry point '{point}'; add it to its points")))
}
