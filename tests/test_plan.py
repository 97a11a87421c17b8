"""Time-optimal timing of paths (planardyn.plan) on the 5R robot of the library.

Expected values: the bang-bang structure of a time-optimal timing (at every grid point an
effort or a speed limit is active, Bobrow, Dubowsky and Gibson 1985), the efforts replayed
through forward dynamics (the plan's own consistency), and the closed form of a straight
path under speed limits alone.
"""

from __future__ import annotations

import numpy as np
import planardyn
import pytest
from conftest import MODELS
from planardyn.plan import PlanError, time_optimal

FIVE_BAR = MODELS / "library" / "five-bar-5r.yaml"
# Base angles (rad): from the drawing, both turned 0.5 rad, through a bow (sigma_II >= 0.2
# along it: away from type II singularities).
Q_END = np.array([0.5, 0.5])
TAU_MAX = np.array([1.5, 1.2])  # N m; the efforts at rest along the path are below 0.6 N m


@pytest.fixture(scope="module")
def robot() -> planardyn.Mechanism:
    return planardyn.load(FIVE_BAR)


@pytest.fixture(scope="module")
def plan(robot: planardyn.Mechanism):
    q0 = robot.drawn_q
    waypoints = [q0, q0 + [0.3, 0.2], q0 + Q_END]
    return time_optimal(robot, waypoints, effort=TAU_MAX, n_grid=150, rtol=None)


def interval_use(robot, plan, f):
    """|tau| / limit (I, len(f)) at fractions f of every grid interval in s, each with that
    interval's s'' (s'^2 linear in s across it), by inverse dynamics of the state there."""
    i = np.repeat(np.arange(len(plan.sdd)), len(f))
    s = plan.s[i] + np.tile(f, len(plan.sdd)) * np.diff(plan.s)[i]
    x = np.maximum(plan.sd[i] ** 2 + 2 * (s - plan.s[i]) * plan.sdd[i], 0.0)  # round-off below 0 at rest
    p1, p2 = plan.path(s, 1), plan.path(s, 2)
    tau = robot.inverse_dynamics(plan.path(s), p1 * np.sqrt(x)[:, None], p1 * plan.sdd[i][:, None] + p2 * x[:, None],
                                 x=plan.x[i])
    return (np.abs(tau) / TAU_MAX).max(axis=1).reshape(len(plan.sdd), len(f))


def test_every_interval_has_an_effort_limit_active_but_the_switch(robot, plan) -> None:
    # Bang-bang (Bobrow, Dubowsky and Gibson 1985), with the limits held along each interval:
    # s'' of every interval is the largest (accelerating) or smallest (braking) that keeps
    # every drive within its limit all along it, so some drive reaches its limit somewhere
    # in it (its ends, or 9 points between: within 1e-6 of the limit; toppra's reachability
    # sets leave 2e-8). The exception is the switch from accelerating to braking, inside
    # one interval whose s'' lies between the two (30.8 -> -12.4 -> -35.2 1/s^2 here).
    use = interval_use(robot, plan, np.linspace(0.0, 1.0, 11)).max(axis=1)
    assert use.max() <= 1 + 1e-9  # within the limits, ends and inside
    inactive = np.flatnonzero(use < 1 - 1e-6)
    assert len(inactive) == 1, inactive
    i = inactive[0]
    assert plan.sdd[i - 1] > 0 > plan.sdd[i] > plan.sdd[i + 1]
    assert plan.sd[0] == 0.0 and plan.sd[-1] == 0.0
    assert 0.05 < plan.duration < 5.0
    assert plan.limit_ratio <= 1 + 1e-10


def test_the_planned_efforts_replayed_follow_the_path(robot, plan) -> None:
    # Open loop through forward dynamics at rtol 1e-11: every named point within 1e-6 m of
    # where the plan puts it, at every grid time.
    res = plan.simulate()
    assert res.success, res.message
    planned = np.array([robot.point_positions(robot.assemble(q)) for q in plan.q])
    reached = np.array([robot.point_positions(x) for x in res.x])
    err = np.linalg.norm(planned - reached, axis=-1).max()
    assert err <= 1e-6, err


