"""Time-optimal timing within the motors' torque-speed envelopes (time_optimal(...,
effort="actuators")) on the 5R of the library geared 20:1 (efficiency 0.8, rotor inertia).

Expected values: each motor's torque (the core's motor torque map of the planned joint
efforts) within the torque its envelope offers at its speed at every grid point, to toppra's
tolerance; some limit active at every grid point but the switch (bang-bang); where the
envelope droops, the same path takes longer than with the peak torque at every speed.
"""

from __future__ import annotations

import numpy as np
import planardyn
import pytest
from planardyn import library
from planardyn import robot as rb
from planardyn.plan import PlanError, task_waypoints, time_optimal

RATIO = 20.0
PICK, PLACE = [-0.08, 0.28], [0.08, 0.36]  # m


def geared(limits: dict) -> planardyn.Mechanism:
    model = library.five_bar_model()
    model["actuators"] = [{"coordinate": c, "gear_ratio": RATIO, "efficiency": 0.8, "rotor_inertia": 1e-5,
                           "limits": limits} for c in ("theta1", "theta2")]
    return planardyn.from_dict(model)


# Motor side: 0.2 N m up to 100 rad/s, falling linearly to 0 at 300 rad/s; the flat one keeps
# 0.2 N m to 300 rad/s.
CURVE = {"peak_torque": 0.2, "max_speed": 300.0, "corner_speed": 100.0}
FLAT = {"peak_torque": 0.2, "max_speed": 300.0, "torque_speed": [[0.0, 0.2], [300.0, 0.2]]}


@pytest.fixture(scope="module")
def path():
    ee = rb.EndEffector(geared(CURVE), "P")
    return task_waypoints(ee, [PICK, PLACE], 0.01)


#: Fractions of each grid interval the tests check: its ends and 9 points between.
FRACTIONS = np.linspace(0.0, 1.0, 11)


def usage(mech, plan, f=FRACTIONS):
    """|t_m| / available torque (I, len(f)): the largest over the motors, at fractions f of
    every grid interval in s, each with that interval's s'' (s'^2 linear in s across it):
    the core's motor torque of the efforts inverse dynamics gives there. The path's end, at
    rest, is left out: there the core's map takes the motoring branch (t_m = tau / (n eta)),
    where braking into it back-drives the gear (t_m = tau eta / n) up to the last instant."""
    i = np.repeat(np.arange(len(plan.sdd)), len(f))
    s = plan.s[i] + np.tile(f, len(plan.sdd)) * np.diff(plan.s)[i]
    use, speed = usage_at(mech, plan, i, s)
    use = use.reshape(len(plan.sdd), len(f))
    use[-1, -1] = 0.0
    return use, speed.reshape(use.shape)


def knot_usage(mech, plan):
    """The largest |t_m| / available torque (I,) at the path's knots inside each grid interval
    (0 where none): the efforts have a kink there (the spline's third derivative jumps), a
    maximum the fractions may miss."""
    knots = plan.path.ss_waypoints
    i = np.searchsorted(plan.s, knots, side="right") - 1
    keep = (i >= 0) & (i < len(plan.sdd)) & (knots > plan.s[np.clip(i, 0, len(plan.sdd) - 1)])
    out = np.zeros(len(plan.sdd))
    np.maximum.at(out, i[keep], usage_at(mech, plan, i[keep], knots[keep])[0])
    return out


def usage_at(mech, plan, i, s):
    """|t_m| / available torque and the motors' speeds, the largest over the motors, at the
    points s of the grid intervals i."""
    x = np.maximum(plan.sd[i] ** 2 + 2 * (s - plan.s[i]) * plan.sdd[i], 0.0)  # round-off below 0 at rest
    p1, p2 = plan.path(s, 1), plan.path(s, 2)
    qd = p1 * np.sqrt(x)[:, None]
    tau = mech.inverse_dynamics(plan.path(s), qd, p1 * plan.sdd[i][:, None] + p2 * x[:, None], x=plan.x[i])
    qdd = p1 * plan.sdd[i][:, None] + p2 * x[:, None]
    t_m = np.asarray(mech.motor_torques(plan.path(s), qd, qdd, tau, x=plan.x[i]))
    ratio = np.array([a["gear_ratio"] for a in mech.actuators])
    avail = np.column_stack([mech.available_torque(k, ratio[k] * qd[:, k]) for k in range(mech.dof)])
    return (np.abs(t_m) / avail).max(axis=1), np.abs(ratio * qd).max(axis=1)


