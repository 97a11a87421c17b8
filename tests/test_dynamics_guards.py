"""No finite garbage and no NaN/inf from the dynamics calls.

Near the slider-driven slider-crank's dead centre (slider at r + l = 0.4 m) the analogues grow
as 1/sigma and the results lost every digit while looking like numbers (inverse dynamics 9.8e25
at sigma 5.7e-8); below ``planardyn::dynamics::SINGULAR_SIGMA`` = 1e-6 the four dynamics calls
raise ``SingularityError`` (kind 'type_ii', ``sigma_min``), or compute with
``allow_singular=True``. Finite inputs whose results overflow raise ``ValueError`` naming the
quantity, never return NaN or inf.
"""

from __future__ import annotations

import numpy as np
import planardyn as pd
import pytest

SINGULAR_SIGMA = 1e-6
DEAD_CENTRE = 0.4  # m: crank 0.1 m + rod 0.3 m, guide through the crank pivot


@pytest.fixture(scope="module")
def slider():
    return pd.load_example("library/slider-crank-slider-driven")


def near(mech, d):
    q = np.array([DEAD_CENTRE - d])
    return q, mech.kinematics(q)["sigma_min"]


CALLS = {
    "mass_matrix": lambda m, q, **kw: m.mass_matrix(q, **kw),
    "forward_dynamics": lambda m, q, **kw: m.forward_dynamics(q, [0.0], tau=[0.0], **kw),
    "inverse_dynamics": lambda m, q, **kw: m.inverse_dynamics(q, [0.1], [1.0], **kw),
    "reactions": lambda m, q, **kw: m.reactions(q, [0.0], tau=[0.0], **kw),
}


@pytest.mark.parametrize("name", list(CALLS))
def test_at_the_dead_centre_each_call_is_refused_with_the_measure(slider, name):
    q, sigma = near(slider, 1e-14)
    assert sigma < SINGULAR_SIGMA
    with pytest.raises(pd.SingularityError, match="type II") as err:
        CALLS[name](slider, q)
    assert err.value.kind == "type_ii"
    # The core's estimate of the measure stops within its SIGMA_RTOL (2e-3) of the SVD.
    assert err.value.sigma_min == pytest.approx(sigma, rel=2e-3)
    # On request the value is computed (and is finite) instead.
    assert np.all(np.isfinite(CALLS[name](slider, q, allow_singular=True)))


def test_just_above_the_threshold_forward_and_inverse_agree(slider):
    q, sigma = near(slider, 1e-10)
    assert SINGULAR_SIGMA < sigma < 100 * SINGULAR_SIGMA
    tau = slider.inverse_dynamics(q, [0.1], [1.0])
    qdd = slider.forward_dynamics(q, [0.1], tau=tau)
    # Round-off grows as the measure falls (test dynamics_guards.rs measures it): 1e-3 is the
    # accuracy the threshold keeps.
    assert qdd[0] == pytest.approx(1.0, rel=1e-3)


def test_huge_efforts_are_an_overflow_error():
    mech = pd.load_example("five-bar-free-fall")
    with pytest.raises(ValueError, match="accelerations qdd overflow") as err:
        mech.forward_dynamics(mech.q0, [0.0, 0.0], tau=[1e308, 1e308])
    assert err.value.quantity == "accelerations qdd"


@pytest.mark.parametrize(
    ("call", "quantity"),
    [
        (lambda m, q, v: m.forward_dynamics(q, v), "accelerations qdd"),
        (lambda m, q, v: m.reactions(q, v), "accelerations qdd"),
        (lambda m, q, v: m.inverse_dynamics(q, v, [0.0, 0.0]), "efforts tau"),
        (lambda m, q, v: m.kinematics(q, v), "convective accelerations c"),
        (lambda m, q, v: m.energy(q, v), "energies"),
    ],
)
def test_huge_rates_are_an_overflow_error(call, quantity):
    mech = pd.load_example("five-bar-free-fall")
    with pytest.raises(ValueError, match="try smaller efforts") as err:
        call(mech, mech.q0, [1e155, 1e155])
    assert err.value.quantity == quantity


def test_a_run_of_no_step_reports_the_start_measure_not_inf():
    # A drive that fails after the start: the first step is never accepted.
    def drives(t, q, qd):
        if t > 0.0:
            raise RuntimeError("no effort after the start")
        return np.zeros(2)

    mech = pd.load_example("five-bar-free-fall")
    res = mech.simulate(t_end=1.0, drives=drives)
    assert res.status == "drive_failed" and res.stats["naccept"] == 0
    sigma0 = mech.kinematics(mech.q0)["sigma_min"]
    # The integrator's estimate of the measure, within its SIGMA_RTOL (2e-3) of the SVD.
    assert res.stats["min_sigma"] == pytest.approx(sigma0, rel=2e-3)
