"""Sensitivities (planardyn.sensitivity): central differences with the eps^(1/3) step rule
against exact derivatives (efforts linear in a mass; a small-amplitude pendulum's motion,
analytic in its length), against a finer step (within the Richardson estimate), and the
errors of a design that cannot follow the path."""

from __future__ import annotations

import math
from concurrent.futures import ThreadPoolExecutor

import numpy as np
import planardyn as pd
import pytest
from conftest import MODELS, PENDULUM_I, PENDULUM_L, PENDULUM_M, G, pendulum_dict
from planardyn import batch, library, robot
from planardyn import sensitivity as sens

DT = 0.004  # s, path samples


@pytest.fixture(scope="module")
def five_bar():
    return pd.load(MODELS / "five-bar.yaml")


@pytest.fixture(scope="module")
def circle(five_bar):
    home = robot.EndEffector(five_bar, "P").home()
    return robot.circle(home + [0.0, 0.05], 0.05, duration=1.0)


def test_step_rule_is_exact_and_relative():
    v = np.array([0.25, -3.0, 0.0])
    h = sens.steps(v, typical=[0.0, 0.0, 0.1])
    assert np.allclose(h, sens.DEFAULT_REL_STEP * np.array([0.25, 3.0, 0.1]), rtol=1e-9)
    assert np.array_equal((v + h) - v, h)  # representable: no rounding in the step itself
    assert sens.DEFAULT_REL_STEP == pytest.approx(np.finfo(float).eps ** (1 / 3))
    with pytest.raises(ValueError, match="points.A.0 = 0: .*typical="):
        sens.steps([0.0], names=["points.A.0"])


def test_effort_derivative_to_a_mass_is_the_exact_difference_quotient(five_bar, circle):
    # tau = A(q) qdd - b(q, qd) is linear in each mass (and the uniform bar's inertia m L^2/12
    # with it) and the inverse kinematics does not depend on masses: any difference quotient
    # is the derivative, here over 1 kg.
    path = "bodies.distal_right.mass"
    s = sens.efforts(five_bar, [path, "points.A2.0"], circle, dt=DT)
    lo, hi = batch.inverse_dynamics(batch.sweep(five_bar, path, [0.7, 1.7]), circle, dt=DT)
    exact = hi.tau - lo.tau
    assert s.values[0] == 0.7 and s.derivative.shape == (2, len(lo.t), 2)
    assert np.abs(s[path] - exact).max() < 1e-9 * np.abs(exact).max()
    assert np.array_equal(s.value, lo.tau)
    assert s.error[0].max() < 1e-9 * np.abs(exact).max()
    # The base pivot's x is a nonlinear parameter: the same derivative with a 4x finer step
    # lies within a few Richardson estimates (truncation ~ h^2: the finer one is 16x closer).
    fine = sens.efforts(five_bar, ["points.A2.0"], circle, dt=DT, rel_step=sens.DEFAULT_REL_STEP / 4)
    diff = np.abs(fine.derivative[0] - s.derivative[1]).max()
    assert diff < 3 * s.error[1].max() + 1e-8 * np.abs(s.derivative[1]).max()
    assert np.abs(s.derivative[1]).max() > 10  # N m per m: a real dependence, not noise


def test_pendulum_motion_derivative_to_its_length_is_analytic():
    # Small swing theta0 = 1e-4 rad: theta = theta0 cos(w t), w^2 = m g L / (I + m L^2)
    # (nonlinear correction ~theta0^2/16 = 6e-10 relative). The parameter is the centre of
    # mass' y = -L: d theta/dy = -d theta/dL = theta0 t sin(w t) dw/dL, with
    # dw/dL = m g (I - m L^2) / (2 w (I + m L^2)^2).
    m, inertia, L, theta0 = PENDULUM_M, PENDULUM_I, PENDULUM_L, 1e-4
    J = inertia + m * L * L
    w = math.sqrt(m * G * L / J)
    dw_dL = m * G * (inertia - m * L * L) / (2 * w * J * J)
    t = np.linspace(0.0, 2.0, 81)
    s = sens.trajectory(pendulum_dict(), ["bodies.bob.com.1"], t, q0=[theta0], method="dop853", rtol=1e-12, atol=1e-18)
    expected = theta0 * t * np.sin(w * t) * dw_dL  # d theta / d(-L) = +theta0 t sin(wt) dw/dL
    assert s.values[0] == -L
    got = s.derivative[0][:, 0]
    assert np.abs(got - expected).max() < 1e-6 * np.abs(expected).max()
    # The motion itself: the nonlinear frequency shift w theta0^2/16 gives a phase error of
    # w t theta0^2 / 16 = 5e-9 rad per rad of amplitude after 2 s.
    assert np.abs(s.value[:, 0] - theta0 * np.cos(w * t)).max() < 2e-8 * theta0


def test_objective_of_a_library_design_matches_a_finer_step_and_any_executor():
    def make(proximal, distal):
        return library.five_bar_model(base=0.2, proximal=proximal, distal=distal)

    mech = library.five_bar(base=0.2, proximal=0.2, distal=0.25)
    home = robot.EndEffector(mech, "P").home()
    path = robot.circle(home + [0.0, 0.02], 0.02, duration=0.5)
    params = {"proximal": 0.2, "distal": 0.25}

    def f(motion):
        return [sens.peak_effort(motion), sens.rms_effort(motion), motion.sigma_II.min()]

    s = sens.objective(make, params, path, f, dt=DT)
    assert s.derivative.shape == (2, 3)
    fine = sens.objective(make, params, path, f, dt=DT, rel_step=sens.DEFAULT_REL_STEP / 4)
    assert np.all(np.abs(fine.derivative - s.derivative) <= 3 * s.error + 1e-7 * np.abs(s.derivative))
    # A check of the RMS helper on the nominal motion: the trapezoidal mean of sum tau_k^2.
    nominal = batch.inverse_dynamics([mech], path, dt=DT)[0]
    y2 = (nominal.tau**2).sum(axis=1)
    assert s.value[1] == pytest.approx(math.sqrt(np.trapezoid(y2, nominal.t) / 0.5), rel=1e-12)
    assert s.value[0] == np.abs(nominal.tau).max()
    with ThreadPoolExecutor(2) as ex:
        again = sens.objective(make, params, path, f, dt=DT, executor=ex, threads=1)
    assert np.array_equal(again.derivative, s.derivative)
    assert "proximal" in str(s)


def test_a_design_that_cannot_follow_the_path_raises_naming_it(five_bar):
    home = robot.EndEffector(five_bar, "P").home()
    far = robot.point_to_point(home, (home[0], 1.0), duration=0.5)
    with pytest.raises(pd.SingularityError, match="the nominal design: .* type I "):
        sens.efforts(five_bar, ["bodies.distal_right.mass"], far, dt=DT)
    with pytest.raises(ValueError, match="mapping"):
        sens.efforts(library.five_bar_model, ["proximal"], far)
