"""The one-state dynamics calls on a given branch: ``mass_matrix``, ``forward_dynamics``,
``forward_dynamics_derivatives`` and ``reactions`` take ``x_start`` as ``assemble``,
``kinematics`` and ``energy`` do (and ``inverse_dynamics`` its ``x``), so a row of a run that
went through a type II singularity onto the other branch is evaluated where the run was. Before
they had no branch argument and gave the drawing branch's values there (the s15 sweep: the
biglide's forward_dynamics at t = 0.5 s gave [2.67, 4.50] for the run's [8.68, -0.15]).

Reference values: the run's own rows (its qdd at a tight tolerance is forward dynamics on its
branch, to round-off), its reactions along the result (``reactions(res)``, each row on its
own ``x``), and inverse dynamics on the same ``x`` (linear in qdd: A qdd = tau(qdd) - tau(0)).
"""

from __future__ import annotations

import numpy as np
import planardyn as pd
import pytest

TIGHT = dict(method="dop853", rtol=1e-10, atol=1e-12)
# Relative agreement of two evaluations of the same quantities at the same state: round-off
# amplified by 1/sigma (sigma >= ~1e-2 at the rows checked), far below the branches' difference
# (order 1, checked alongside).
SAME = 1e-8


def off_branch(mech, q, x):
    """How far the drawing's assembly at q is from x (m or rad, the angles' difference to a
    whole turn: a crank that turned once is on the same branch; inf where it fails)."""
    try:
        d = mech.assemble(q) - x
    except pd.AssemblyError:
        return np.inf
    d[2::3] = (d[2::3] + np.pi) % (2 * np.pi) - np.pi
    return np.abs(d).max()


@pytest.fixture(scope="module", params=["five-bar-free-fall", "library/slider-crank-slider-driven", "library/biglide"])
def crossed(request):
    """A run through a type II singularity, and its row on the other branch (the drawing's
    assembly at its q is O(1) away: > 1e-2 m or rad, 59 to 265 rows of these runs) farthest
    from the singularity (sigma 0.19 .. 0.40)."""
    mech = pd.load_example(request.param)
    kw = dict(qd0=[3.0]) if "slider" in request.param else {}
    res = mech.simulate(t_end=1.0, **TIGHT, **kw)
    assert res.success and res.partitioned.any()
    other = [k for k in range(len(res.t)) if off_branch(mech, res.q[k], res.x[k]) > 1e-2]
    k = max(other, key=lambda k: res.sigma[k])
    return mech, res, k


def rel(a, b):
    return np.abs(np.asarray(a) - np.asarray(b)).max() / max(np.abs(np.asarray(b)).max(), 1.0)


def test_forward_dynamics_on_the_runs_branch(crossed):
    mech, res, k = crossed
    args = (res.q[k], res.qd[k], res.t[k], res.tau[k])
    assert rel(mech.forward_dynamics(*args, x_start=res.x[k]), res.qdd[k]) < SAME
    d = mech.forward_dynamics_derivatives(*args, x_start=res.x[k])
    assert rel(d["qdd"], res.qdd[k]) < SAME
    # The drawing's branch is another mechanism state: its qdd is not the run's.
    assert rel(mech.forward_dynamics(*args), res.qdd[k]) > 1e-3


def test_mass_matrix_on_the_runs_branch(crossed):
    mech, res, k = crossed
    q, qd, qdd, x = res.q[k], res.qd[k], res.qdd[k], res.x[k]
    a = mech.mass_matrix(q, x_start=x)
    expected = mech.inverse_dynamics(q, qd, qdd, x=x) - mech.inverse_dynamics(q, qd, np.zeros_like(qdd), x=x)
    assert rel(a @ qdd, expected) < SAME
    assert rel(np.linalg.inv(a), mech.forward_dynamics_derivatives(q, qd, res.t[k], res.tau[k], x_start=x)["dtau"]) < SAME


def test_reactions_on_the_runs_branch(crossed):
    mech, res, k = crossed
    along = mech.reactions(res)[k]
    at = mech.reactions(res.q[k], res.qd[k], res.t[k], res.tau[k], x_start=res.x[k])
    assert rel(at, along) < SAME
    with pytest.raises(TypeError, match="result alone"):
        mech.reactions(res, x_start=res.x[k])


def test_x_start_of_the_wrong_length_is_refused_naming_it(crossed):
    mech, res, k = crossed
    with pytest.raises(ValueError, match="x_start"):
        mech.forward_dynamics(res.q[k], res.qd[k], x_start=res.x[k][:2])
    with pytest.raises(ValueError, match="x_start"):
        mech.mass_matrix(res.q[k], x_start=res.x[k][:2])
