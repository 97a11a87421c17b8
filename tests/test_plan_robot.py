"""Time-optimal planning on the shipped geared 5R ``five-bar-robot`` as it is: its servos left
out (the planned efforts replace the drive laws), its pins' and motors' Coulomb friction kept.

Expected values: every motor's torque (Mechanism.motor_torques of the efforts inverse dynamics
of the model with its friction gives, at the motor's speed) within the torque its envelope
offers, at dense points between the grid, to RATIO_TOL (the plan's own acceptance); some limit
active (the plan compressed in time by its rtol breaks one); the pins' share of the efforts
equal to the power their Coulomb friction dissipates (mu r |F| |omega|, F the pin's load from
the forward reactions under the planned motor torques): an independent route to the same
friction.
"""

from __future__ import annotations

import numpy as np
import planardyn as pdy
import pytest
from planardyn import robot as rb
from planardyn.plan import PlanError, task_waypoints, time_optimal
from planardyn.plan.topp import RATIO_TOL, RTOL

NAME = "five-bar-robot"
LINE = [[-0.04, 0.45], [0.06, 0.5]]  # m, the line docs/planning.md plans
RATIO = 30.0  # the model's gear ratio
PINS = {"elbow1": ("proximal_left", "distal_left"), "effector": ("distal_left", "distal_right"),
        "elbow2": ("proximal_right", "distal_right")}
MU_R, R = 0.1 * 0.005, 0.005  # mu r and r of every pin (m)
V_ST = 1e-4  # the pins' stiction speed (m/s, model-format.md's default): mu tanh(r |omega| / V_ST)

#: Fractions of each grid interval checked: its ends and 9 points between (10x the grid).
FRACTIONS = np.linspace(0.0, 1.0, 11)

#: The friction balance holds to round-off of the efforts' size (a few N m) and of the
#: friction's fixed point (the core iterates the pins' loads to 1e-13): its inverse dynamics
#: and its forward reactions solve the same equations by different routes.
BALANCE_TOL = 1e-9


@pytest.fixture(scope="module")
def planned():
    robot = pdy.load_example(NAME)
    q = task_waypoints(rb.EndEffector(robot, "P"), LINE, spacing=0.01)
    return robot, time_optimal(robot, q, "actuators")


def states(plan, scale=1.0, f=FRACTIONS):
    """q, qd, qdd, the branch x, at fractions f of every grid interval (s'^2 linear in s
    across it), the time compressed by ``scale`` (qd * scale, qdd * scale^2)."""
    i = np.repeat(np.arange(len(plan.sdd)), len(f))
    s = plan.s[i] + np.tile(f, len(plan.sdd)) * np.diff(plan.s)[i]
    x = np.maximum(plan.sd[i] ** 2 + 2 * (s - plan.s[i]) * plan.sdd[i], 0.0)
    p1, p2 = plan.path(s, 1), plan.path(s, 2)
    qd = p1 * np.sqrt(x)[:, None]
    qdd = p1 * plan.sdd[i][:, None] + p2 * x[:, None]
    return plan.path(s), scale * qd, scale**2 * qdd, plan.x[i]


def usage(mech, q, qd, qdd, x):
    """|t_m| / available torque (N,), the largest over the motors: the core's motor torques
    of the efforts of the model with its friction."""
    tau = mech.inverse_dynamics(q, qd, qdd, x=x)
    t_m = np.asarray(mech.motor_torques(q, qd, qdd, tau, x=x))
    avail = np.column_stack([mech.available_torque(k, RATIO * qd[:, k]) for k in range(mech.dof)])
    return (np.abs(t_m) / avail).max(axis=1)


def test_the_servos_are_left_out_and_said_so(planned) -> None:
    robot, plan = planned
    assert [ld["type"] for ld in plan.mech.to_dict()["loads"]] == ["friction"] * 3
    assert len(plan.ignored) == 3 and "servo" in plan.ignored[1] and "motor1" in plan.ignored[1]
    assert plan.mech.to_dict()["actuators"] == robot.to_dict()["actuators"]


def test_motor_torques_stay_within_the_envelopes_between_the_grid_and_a_limit_binds(planned) -> None:
    _, plan = planned
    use = usage(plan.mech, *states(plan))
    # The path's last point is at rest (s' = 0): the core's map takes the motoring branch
    # there, the plan the back-driven one braking into it (docs/planning.md).
    use = use[:-1]
    assert use.max() <= 1 + RATIO_TOL
    assert use.max() >= 1 - 1e-6  # a limit reached (to toppra's stage tolerance and ROW_MARGIN)
    # Time-optimal to its rtol: the same path run faster by rtol breaks a limit somewhere.
    faster = usage(plan.mech, *states(plan, 1 / (1 - RTOL)))[:-1]
    assert faster.max() > 1 + 1e-3  # measured 1.00777: the inertial torques grow by (1 - rtol)^-2


def test_the_pins_friction_efforts_balance_their_dissipated_power(planned) -> None:
    _, plan = planned
    mech = plan.mech
    q, qd, qdd, x = states(plan, f=np.array([0.5]))
    inner = slice(1, -1)  # not the intervals that touch rest
    q, qd, qdd, x = q[inner], qd[inner], qdd[inner], x[inner]
    tau = np.asarray(mech.inverse_dynamics(q, qd, qdd, x=x))
    model = mech.to_dict()
    model["loads"] = []
    bare = pdy.from_dict(model)
    tau0 = np.asarray(bare.inverse_dynamics(q, qd, qdd, x=x))
    t_m = np.asarray(mech.motor_torques(q, qd, qdd, tau, x=x))
    names, bodies = mech.pair_names, mech.body_names
    power = np.zeros(len(q))
    for row in range(len(q)):
        reactions = mech.reactions(q[row], qd[row], tau=t_m[row])
        xd = np.asarray(mech.kinematics(q[row], qd[row], x_start=x[row])["xd"])
        for pin, (b1, b2) in PINS.items():
            force = np.hypot(*reactions[names.index(pin), :2])
            omega = xd[3 * bodies.index(b2) + 2] - xd[3 * bodies.index(b1) + 2]
            power[row] += MU_R * force * abs(omega) * np.tanh(R * abs(omega) / V_ST)
    friction = np.einsum("ij,ij->i", tau - tau0, qd)
    assert power.min() > 0
    np.testing.assert_allclose(friction, power, rtol=BALANCE_TOL, atol=BALANCE_TOL * np.abs(tau).max())


def test_a_damper_that_is_not_a_servo_is_refused_by_name() -> None:
    model = pdy.load_example(NAME).to_dict()
    model["loads"][2]["viscous"] = 0.01  # elbow1's friction load gets viscous friction
    robot = pdy.from_dict(model)
    q0 = robot.drawn_q
    with pytest.raises(PlanError, match=r"loads\[2\] \(friction at pair elbow1\) damps with 0.01.*viscous set to 0"):
        time_optimal(robot, [q0, q0 + 0.1], "actuators")
