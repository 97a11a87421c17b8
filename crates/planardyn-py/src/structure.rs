//! Structural analysis (`planardyn.structure`): the core's `planardyn::structure` results as
//! Python dicts of names and numbers, and the pair-constraint Jacobian Phi_x.

use crate::convert::{arr1, arr2, vector, Floats};
use crate::errors::{kinematics_error, model_error};
use crate::mechanism::PyMechanism;
use planardyn::loader::analyse_spec;
use planardyn::model::Link;
use planardyn::structure::{analyse, pair_constraint_jacobian, scaled_constraint_jacobian, Structure};
use planardyn::Format;
use pyo3::prelude::*;
use pyo3::types::PyDict;

type ArrayArg<'py> = Floats<'py>;

/// The pair-constraint Jacobian Phi_x = dPhi/dx at body coordinates x: shape
/// (`n_pair_rows`, 3n), every pair's rows in pair order, also the ones the core leaves out
/// as redundant; three columns per body (X, Y in m, phi in rad). `scaled=True` makes it
/// dimensionless as the core's rank test does (`planardyn::structure::scaled_constraint_jacobian`).
#[pyfunction]
#[pyo3(signature = (mech, x, scaled=false))]
pub fn constraint_jacobian<'py>(
    py: Python<'py>,
    mech: &PyMechanism,
    x: ArrayArg<'py>,
    scaled: bool,
) -> PyResult<Bound<'py, PyAny>> {
    let m = &*mech.inner;
    let x = vector("x", &x, m.n_x(), "body coordinates [X, Y, phi] per body")?;
    let (rows, cols) = (m.n_pair_rows(), m.n_x());
    let j = if scaled { scaled_constraint_jacobian(m, &x) } else { pair_constraint_jacobian(m, &x) };
    arr2(py, rows, cols, j)
}

/// The structural analysis of a mechanism at body coordinates x (default: the drawing).
#[pyfunction]
#[pyo3(signature = (mech, x=None))]
pub fn structure<'py>(py: Python<'py>, mech: &PyMechanism, x: Option<ArrayArg<'py>>) -> PyResult<Bound<'py, PyDict>> {
    let m = &*mech.inner;
    let x = match x {
        Some(x) => vector("x", &x, m.n_x(), "body coordinates [X, Y, phi] per body")?,
        None => m.x0.clone(),
    };
    let s = analyse(m, &x).map_err(|e| kinematics_error(py, &e))?;
    to_dict(py, &s)
}

/// The structural analysis of a model dict (as JSON text) at its drawing, also of a model
/// whose mobility differs from its coordinates (`planardyn::loader::analyse_spec`).
#[pyfunction]
#[pyo3(signature = (text, source="<dict>"))]
pub fn structure_of_model<'py>(py: Python<'py>, text: &str, source: &str) -> PyResult<Bound<'py, PyDict>> {
    let s = analyse_spec(text, Format::Data, source).map_err(|e| model_error(py, &e))?;
    to_dict(py, &s)
}

fn to_dict<'py>(py: Python<'py>, s: &Structure) -> PyResult<Bound<'py, PyDict>> {
    let pair = |k: &planardyn::model::PairId| s.pairs[k.0].clone();
    let pairs = |ks: &[planardyn::model::PairId]| ks.iter().map(pair).collect::<Vec<_>>();
    let link = |l: &Link| match l {
        Link::Ground => "ground".to_string(),
        Link::Body(b) => s.bodies[b.0].clone(),
    };
    let d = PyDict::new(py);
    d.set_item("bodies", &s.bodies)?;
    d.set_item("pairs", &s.pairs)?;
    d.set_item("n_pair_rows", s.n_pair_rows)?;
    d.set_item("grubler", s.grubler)?;
    d.set_item("rank", s.rank)?;
    d.set_item("singular_values", arr1(py, s.singular_values.clone()))?;
    d.set_item("independent_rows", &s.independent_rows)?;
    d.set_item("mobility", s.mobility)?;
    d.set_item("redundant", s.redundant)?;
    let stresses = s
        .self_stresses
        .iter()
        .map(|st| {
            let e = PyDict::new(py);
            e.set_item("pairs", pairs(&st.pairs))?;
            e.set_item("lambda", arr1(py, st.lambda.clone()))?;
            Ok(e)
        })
        .collect::<PyResult<Vec<_>>>()?;
    d.set_item("self_stresses", stresses)?;
    d.set_item("actuation", s.actuation)?;
    d.set_item("redundantly_actuated", s.redundantly_actuated())?;
    let loops = s
        .loops
        .iter()
        .map(|lp| {
            let mut path = Vec::new();
            for (l, k) in lp.links.iter().zip(&lp.pairs) {
                path.push(link(l));
                path.push(pair(k));
            }
            path.push(link(&lp.links[0]));
            let e = PyDict::new(py);
            e.set_item("closing_pair", pair(&lp.closing_pair))?;
            e.set_item("path", path)?;
            Ok(e)
        })
        .collect::<PyResult<Vec<_>>>()?;
    d.set_item("loops", loops)?;
    d.set_item("connected", s.connected)?;
    d.set_item("input_links", s.input_links.iter().map(|b| s.bodies[b.0].clone()).collect::<Vec<_>>())?;
    d.set_item("relative_inputs", pairs(&s.relative_inputs))?;
    let groups = s
        .groups
        .iter()
        .map(|g| {
            let e = PyDict::new(py);
            e.set_item("links", g.links.iter().map(|l| s.link_name(l)).collect::<Vec<_>>())?;
            e.set_item("inner_pairs", pairs(&g.inner_pairs))?;
            e.set_item("outer_pairs", pairs(&g.outer_pairs))?;
            e.set_item("class", g.class)?;
            e.set_item("order", g.order)?;
            e.set_item("kind", &g.kind)?;
            e.set_item("description", &g.description)?;
            Ok(e)
        })
        .collect::<PyResult<Vec<_>>>()?;
    d.set_item("groups", groups)?;
    d.set_item("left_over", s.left_over.iter().map(|l| s.link_name(l)).collect::<Vec<_>>())?;
    d.set_item("left_over_mobility", s.left_over_mobility)?;
    Ok(d)
}

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(constraint_jacobian, m)?)?;
    m.add_function(wrap_pyfunction!(structure, m)?)?;
    m.add_function(wrap_pyfunction!(structure_of_model, m)?)?;
    Ok(())
}
