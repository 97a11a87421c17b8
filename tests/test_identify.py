"""The regressor form of the dynamics and the base parameters (planardyn.identify)."""

from __future__ import annotations

import numpy as np
import planardyn as pd
import pytest
from planardyn.identify import base_parameters, sample_states


@pytest.mark.parametrize("name", ["five-bar", "3-rrr", "slider-crank", "hydraulic-boom", "andrews-squeezer"])
def test_y_pi_plus_tau_o_is_the_inverse_dynamics_of_a_run(name):
    # Along a run, on its branch: exact in exact arithmetic, so round-off of the sums
    # (1e-12 of the largest effort) bounds the difference.
    mech = pd.load_example(name)
    res = mech.simulate(t_end=0.05, output_dt=0.005)
    Y, tau_o = mech.regressor(res.q, res.qd, res.qdd, x=res.x)
    pi = np.array(list(mech.inertial_parameters.values()))
    assert Y.shape == (len(res.t), mech.dof, 4 * mech.n_bodies) and tau_o.shape == res.q.shape
    tau = mech.inverse_dynamics(res.q, res.qd, res.qdd, x=res.x)
    np.testing.assert_allclose(Y @ pi + tau_o, tau, rtol=0, atol=1e-12 * max(1.0, np.abs(tau).max()))


def test_pendulum_has_three_base_parameters(pendulum):
    # A body on a ground pivot s (in the body frame, from the drawn centre of mass) moves by
    # one angle: tau = J qdd + g x (first moment about the pivot), with J = I_O + m |s|^2
    # - 2 s.(m c) and the first moment (m cx - m sx, m cy - m sy): 3 of the 4 parameters.
    pend = pendulum
    base = base_parameters(pend, samples=50)
    assert base.rank == 3 and base.parameters == ["m_bob", "mcx_bob", "mcy_bob", "I_bob"]
    assert base.condition < 1e3


@pytest.mark.parametrize("name", ["library/four-bar", "five-bar", "3-rrr"])
def test_base_parameters_give_the_same_efforts_for_any_parameters(name):
    # beta = pi_ind + K pi_dep must reproduce Y pi for every pi, at states the rank was not
    # found from (another seed): 1e-9 of the efforts' size (K comes from a least-squares fit
    # of exactly dependent columns, exact to round-off of its conditioning).
    mech = pd.load_example(name)
    base = base_parameters(mech, samples=150, seed=1)
    p = len(base.parameters)
    assert 0 < base.rank < p and base.condition < 1e6
    q, qd, qdd, x = sample_states(mech, 40, seed=2)
    Y, _ = mech.regressor(q, qd, qdd, x=x)
    rng = np.random.default_rng(3)
    for _ in range(3):
        pi = rng.uniform(0.1, 2.0, p)
        full = Y @ pi
        np.testing.assert_allclose(Y[..., base.independent] @ base.of(pi), full, rtol=0,
                                   atol=1e-9 * np.abs(full).max())
    assert len(base.expressions) == base.rank and all(e.split()[0] in base.parameters for e in base.expressions)