def test_motor_torques_stay_within_the_drooping_envelope_and_it_binds(path) -> None:
    # 0.15081 s against 0.14269 s with the flat envelope (both on 399 grid points, from 200
    # doubled once); theta1's motor reaches 212 rad/s, and the drooping line binds in most
    # intervals where a motor runs above its corner speed.
    mech = geared(CURVE)
    plan = time_optimal(mech, path, "actuators", n_grid=200)
    use, speed = usage(mech, plan)
    assert use.max() <= 1 + 1e-9  # at both ends of every interval and inside
    # Interval 265's largest is at a knot (0.99999997 at 0.811 of it): the check's cut there.
    active = np.maximum(use.max(axis=1), knot_usage(mech, plan)) > 1 - 1e-6
    assert np.count_nonzero(~active) <= 1  # the switch from accelerating to braking
    on_droop = ((speed > 100.0) & (use > 1 - 1e-6)).any(axis=1)
    assert on_droop.sum() > 200
    assert plan.limit_ratio <= 1 + 1e-10
    # TimedPath.lo, hi are the exact joint-side bounds at the planned speeds.
    assert np.all(plan.tau[:-1] <= plan.hi[:-1] + 1e-9) and np.all(plan.tau[:-1] >= plan.lo[:-1] - 1e-9)
    flat_mech = geared(FLAT)
    flat = time_optimal(flat_mech, path, "actuators", n_grid=200)
    assert usage(flat_mech, flat)[0].max() <= 1 + 1e-9
    assert plan.duration > 1.03 * flat.duration
    # Regression value: the flat envelope's time measured when this test was written (no
    # closed form: the efficiency's branch makes the joint-side limit depend on the power's
    # sign); 1e-3 is the rtol the grid is refined to. 0.142686 s since the rotor turns before
    # its gear (issue 23: its torque no longer pays the efficiency; 0.143525 s before).
    assert flat.duration == pytest.approx(0.142686, rel=1e-3)


def test_a_geared_inertia_matches_the_phase_plane_reference() -> None:
    # An inertia J (no gravity) turned 2 rad from rest to rest by a geared motor with the
    # drooping envelope, its rotor before the gear: the fastest motion accelerates at
    # n eta T(n qd) / (J + eta n^2 J_rotor) (motoring), then brakes at
    # n T(n qd) / (eta J + n^2 J_rotor) (back-driven: the gear losses help). Both phases
    # integrated at rtol 1e-12 and joined where their (q, qd) curves cross give the reference
    # time, 0.2483043 s. The plan, within the envelope along every interval, is longer by
    # O(grid spacing): 0.2484188 s on 799 grid points (from 400 doubled once), 4.6e-4 longer,
    # never shorter; its estimated excess (the change over the last doubling) takes it to
    # 0.2483030 s: within 2e-5 of the reference (5.3e-6).
    from scipy.integrate import solve_ivp
    from scipy.optimize import brentq

    J, J_rotor, eta, theta = 0.02, 1e-5, 0.8, 2.0
    mech = planardyn.from_dict({
        "name": "geared crank", "gravity": [0.0, 0.0],
        "points": {"O": [0.0, 0.0], "A": [0.1, 0.0]}, "ground": ["O"],
        "bodies": {"crank": {"points": ["O", "A"], "mass": 1.0, "inertia": J, "com": [0.0, 0.0]}},
        "pairs": [{"type": "revolute", "name": "R", "at": "O", "bodies": ["ground", "crank"]}],
        "coordinates": [{"name": "theta", "pair": "R", "value": 0.0}],
        "actuators": [{"coordinate": "theta", "gear_ratio": RATIO, "efficiency": eta, "rotor_inertia": J_rotor,
                       "limits": CURVE}],
    })
    J_up, J_down = J + eta * RATIO**2 * J_rotor, eta * J + RATIO**2 * J_rotor

    def torque(qd: float) -> float:
        return float(mech.available_torque(0, np.array([RATIO * qd]))[0])

    acc = solve_ivp(lambda t, y: [y[1], RATIO * eta * torque(y[1]) / J_up], (0, 2), [0.0, 0.0], rtol=1e-12,
                    atol=1e-12, dense_output=True, events=lambda t, y: y[0] - theta)
    brake = solve_ivp(lambda t, y: [-y[1], RATIO * torque(y[1]) / J_down], (0, 2), [theta, 0.0],
                      rtol=1e-12, atol=1e-12, dense_output=True, events=lambda t, y: y[0])

    def t_at(sol, q: float) -> float:
        return brentq(lambda t: sol.sol(t)[0] - q, 0.0, sol.t[-1], xtol=1e-14)

    q_switch = brentq(lambda q: acc.sol(t_at(acc, q))[1] - brake.sol(t_at(brake, q))[1], 0.1, theta - 0.1,
                      xtol=1e-13)
    reference = t_at(acc, q_switch) + t_at(brake, q_switch)
    plan = time_optimal(mech, [[0.0], [theta]], "actuators", n_grid=400)
    assert RATIO * np.abs(plan.qd).max() > 150.0  # well on the drooping line (corner 100 rad/s)
    assert reference <= plan.duration <= reference * (1 + 1e-3)
    assert plan.duration - plan.time_error == pytest.approx(reference, rel=2e-5), (plan.duration, reference)