def test_the_timing_is_a_motion_that_simulate_and_inverse_dynamics_take(robot, plan) -> None:
    # Both coordinates driven by the tables: the spline through 400 samples reproduces the
    # plan's positions to its interpolation error (below 1e-5 rad here), and the efforts the
    # motion needs agree with the plan's (inverse dynamics of the same state) to 1e-9 N m.
    res = robot.simulate(plan.duration, motion=plan.motion(400), t_eval=plan.t, method="dop853", rtol=1e-10)
    assert res.success, res.message
    assert np.abs(res.q - plan.q).max() < 1e-5
    tau = robot.inverse_dynamics(plan.q, plan.qd, plan.qdd)
    assert np.abs(tau - plan.tau).max() < 1e-9 * np.abs(plan.tau).max()


def test_speed_limits_alone_on_a_straight_path_give_length_over_speed(robot) -> None:
    # q(s) = q0 + s dq, theta1 the longer move at 0.8 rad/s: s' = v / |dq_1| everywhere but at
    # the two ends, which start and stop at rest and so take twice their grid interval's
    # time: T = (|dq_1| / v) (n + 1) / (n - 1) for n grid points, in closed form (to toppra's
    # linear programs' tolerance, 1e-9 of s'^2: 0.5100000006 s for 0.51 s).
    q0 = robot.drawn_q
    dq = np.array([0.4, 0.25])
    n, v = 101, 0.8
    plan = time_optimal(robot, [q0, q0 + dq], effort=None, speed=[v, v], n_grid=n, rtol=None)
    expected = dq[0] / v * (n + 1) / (n - 1)
    assert plan.duration == pytest.approx(expected, rel=1e-8)
    assert np.abs(plan.qd[1:-1, 0]).max() == pytest.approx(v, rel=1e-8)


def test_dampers_and_bad_limits_are_refused(robot) -> None:
    # five-bar.yaml's spring-dampers at its motor pairs are its drives' servos: without the
    # drives they are passive dampers, which TOPP refuses by name.
    model = planardyn.load(MODELS / "five-bar.yaml").to_dict()
    del model["drives"]
    damped = planardyn.from_dict(model)
    q0 = damped.drawn_q
    with pytest.raises(PlanError, match=r"loads\[0\] \(torsional_spring at pair motor1\) damps with 1: .* set to 0"):
        time_optimal(damped, [q0, q0 + 0.1], effort=[5.0, 5.0])
    q0 = robot.drawn_q
    with pytest.raises(PlanError, match="effort: expected"):
        time_optimal(robot, [q0, q0 + 0.1], effort=[1.0, 2.0, 3.0])
    with pytest.raises(PlanError, match="no timing"):
        time_optimal(robot, [q0, q0 + 0.1], effort=[1e-3, 1e-3])


def test_cli_writes_a_motion_table_inverse_dynamics_reads(tmp_path) -> None:
    # Exit 0 and a table whose efforts inverse dynamics reproduces (the same computation);
    # exit 1 when no timing exists (0.1 N m cannot hold the robot up against gravity).
    from planardyn.cli import main
    from planardyn.results_io import read_motion

    out = tmp_path / "timed.csv"
    line = ["--line", "-0.08", "0.28", "0.08", "0.36"]
    assert main(["plan", str(FIVE_BAR), *line, "--effort", "3", "3", "--grid", "60", "-o", str(out)]) == 0
    robot = planardyn.load(FIVE_BAR)
    table = read_motion(out, robot.coordinate_names)
    tau = robot.inverse_dynamics(table["q"], table["qd"], table["qdd"])
    assert np.abs(tau - table["tau"]).max() < 1e-9
    assert np.abs(table["tau"]).max() == pytest.approx(3.0, rel=1e-6)
    assert main(["plan", str(FIVE_BAR), *line, "--effort", "0.1", "0.1"]) == 1
