"""Inverse dynamics follows the branch the motion took.

A motion that passes through a type II singularity may leave it on the other assembly
branch: the free-falling five-bar does, and a slider-crank pushed through its dead centre.
Their efforts are known exactly: the five-bar is passive (the truth is 0), the slider-crank
ran under its model's drives (the truth is the run's own ``tau``). With the body coordinates
of every row (a result's ``x``, which results files carry) the efforts match; from q alone
the rows after the singularity are refused, naming the row, instead of being computed on
the drawn branch (they were off by up to 2.28e3 N m).
"""

from __future__ import annotations

import numpy as np
import planardyn as pd
import pytest
from planardyn.results_io import inverse_from_file, write_results

TIGHT = dict(method="dop853", rtol=1e-10, atol=1e-12)


@pytest.fixture(scope="module")
def free_fall():
    mech = pd.load_example("five-bar-free-fall")
    res = mech.simulate(t_end=1.0, **TIGHT)
    # The run itself goes through a type II singularity (it switches to body coordinates).
    assert res.success and res.partitioned.any()
    return mech, res


def test_free_fall_efforts_are_zero_from_the_result(free_fall):
    mech, res = free_fall
    # With the run's body rates: at its most singular row (sigma 8.6e-4) one rounding unit of
    # qd moves the rates solved from it, and the efforts by ~2e-8 N m (2.5e-8 measured from
    # x alone); xd holds the integrator's state.
    tau = mech.inverse_dynamics(res.q, res.qd, res.qdd, x=res.x, xd=res.xd)
    # Passive: 0 exactly; 1e-8 N m is the bound, ~1e4 times the round-off of A qdd - b.
    assert np.abs(tau).max() < 1e-8


def test_free_fall_efforts_are_zero_from_its_results_file(free_fall, tmp_path):
    mech, res = free_fall
    path = tmp_path / "free-fall.npz"
    write_results(res, path)
    # The file's xd are passed with its x (see the test above for why).
    inv = inverse_from_file(mech, path)
    assert np.abs(inv.tau).max() < 1e-8
    assert np.array_equal(inv.xd, res.xd)
    assert inv.metadata["branch"] == "each row's body coordinates"
    assert np.allclose(inv.x, res.x, atol=1e-9)


def test_body_rates_that_are_not_qd_s_are_refused_naming_the_row(free_fall):
    mech, res = free_fall
    xd = res.xd.copy()
    # Another state's rates: one body's angular rate off by 1e-6 rad/s, far above the
    # round-off (relative 1e-10 accepted) and far below the rates themselves (~1-10 rad/s).
    xd[7, 2] += 1e-6
    with pytest.raises(ValueError, match="row 7"):
        mech.inverse_dynamics(res.q, res.qd, res.qdd, x=res.x, xd=xd)
    with pytest.raises(ValueError, match="xd needs x"):
        mech.inverse_dynamics(res.q, res.qd, res.qdd, xd=res.xd)


def test_free_fall_from_q_alone_is_refused_at_the_singularity(free_fall):
    mech, res = free_fall
    with pytest.raises(pd.SingularityError, match="cannot be decided") as err:
        mech.inverse_dynamics(res.q, res.qd, res.qdd)
    row = err.value.row
    # Refused before the run entered the partition chart's region far behind: at a row where
    # the drawn branch is within 0.05 of the singularity, and before the motion left it.
    assert err.value.sigma_min < 0.05
    assert 0 < row < np.argmax(res.partitioned)


@pytest.mark.parametrize("v0", [-3.0, 3.0])
def test_slider_crank_through_its_dead_centre(v0):
    mech = pd.load_example("library/slider-crank-slider-driven")
    res = mech.simulate(t_end=1.0, qd0=[v0], **TIGHT)
    assert res.success and res.partitioned.any()
    tau = mech.inverse_dynamics(res.q, res.qd, res.qdd, x=res.x)
    # Near the dead centre (sigma ~1e-4) round-off in the efforts grows as 1/sigma: 1e-6 N
    # is ~1e2 times the measured 3e-8 N and 1e-6 of the gravity loads.
    assert np.abs(tau - res.tau).max() < 1e-6
    with pytest.raises(pd.SingularityError) as err:
        mech.inverse_dynamics(res.q, res.qd, res.qdd)
    assert err.value.row < np.argmax(res.partitioned)


def test_a_single_row_near_a_singularity_is_not_refused(free_fall):
    # One row has no "after": nothing to decide. At the run's most singular row (sigma
    # 8.6e-4) the passive efforts are still 0 to round-off amplified by 1/sigma, given the
    # row's body rates (from qd's rounding alone they are 2.5e-8 N m off).
    mech, res = free_fall
    i = int(np.argmin(res.sigma))
    tau = mech.inverse_dynamics(res.q[i], res.qd[i], res.qdd[i], x=res.x[i], xd=res.xd[i])
    assert np.abs(tau).max() < 1e-8