def test_missing_actuators_are_refused(path) -> None:
    bare = planardyn.from_dict(library.five_bar_model())
    with pytest.raises(PlanError, match="has no actuator"):
        time_optimal(bare, path, "actuators")
    with pytest.raises(PlanError, match="effort"):
        time_optimal(bare, path, "motors")


def test_cli_plans_within_the_motors(tmp_path, path) -> None:
    # The same timing from the shell (--actuators), written as a motion table whose motor
    # torques stay within the envelope; --collocate does not take --actuators (exit 2).
    import json

    from planardyn.cli import main
    from planardyn.results_io import read_motion

    model = library.five_bar_model()
    model["actuators"] = [{"coordinate": c, "gear_ratio": RATIO, "efficiency": 0.8, "rotor_inertia": 1e-5,
                           "limits": CURVE} for c in ("theta1", "theta2")]
    file, out = tmp_path / "geared.json", tmp_path / "timed.csv"
    file.write_text(json.dumps(model))
    line = ["--line", *map(str, PICK + PLACE), "--actuators"]
    assert main(["plan", str(file), *line, "-o", str(out)]) == 0
    mech = planardyn.load(file)
    table = read_motion(out, mech.coordinate_names)
    t_m = np.asarray(mech.motor_torques(table["q"], table["qd"], table["qdd"], table["tau"]))[:-1]
    avail = np.column_stack([mech.available_torque(k, RATIO * table["qd"][:-1, k]) for k in range(2)])
    assert np.all(np.abs(t_m) <= avail * (1 + 1e-9))
    assert table["t"][-1] == pytest.approx(time_optimal(geared(CURVE), path, "actuators").duration, rel=1e-9)
    assert main(["plan", str(file), *line, "--collocate", "time"]) == 2


def test_timing_that_alternates_between_two_rounds_takes_the_one_within_the_limits():
    # The five-bar robot's motors on this line at n_grid 10 (refined to 145 points): from a round
    # on the tangents taken at 0.0679969 s (limits used to 0.99999997) give 0.0679794 s (to
    # 1.000003) and back, so the rounds never settled and the plan failed after 60. The dense
    # check holds the first within the limits: it is the plan, and its status says why.
    mech = planardyn.load_example("five-bar-robot")
    q = task_waypoints(rb.EndEffector(mech, "P"), [[-0.04, 0.45], [0.06, 0.5]], 0.01)
    plan = time_optimal(mech, q, "actuators", n_grid=10)
    assert plan.duration == pytest.approx(0.0679969417, rel=1e-9)
    assert plan.limit_ratio <= 1 + 1e-10
    assert "alternating between 0.0679969417 s (taken: limits used to 0.99999997" in plan.status
    assert "and 0.0679793638 s (limits used to 1.00000298)" in plan.status
    # Checked apart from the plan's own check: the motor torques of the model the plan ran on
    # (its servos left out) at 11 points of every interval (the path's end, at rest, left out
    # as in usage()) within the envelope to round-off.
    use, _ = usage(plan.mech, plan)
    assert len(plan.s) == 145 and use.max() <= 1 + 1e-9
