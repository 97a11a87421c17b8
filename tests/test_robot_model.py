"""The shipped geared 5R (``five-bar-robot``): motors behind 30:1 gearboxes with their rotors,
motor friction and Coulomb pin friction, against the hand formulas of docs/actuators.md.

Expected values: the motor torque t_m = J n qdd + f(n qd) + t, t = tau / (n eta) motoring
(tau qd >= 0) or tau eta_b / n back-driven, f = c n qd + T_c tanh(n qd / v_m), with the
joint-side efforts tau of inverse dynamics and the model file's motor data (the rotor turns
before its gear, on the ground: omega_r' = n qdd); along a run, the power balance of the
mechanism: the gears' outputs' work less the pins' and the servo dampers' dissipation is the
change of T + V.
"""

from __future__ import annotations

import numpy as np
import planardyn as pdy
import pytest
from scipy.integrate import simpson

NAME = "five-bar-robot"
#: The model file's motors (both the same): ratio, efficiencies, rotor (kg m^2), friction
#: (N m s/rad, N m) and the default stiction speed (rad/s, docs/model-format.md).
N, ETA, ETA_B, J, C, T_C, V_M = 30.0, 0.8, 0.75, 1.4e-5, 2e-5, 0.004, 1e-2
#: The servo dampers on the two motor pairs (N m s/rad).
DAMPING = 1.0
#: The run's output step (s): fine enough for the power's quadrature (see the test).
OUTPUT_DT = 2e-4


@pytest.fixture(scope="module")
def robot() -> pdy.Mechanism:
    return pdy.load_example(NAME)


def motor_friction(qd):
    w = N * np.asarray(qd)
    return C * w + T_C * np.tanh(w / V_M)


def hand_motor_torques(tau, qd, qdd):
    """t_m of docs/actuators.md for joint-side efforts tau at (qd, qdd), motors on the ground."""
    tau, qd, qdd = map(np.asarray, (tau, qd, qdd))
    gear_input = np.where(tau * qd >= 0, tau / (N * ETA), tau * ETA_B / N)
    return J * N * qdd + motor_friction(qd) + gear_input


def hand_gear_outputs(t_m, qd, qdd):
    """The inverse: tau = n eta t motoring (t qd >= 0), n t / eta_b back-driven."""
    t = np.asarray(t_m) - motor_friction(qd) - J * N * np.asarray(qdd)
    return np.where(t * qd >= 0, N * ETA * t, N * t / ETA_B)


def test_the_model_carries_its_motors_and_pin_friction(robot):
    assert robot.actuator_names == ["theta1", "theta2"]
    for a in robot.actuators:
        assert (a["gear_ratio"], a["efficiency"], a["backdrive_efficiency"], a["rotor_inertia"]) == (N, ETA, ETA_B, J)
        assert (a["peak_torque"], a["continuous_torque"], a["max_speed"]) == (1.3, 0.45, 470.0)
    pins = [ld for ld in robot.to_dict()["loads"] if ld["type"] == "friction"]
    assert [(ld["pair"], ld["mu"], ld["pin_radius"]) for ld in pins] == [
        ("elbow1", 0.1, 0.005), ("effector", 0.1, 0.005), ("elbow2", 0.1, 0.005)]


def test_motor_torques_are_the_hand_formula_on_inverse_dynamics(robot):
    # theta1 driven along its motion (motoring), theta2 braked by its load (back-driven):
    # both branches of the gear at one state.
    q, qd, qdd = robot.q0, np.array([1.5, -2.0]), np.array([20.0, 15.0])
    tau = robot.inverse_dynamics(q, qd, qdd)
    assert tau[0] * qd[0] > 0 and tau[1] * qd[1] < 0, tau
    t_m = robot.motor_torques(q, qd, qdd)
    # The same products in another order: round-off, 1e-15 of the terms; bound 1e-12.
    np.testing.assert_allclose(t_m, hand_motor_torques(tau, qd, qdd), rtol=1e-12, atol=0)
    # Forward dynamics under those motor torques gives the accelerations back (the gears
    # solved with the accelerations; the pins' friction fixed point settles to 1e-13).
    np.testing.assert_allclose(robot.forward_dynamics(q, qd, tau=t_m), qdd, rtol=1e-9, atol=0)
    # Putting the efficiency on the rotor's torque too (the convention before 2ac385e's fix,
    # issue 23 finding 3) would be off by J n qdd (1/eta - 1) on the motoring motor: far
    # outside the bound.
    assert abs(J * N * qdd[0] * (1 / ETA - 1)) > 1e3 * 1e-12 * abs(t_m[0])


def test_a_run_keeps_the_gear_law_and_the_power_balance(robot):
    res = robot.simulate(t_end=0.5, output_dt=OUTPUT_DT, qd0=[1.0, -0.8], rtol=1e-10, atol=1e-12)
    assert res.success, res.message
    # The drives are motor torques (a constant on theta1, a table on theta2): wherever a motor
    # turns faster than its stiction speed the run's joint-side tau are the hand formula's gear
    # outputs for them, and its tau_motor are the laws (round-off 4e-16, bound 1e-12). At rest
    # a gear may hold its load (stuck: any motor torque between its two branches' holds it,
    # and tau_motor reports the motoring one, docs/actuators.md).
    t_m = np.column_stack([np.full(len(res.t), -2.41 / 24),
                           np.interp(res.t, [0.0, 0.2, 0.6, 0.8], [2.61 / 24, 3.2 / 24, 3.2 / 24, 2.61 / 24])])
    moving = np.abs(N * res.qd) > V_M
    assert np.count_nonzero(moving) >= 0.7 * moving.size  # measured 3584 of 5002
    np.testing.assert_allclose(res.tau_motor[moving], t_m[moving], rtol=1e-12, atol=0)
    np.testing.assert_allclose(res.tau[moving], hand_gear_outputs(t_m, res.qd, res.qdd)[moving], rtol=1e-12, atol=0)
    output = res.tau * res.qd
    assert np.any(output[moving] > 0) and np.any(output[moving] < 0)  # both gear branches occur
    # The motors' power n t_m qd splits into the rotors' J n^2 qd qdd, the motor friction
    # f n qd, the gears' losses (t n - tau) qd, never negative where the gear slips (the
    # second law), and their outputs tau qd into the mechanism.
    t = t_m - motor_friction(res.qd) - J * N * res.qdd
    loss = (t * N - res.tau) * res.qd
    assert np.all(loss[moving] >= -1e-15 * np.abs(output).max())
    # The mechanism's balance: the outputs' work less the pins' and the servo dampers'
    # dissipation is the change of T + V (from the states). Simpson's rule over the rows: the
    # power has kinks (branches, the table), so its error falls like h^2: 7.1e-6 J at 1 ms,
    # 2.0e-7 J at 0.2 ms (measured against 0.0294 J of change and 0.32 J of |tau qd| dt).
    power = (np.sum(output, axis=1) - DAMPING * np.sum(res.qd**2, axis=1)
             - robot.dissipated_power(res.q, res.qd, res.qdd, x=res.x, xd=res.xd))
    energy = [sum(robot.energy(q, qd, x_start=x)) for q, qd, x in zip(res.q, res.qd, res.x)]
    assert abs(simpson(power, x=res.t) - (energy[-1] - energy[0])) < 1e-6
    # The run's own balance (the integrator carries the work of every non-conservative
    # force): 2.3e-12 J measured, at rtol 1e-10.
    assert res.energy.drift < 1e-9
