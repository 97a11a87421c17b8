"""Bad values through every public function and CLI option of planardyn.plan and
planardyn.robot.sizing (issue 23, finding 6; the rest of the API has its own fuzz test).

Each argument, one at a time, gets NaN, +-inf, 0, a negative, a huge value, an empty array,
arrays of the wrong shape and a string, the others valid. Expected: every call either
returns a result holding no NaN (nor a warning, nor anything printed: IPOPT's output is
silenced) or raises a planardyn error (PlanardynError) whose message starts with the
argument's name; nothing else (no numpy, scipy, toppra or CasADi error): tests/fuzzing.py's
oracle, shared with tests/test_api_fuzz.py. Every CLI option with
a bad value exits 2 with a message naming the option. At 2ac385e, among others:
task_waypoints with NaN raised "cannot convert float NaN to integer", size with preload NaN
blamed tau[0], collocate with sigma_min NaN ended in CasADi's "Ill-posed problem", minimum
effort in 1e-6 s ran 55 s of NaN warnings.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import planardyn as pd
import pytest
from conftest import MODELS
from fuzzing import ARRAYS, INF, NAN, ONE, failures_of, judge
from planardyn import PlanardynError, robot
from planardyn.plan import InfeasiblePlan, collocate, task_waypoints, time_optimal

#: The numbers tried on every argument: NaN, the infinities, zero, negative, huge; a string
#: and None too (the plan functions take no TypeError for an answer: they refuse these with a
#: PlanardynError naming the argument). Not yet all of tests/fuzzing.py's NUMBERS: collocate
#: with a first-guess duration of 5e-324 s still warns (its warm start's rates overflow).
HOSTILE = [NAN, INF, -INF, 0.0, -1.0, 1e300, -1e300, "x", None]

FIVE_BAR = MODELS / "library" / "five-bar-5r.yaml"
PICK, PLACE = [-0.08, 0.28], [0.08, 0.36]


def crank() -> pd.Mechanism:
    """A bar crank under gravity: 1 coordinate, quick to plan."""
    return pd.from_dict({
        "name": "crank", "gravity": [0.0, -9.81],
        "points": {"O": [0.0, 0.0], "A": [0.4, 0.0]}, "ground": ["O"],
        "bodies": {"bar": {"points": ["O", "A"], "uniform_bar": ["O", "A"], "mass": 0.8}},
        "pairs": [{"type": "revolute", "name": "pivot", "at": "O", "bodies": ["ground", "bar"]}],
        "coordinates": [{"name": "theta", "pair": "pivot", "value": 0.0}],
    })


def probe(call: Callable[..., Any], name: str, values: list[Any], capfd) -> list[str]:
    """Call ``call(value)`` for each value; the failures of the oracle (tests/fuzzing.py: no
    warning, every other error naming the argument, InfeasiblePlan an answer, infinities allowed: a plan's limits and stated accuracy
    are infinite where there are none), and any output printed (IPOPT's is silenced)."""
    found = failures_of(lambda v: judge(lambda: call(v), name, v, naming=PlanardynError, start=True,
                                        answers=(InfeasiblePlan,), inf=True, quiet=True), values)
    printed = capfd.readouterr()
    if printed.out or printed.err:
        found.append(f"{name}: printed {(printed.out + printed.err)[:200]!r}")
    return found


@pytest.fixture(scope="module")
def five() -> robot.EndEffector:
    return robot.EndEffector(pd.load(FIVE_BAR), "P")


def test_time_optimal(capfd) -> None:
    mech = crank()
    base = dict(waypoints=[[-1.2], [1.5]], effort=[2.5], speed=None, n_grid=20, rtol=None)
    extra = {"waypoints": [[[0.0], [0.0]], [[0.0], [NAN]], [[0.0], [1e300]]],
             # 1.7e308 and [-1e308, 1e308]: at 5816799 hi - lo overflowed, toppra's LP divided by
             # the infinite half-width (ZeroDivisionError, s22-check).
             "effort": [[[1.0, -1.0]], lambda q: (NAN, 1.0), lambda q: (1.0,), "motors", 1.7e308, [[-1e308, 1e308]]],
             "n_grid": [2, 2.5, 10**9], "rtol": [1e-300]}
    failures = []
    for name in base:
        values = HOSTILE + ARRAYS + ONE + extra.get(name, [])
        failures += probe(lambda v, n=name: time_optimal(mech, **{**base, n: v}), name, values, capfd)
    assert not failures, "\n".join(failures)


def test_task_waypoints(five, capfd) -> None:
    base = dict(effector=five, X=[PICK, PLACE], spacing=0.01)
    extra = {"X": [[PICK], [PICK, [NAN, 0.3]], [[0.0, 0.0, 0.0], [1.0, 1.0, 1.0]]], "spacing": [1e-300, 5e-324]}  # 5e-324: the pieces overflowed
    failures = []
    for name in base:
        values = HOSTILE + ARRAYS + extra.get(name, [])
        failures += probe(lambda v, n=name: task_waypoints(**{**base, n: v}), name, values, capfd)
    assert not failures, "\n".join(failures)


def test_collocate(capfd) -> None:
    mech = crank()
    base: dict[str, Any] = dict(q_start=[-1.2], q_end=[1.5], objective="time", duration=None, effort=[2.5],
                                speed=None, sigma_min=None, n_intervals=4, warm_start=None, tol=1e-6, max_iter=50)
    extra = {"objective": ["fast"], "n_intervals": [1, 2.5, 10**9], "max_iter": [0, 2.5],
             "warm_start": ["plan", 1.0], "sigma_min": [1.0, 2.0]}
    failures = []
    for name in base:
        values = HOSTILE + ARRAYS + ONE + extra.get(name, [])
        failures += probe(lambda v, n=name: collocate(mech, **{**base, n: v}), name, values, capfd)
    # Minimum effort in a duration no motion within the limits keeps: refused at once with
    # the fastest time (at 2ac385e, 55 s of NaN warnings for --duration 1e-6).
    with pytest.raises(InfeasiblePlan, match="the fastest takes"):
        collocate(mech, [-1.2], [1.5], objective="effort", duration=1e-6, effort=[2.5], n_intervals=4)
    assert not failures, "\n".join(failures)


def test_a_planned_motion_s_methods(capfd) -> None:
    plan = time_optimal(crank(), [[-1.2], [1.5]], effort=[2.5], n_grid=20, rtol=None)
    failures = []
    for method in (plan.timing, plan.state, plan.efforts):
        failures += probe(method, "t", [NAN, [0.1, NAN], [INF], "x", [[0.1]]], capfd)
    failures += probe(plan.motion, "n", [0, 1, 2.5, NAN, 10**9, "x"], capfd)
    assert not failures, "\n".join(failures)


def test_size_and_its_helpers(five, capfd) -> None:
    path = robot.circle([0.014, 0.3], 0.02, duration=0.5)
    base = dict(payload=0.0, distribution="min_norm", preload=None, dt=5e-3)
    extra = {"distribution": ["fair"], "dt": [10.0, 1e-300, 2**70]}  # 2**70: np.isfinite refused the int
    failures = []
    for name in base:
        values = HOSTILE + ARRAYS + extra.get(name, [])
        failures += probe(lambda v, n=name: robot.size(five, path, **{**base, n: v}), name, values, capfd)
    failures += probe(lambda v: robot.size(five, v), "path", [None, 1.0, "x"], capfd)
    failures += probe(lambda v: robot.size(v), "motion", [None, 1.0, "x"], capfd)
    payload = {"mass": 0.5, "inertia": 0.0}
    for name in payload:
        failures += probe(lambda v, n=name: robot.with_payload(five.mech, "P", **{**payload, n: v}), name,
                          HOSTILE, capfd)
    failures += probe(lambda v: robot.with_payload(five.mech, v, 0.5), "point", ["nowhere", None], capfd)
    m = robot.solve_motion(five, path, dt=5e-3)
    arrays = {"t": m.t, "qd": m.qd, "torques": m.tau_motor}
    for name in arrays:
        failures += probe(lambda v, n=name: robot.motor_sizing(five.mech, 0, **{**arrays, n: v}), name,
                          HOSTILE + ARRAYS, capfd)
    failures += probe(lambda v: robot.motor_sizing(five.mech, v, m.t, m.qd, m.tau_motor), "k", [-1, 2, 2.5, NAN, "x"],
                      capfd)
    failures += probe(lambda v: robot.envelope(v, m.tau[:, 0]), "speed", HOSTILE + ARRAYS, capfd)
    failures += probe(lambda v: robot.envelope(m.qd[:, 0], v), "effort", HOSTILE + ARRAYS, capfd)
    failures += probe(lambda v: robot.LimitCheck("speed", 1.0, v, "rad/s"), "limit", HOSTILE, capfd)
    failures += probe(lambda v: robot.LimitCheck("speed", v, 1.0, "rad/s"), "demand", [NAN, -1.0], capfd)
    assert not failures, "\n".join(failures)


PLAN_OPTIONS = {
    "--effort": ["nan", "inf", "0", "-3", "x"], "--speed": ["nan", "0", "-1", "x"], "--spacing": ["nan", "0", "-0.01"],
    "--grid": ["0", "2", "2.5", "nan", "1e9"], "--rtol": ["nan", "0", "-1"], "--intervals": ["1", "nan", "x"],
    "--duration": ["nan", "inf", "0", "-1"], "--sigma-min": ["nan", "0", "-1", "2"],
}
SIZE_OPTIONS = {
    "--duration": ["nan", "inf", "0", "-1"], "--payload": ["nan", "inf", "-1"], "--dt": ["nan", "inf", "0", "-1", "5"],
    "--preload": ["nan", "inf", "x"], "--distribution": ["fair"],
}


@pytest.mark.parametrize(("option", "values"), PLAN_OPTIONS.items())
def test_plan_cli_options(option, values, capfd) -> None:
    from planardyn.cli import main

    line = ["--line", *map(str, PICK + PLACE)]
    failures = []
    for value in values:
        effort = [] if option == "--effort" else ["--effort", "3", "3"]
        collocate_ = ["--collocate", "effort" if option == "--duration" else "time"] if option in (
            "--intervals", "--duration", "--sigma-min") else []
        code = main(["plan", str(FIVE_BAR), *line, *effort, *collocate_, f"{option}={value}"])
        err = capfd.readouterr().err
        if code != 2 or option not in err:
            failures.append(f"{option}={value}: exit {code}, {err.strip()[-200:]!r}")
    assert not failures, "\n".join(failures)


@pytest.mark.parametrize(("option", "values"), SIZE_OPTIONS.items())
def test_size_cli_options(option, values, capfd) -> None:
    failures = []
    for value in values:
        code = robot.size_cli([str(MODELS / "five-bar.yaml"), "--circle", "0.014", "0.5097", "0.06",
                               f"{option}={value}"])
        err = capfd.readouterr().err
        if code != 2 or option not in err:
            failures.append(f"{option}={value}: exit {code}, {err.strip()[-200:]!r}")
    assert not failures, "\n".join(failures)


def test_cli_circle_and_line_values(capfd) -> None:
    from planardyn.cli import main

    for args in (["--circle", "0.014", "nan", "0.06"], ["--circle", "0.014", "0.5", "0"], ["--line", "0", "0", "inf", "1"]):
        assert robot.size_cli([str(MODELS / "five-bar.yaml"), *args]) == 2
        assert args[0] in capfd.readouterr().err
    assert main(["plan", str(FIVE_BAR), "--line", "nan", "0.28", "0.08", "0.36", "--effort", "3", "3"]) == 2
    assert "--line" in capfd.readouterr().err
