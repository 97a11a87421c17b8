//! The loader's checks that need more than the model: the simulation defaults (a method the
//! integrators know), the mobility (the rank of the pair constraints in the drawing) and the
//! assembly at the start coordinates. The model's own checks come first
//! (`model::build`), so that a model with several errors reports the same one as ever.

use crate::error::Setting;
use crate::integrate::Method;
use crate::kinematics::assemble;
use crate::kinematics::rank_proof::independent_rows;
use crate::model::build::context;
use crate::model::checks::{Ctx, R};
use crate::model::pairs;
use crate::model::spec::SimulateSpec;
use crate::model::{Mechanism, MechanismSpec, SimulateDefaults};

/// Validate a specification and build the mechanism; `source` names it in messages.
pub fn build(spec: MechanismSpec, source: &str) -> R<Mechanism> {
    let mut mech = drawing(spec, source)?;
    let spec = mech.spec.clone();
    let ctx = context(source, &spec);
    check_mobility(&ctx, &mut mech)?;
    check_assembly(&ctx, &mech)?;
    Ok(mech)
}

/// Every check but the mobility and the assembly: the mechanism as drawn, all its pair rows
/// kept, which the structural analysis of a model the loader refuses reads.
pub(super) fn drawing(spec: MechanismSpec, source: &str) -> R<Mechanism> {
    let mut mech = Mechanism::drawing(spec, source)?;
    mech.simulate = build_simulate(&context(source, &mech.spec), mech.spec.simulate.as_ref())?;
    Ok(mech)
}

fn build_simulate(ctx: &Ctx, s: Option<&SimulateSpec>) -> R<SimulateDefaults> {
    let Some(s) = s else { return Ok(SimulateDefaults::default()) };
    // Each setting by its one rule, the run's (`Setting::check`), the error at its field.
    let checked = |setting: Setting, v: Option<f64>| -> R<Option<f64>> {
        v.map(|x| setting.check(x).map_err(|e| ctx.err(format!("simulate.{}", setting.name()), e.to_string())))
            .transpose()
    };
    if let Some(m) = &s.method {
        m.parse::<Method>().map_err(|e| ctx.err("simulate.method", e))?;
    }
    let t_end = checked(Setting::TEnd, s.t_end)?;
    let output_dt = checked(Setting::OutputDt, s.output_dt)?;
    // Every run starts from these defaults' output grid (from 0 s to t_end, 1 s without it).
    if let Some(h) = output_dt {
        Setting::check_outputs(0.0, t_end.unwrap_or(SimulateDefaults::T_END), h)
            .map_err(|e| ctx.err("simulate.output_dt", e.to_string()))?;
    }
    Ok(SimulateDefaults {
        t_end,
        method: s.method.clone(),
        rtol: checked(Setting::Rtol, s.rtol)?,
        atol: checked(Setting::Atol, s.atol)?,
        dt: checked(Setting::Dt, s.dt)?,
        output_dt,
    })
}

/// The mobility, 3n minus the rank of the pair constraints in the drawing, must equal the
/// number of coordinates; the Chebyshev-Grubler count 3n - (sum of the pairs' rows)
/// explains a mismatch. Redundant constraints (rank below the row count with the right
/// mobility, as in a parallelogram) are left out of the position equations and reported
/// in `warnings`.
fn check_mobility(ctx: &Ctx, mech: &mut Mechanism) -> R<()> {
    let (n, rows, m) = (mech.n_bodies() as i64, mech.n_pair_rows(), mech.dof() as i64);
    let cr = independent_rows(mech, &mech.x0);
    let (grubler, mobility) = (3 * n - rows as i64, 3 * n - cr.rank as i64);
    // The count written out: 2 rows for each revolute and prismatic pair, 1 for each gear or slot.
    let p1 = mech.pairs.iter().filter(|p| pairs::n_rows(&p.kind) == 1).count();
    let p2 = mech.pairs.len() - p1;
    let count =
        if p1 == 0 { format!("3n - 2p = 3*{n} - 2*{p2}") } else { format!("3n - 2p - p1 = 3*{n} - 2*{p2} - {p1}") };
    // Whatever the coordinates, a drawing whose constraints have full rank cannot move.
    if mobility == 0 {
        let why = if n == 0 {
            "the model has no mobile body".to_string()
        } else {
            format!(
                "its {rows} pair constraints have rank {} = 3n in the drawing (Chebyshev-Grubler: {count} = {grubler})",
                cr.rank
            )
        };
        return Err(ctx.err(
            "coordinates",
            format!(
                "the drawing is a structure (mobility 0): {why}, so nothing can move, and planardyn moves \
                 mechanisms only; remove a pair or a body (or add a body) until the mobility is at least 1, \
                 or check the drawing, then give one coordinate per degree of freedom"
            ),
        ));
    }
    if m == 0 {
        return Err(ctx.err(
            "coordinates",
            format!(
                "no generalized coordinates, but the mechanism has mobility 3n - rank = {mobility}; \
                 name {mobility} input pair(s) under `coordinates`"
            ),
        ));
    }
    if mobility != m {
        let message = if mobility == grubler {
            format!(
                "the mechanism has mobility {count} = {mobility} but {m} coordinate(s) are given; \
                 give exactly {mobility} coordinate(s), or check the pairs (a revolute or prismatic pair removes 2 freedoms, \
                 a gear or slot pair 1)"
            )
        } else {
            format!(
                "the {rows} pair constraints have rank {} in the drawing, so it has mobility 3n - rank = {mobility} \
                 (Chebyshev-Grubler: {count} = {grubler}), but {m} coordinate(s) are given: the drawing is at a \
                 singular (folded) configuration, or has redundant constraints; draw it away from singular positions",
                cr.rank
            )
        };
        return Err(ctx.err("coordinates", message));
    }
    if cr.rank < rows {
        mech.row_slot = vec![None; rows];
        for (slot, &row) in cr.rows.iter().enumerate() {
            mech.row_slot[row] = Some(slot);
        }
        mech.n_constraints = cr.rank;
        mech.pair_slots = mech.slots_by_pair(&mech.row_slot);
        for stress in &cr.stresses {
            let names: Vec<&str> = stress.iter().map(|&k| mech.pairs[k.0].name.as_str()).collect();
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
