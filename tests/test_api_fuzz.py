"""Fuzzing the arguments of the public functions issues 12-16 added (issue 23 finding 6).

Every function below (:data:`CASES`, listed by name) is called with valid arguments except
one, which is NaN, an infinity, zero, negative, huge, tiny, of the wrong shape, or of the
wrong type. The outcome is judged by tests/fuzzing.py's oracle, shared with the planning
fuzz test: a result with no NaN or infinity in it (the documented NaN of unreachable map
cells is in no function listed here), a :class:`~planardyn.PlanardynError` naming the
argument (never an internal error), or a ``TypeError`` for a value of the wrong type (not a
number, not an array of numbers). Anything else (a ``ValueError`` of numpy or scipy,
``ZeroDivisionError``, ``OverflowError``, ``LinAlgError``, ``IndexError``...) is a library
error leaked to the user: a failure.

Two passes, as tests/test_loader_fuzz.py: every argument of every case with every value of the
fixed hostile lists (:func:`test_every_argument_with_every_hostile_value`), then hypothesis'
random values (``PLANARDYN_FUZZ_EXAMPLES``, default 300; a longer campaign:
``PLANARDYN_FUZZ_EXAMPLES=20000 pytest tests/test_api_fuzz.py``, or
``python tests/test_api_fuzz.py 20000`` which prints its counts). The command-line options
those issues added are fuzzed in tests/test_cli_fuzz.py.

Not listed here (tests/test_plan_fuzz.py has them): ``planardyn.plan`` and
``robot.size``/``motor_sizing``/``envelope`` (robot/sizing.py).
"""

from __future__ import annotations

import copy
import os
import sys
from collections import Counter
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

import numpy as np
import planardyn as pd
import pytest
from conftest import pendulum_dict
from fuzzing import NUMBERS, WRONG_TYPES, failures_of, judge
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from planardyn import identify, library, robot
from planardyn.results_io import inverse_result, motion_derivatives
from test_actuators import three_legged

FUZZ_EXAMPLES = int(os.environ.get("PLANARDYN_FUZZ_EXAMPLES", "300"))


# ------------------------------------------------------------------ argument kinds


@dataclass(frozen=True)
class Arg:
    """An argument: its valid value and its kind, which says how to spoil it."""

    value: Any
    kind: str = "number"  # number | count | array | indices | name | none-or-number
    #: Whether values of the wrong type are tried too (not for a number the test's own
    #: functions compute with: their TypeError would be the test's).
    types: bool = True


def spoiled(arg: Arg) -> list[Any]:
    """The hostile values of an argument (each with the right type), in a fixed order."""
    if arg.kind in ("number", "none-or-number"):
        return list(NUMBERS)
    if arg.kind == "count":
        return [0, -1, 2**70, -(2**70), 10**12]
    if arg.kind == "indices":
        return [[0, 10**6], [-(10**6)], [2**62], [True, False], np.zeros((0,), dtype=int)]
    if arg.kind == "name":
        return ["", "nope", "\x00", "é" * 300, " " + str(arg.value)]
    if arg.kind == "array":
        a = np.asarray(arg.value, dtype=float)
        out: list[Any] = []
        for v in [v for v in NUMBERS if isinstance(v, float)]:  # big integers are tried as numbers
            b = a.copy()
            b.flat[b.size // 2] = v
            out.append(b)
        out += [a * 1e300, a * 1e-300, np.zeros_like(a), np.zeros((0,)), a.ravel()[:-1] if a.size else a[None],
                a[None], np.float64(1.0), np.concatenate([a.ravel(), [1.0]])]
        return out
    return []


def is_wrong_type(value: Any, kind: str = "") -> bool:
    """A value of the wrong type for an argument of ``kind`` (floats for indices)."""
    if any(value is w for w in WRONG_TYPES):
        return True
    return kind == "indices" and np.asarray(value).dtype.kind == "f"


@dataclass
class Case:
    """A public function, its valid arguments, and how to call it."""

    name: str
    call: Callable[..., Any]
    args: dict[str, Arg]
    #: Names by which an ArgumentError may name an argument instead of its own.
    aliases: dict[str, tuple[str, ...]] = field(default_factory=dict)

    def run(self, spoil: dict[str, Any]) -> Any:
        kw = {k: copy.deepcopy(a.value) for k, a in self.args.items()}
        kw.update(spoil)
        return self.call(**kw)


# ------------------------------------------------------------------ the mechanisms and data


def three_legged_geared() -> pd.Mechanism:
    """tests/test_actuators.py's five-bar with a third, redundant leg, its motor geared (n 15,
    eta 0.85) with a torque-speed envelope: every argument of the actuator functions applies."""
    model = three_legged().to_dict()
    model["actuators"] = [{"pair": "motor3", "gear_ratio": 15.0, "efficiency": 0.85, "rotor_inertia": 3e-5,
                           "limits": {"peak_torque": 2.0, "torque_speed": [[0.0, 2.0], [100.0, 2.0], [300.0, 0.0]]}}]
    return pd.from_dict(model)


FIVE = pd.load_example("five-bar")
GEARED = three_legged_geared()
Q, QD, QDD = FIVE.q0 + np.array([0.05, -0.04]), np.array([1.2, -0.7]), np.array([3.0, 5.0])
RUN = FIVE.simulate(0.05, output_dt=0.005)
DENSE = FIVE.simulate(0.05, output_dt=0.005, dense_output=True)
BASE = identify.base_parameters(FIVE, samples=30)
T_REC = np.linspace(0.0, 0.5, 101)
REC = np.column_stack([FIVE.q0[0] + 0.2 * np.sin(2 * np.pi * T_REC), FIVE.q0[1] + 0.2 * np.sin(6 * np.pi * T_REC)])
EXC = identify.Excitation(FIVE.q0, 1.0, np.full((2, 2), 0.1), np.full((2, 2), 0.05), 10.0, 20.0)
PENDULUM = pd.from_dict(pendulum_dict())


def identify_rows() -> tuple[np.ndarray, ...]:
    """The five-bar's exact efforts along the excitation: data that identify every base parameter."""
    q, qd, qdd = EXC.sample(np.linspace(0.0, 1.0, 60, endpoint=False))
    return q, qd, qdd, FIVE.inverse_dynamics(q, qd, qdd)


ID_Q, ID_QD, ID_QDD, ID_TAU = identify_rows()


def simulate_with(**kw: Any) -> pd.SimulationResult:
    return FIVE.simulate(**{"t_end": 0.02, "max_steps": 400, **kw})


def motion_speed(speed: Any) -> pd.SimulationResult:
    return simulate_with(motion={"theta1": speed})


def motion_table(t: Any, q: Any) -> pd.SimulationResult:
    return simulate_with(motion={"theta1": {"t": t, "q": q}})


def motion_function(value: Any) -> pd.SimulationResult:
    return simulate_with(motion={"theta1": lambda t: (value, value, value)})


def crossing(value: Any, direction: Any) -> pd.SimulationResult:
    return simulate_with(events=[pd.Crossing("theta1", value, terminal=True, direction=direction)])


def event_function(value: Any) -> pd.SimulationResult:
    return simulate_with(events=[lambda t, q, qd: value])


def batch_motion(speed: Any) -> Any:
    out = pd.batch.simulate([FIVE], 0.02, max_steps=400, motion={"theta1": speed}, threads=1)
    if isinstance(out[0], pd.batch.BatchError):  # a variant's failure, reported in place
        raise pd.SimulationError(out[0].message)
    return out


def from_functions(duration: Any, scale: Any) -> robot.TaskPath:
    return robot.from_functions(lambda t: scale * np.column_stack([np.cos(t), np.sin(t)]),
                                lambda t: scale * np.column_stack([-np.sin(t), np.cos(t)]),
                                lambda t: scale * np.column_stack([-np.cos(t), -np.sin(t)]), duration)


def path_samples(path: robot.TaskPath, t: Any) -> Any:
    return path.sample(t)


CASES: list[Case] = [
    # issue 12: prescribed motion, events, dense output, trajectories, task paths, drawing help
    Case("Mechanism.simulate(motion=speed)", motion_speed, {"speed": Arg(2.0)}, {"speed": ("motion",)}),
    Case("Mechanism.simulate(motion=table)", motion_table,
         {"t": Arg([0.0, 0.01, 0.02, 0.03], "array"), "q": Arg([2.0, 2.01, 2.03, 2.06], "array")},
         {"t": ("motion",), "q": ("motion",)}),
    Case("Mechanism.simulate(motion=function)", motion_function, {"value": Arg(2.0, types=False)},
         {"value": ("motion", "q")}),
    Case("Mechanism.simulate(events=Crossing)", crossing, {"value": Arg(2.1), "direction": Arg(0.0)},
         {"value": ("event",), "direction": ("event",)}),
    Case("Mechanism.simulate(events=function)", event_function, {"value": Arg(1.0, types=False)}),
    Case("Mechanism.simulate(t_end, output_dt)", simulate_with,
         {"t_end": Arg(0.02), "output_dt": Arg(0.01, "none-or-number")}),
    Case("batch.simulate(motion=speed)", batch_motion, {"speed": Arg(2.0)}, {"speed": ("motion",)}),
    Case("Mechanism.reactions(q, qd, t, tau)", FIVE.reactions,
         {"q": Arg(Q, "array"), "qd": Arg(QD, "array"), "t": Arg(0.0), "tau": Arg([0.1, 0.2], "array")}),
    Case("SimulationResult.sol(t)", lambda t: DENSE.sol(t), {"t": Arg([0.0, 0.01, 0.05], "array")}),
    Case("SimulationResult.take(rows)", lambda rows: RUN.take(rows), {"rows": Arg([0, 2, 4], "indices")}),
    Case("robot.from_functions", from_functions, {"duration": Arg(1.0), "scale": Arg(0.1, types=False)},
         {"scale": ("X", "Xd", "Xdd")}),
    Case("robot.table", robot.table,
         {"t": Arg([0.0, 0.5, 1.0], "array"), "X": Arg([[0.0, 0.3], [0.05, 0.32], [0.1, 0.3]], "array"),
          "bc_type": Arg("not-a-knot", "name")}),
    Case("TaskPath.sample", lambda t: path_samples(robot.table([0.0, 0.5, 1.0], [[0, 0.3], [0.1, 0.3], [0.2, 0.3]]), t),
         {"t": Arg([0.0, 0.5], "array")}),
    Case("library.circle_intersection", library.circle_intersection,
         {"c1": Arg([0.0, 0.0], "array"), "r1": Arg(1.0), "c2": Arg([1.0, 0.0], "array"), "r2": Arg(1.0),
          "mode": Arg(1, "count")}),
    Case("results_io.inverse_result", lambda t, q: inverse_result(FIVE, t, q),
         {"t": Arg(T_REC[:11], "array"), "q": Arg(REC[:11], "array")}),
    Case("results_io.motion_derivatives", motion_derivatives,
         {"t": Arg(T_REC[:11], "array"), "q": Arg(REC[:11], "array")}),
    Case("load_example", pd.load_example, {"name": Arg("five-bar", "name")}),
    # issue 13: actuators, redundant actuation, losses
    Case("Mechanism.motor_torques", GEARED.motor_torques,
         {"q": Arg(Q, "array"), "qd": Arg(QD, "array"), "qdd": Arg(QDD, "array"), "tau": Arg([0.2, 0.1, 0.4], "array")}),
    Case("Mechanism.distribute_efforts", GEARED.distribute_efforts,
         {"q": Arg(Q, "array"), "qd": Arg(QD, "array"), "qdd": Arg(QDD, "array"),
          "method": Arg("preload", "name"), "preload": Arg([3.0], "array")}),
    Case("Mechanism.forward_dynamics_actuated", GEARED.forward_dynamics_actuated,
         {"q": Arg(Q, "array"), "qd": Arg(QD, "array"), "efforts": Arg([0.1, 0.2, 0.05], "array"), "t": Arg(0.0)}),
    Case("Mechanism.available_torque", GEARED.available_torque,
         {"coordinate": Arg(2, "count"), "speed": Arg([0.0, 150.0, 400.0], "array")}),
    Case("Mechanism.dissipated_power", FIVE.dissipated_power,
         {"q": Arg(Q, "array"), "qd": Arg(QD, "array"), "qdd": Arg(QDD, "array")}),
    # issue 14: exact derivatives
    Case("Mechanism.forward_dynamics_derivatives", FIVE.forward_dynamics_derivatives,
         {"q": Arg(Q, "array"), "qd": Arg(QD, "array"), "t": Arg(0.0), "tau": Arg([0.1, -0.2], "array")}),
    Case("Mechanism.inverse_dynamics_derivatives", FIVE.inverse_dynamics_derivatives,
         {"q": Arg(Q, "array"), "qd": Arg(QD, "array"), "qdd": Arg(QDD, "array")}),
    # issue 15: the regressor and identification
    Case("Mechanism.regressor", FIVE.regressor,
         {"q": Arg(RUN.q[:3], "array"), "qd": Arg(RUN.qd[:3], "array"), "qdd": Arg(RUN.qdd[:3], "array"),
          "x": Arg(RUN.x[:3], "array"), "xd": Arg(RUN.xd[:3], "array")}),
    Case("Mechanism.inverse_dynamics(x, xd)", FIVE.inverse_dynamics,
         {"q": Arg(RUN.q[:3], "array"), "qd": Arg(RUN.qd[:3], "array"), "qdd": Arg(RUN.qdd[:3], "array"),
          "x": Arg(RUN.x[:3], "array"), "xd": Arg(RUN.xd[:3], "array")}),
    Case("identify.base_parameters", lambda samples, seed: identify.base_parameters(PENDULUM, samples, seed),
         {"samples": Arg(20, "count"), "seed": Arg(1, "count")}),
    Case("identify.sample_states", lambda n, seed: identify.sample_states(PENDULUM, n, seed),
         {"n": Arg(5, "count"), "seed": Arg(1, "count")}),
    Case("BaseParameters.of", BASE.of, {"pi": Arg(list(FIVE.regressor_parameters.values()), "array")}),
    Case("identify.identify", lambda q, qd, qdd, tau: identify.identify(FIVE, q, qd, qdd, tau, base=BASE),
         {"q": Arg(ID_Q, "array"), "qd": Arg(ID_QD, "array"), "qdd": Arg(ID_QDD, "array"),
          "tau": Arg(ID_TAU, "array")}),
    Case("identify.differentiate", identify.differentiate,
         {"t": Arg(T_REC, "array"), "q": Arg(REC, "array"), "cutoff": Arg(10.0)}),
    Case("identify.lowpass", identify.lowpass, {"t": Arg(T_REC, "array"), "v": Arg(REC, "array"), "cutoff": Arg(10.0)}),
    Case("identify.inside", identify.inside, {"t": Arg(T_REC, "array"), "cutoff": Arg(10.0)}),
    Case("identify.excitation",
         lambda period, harmonics, amplitude, samples, max_evaluations, tau_max, qd_max, sigma_margin:
         identify.excitation(FIVE, period, harmonics, amplitude, samples, BASE, max_evaluations, tau_max, qd_max,
                             sigma_margin),
         {"period": Arg(1.0), "harmonics": Arg(1, "count"), "amplitude": Arg(0.3), "samples": Arg(12, "count"),
          "max_evaluations": Arg(3, "count"), "tau_max": Arg(None, "none-or-number"),
          "qd_max": Arg(None, "none-or-number"), "sigma_margin": Arg(None, "none-or-number")}),
    Case("Excitation.sample", EXC.sample, {"t": Arg([0.0, 0.25, 0.5], "array")}),
]


# ------------------------------------------------------------------ the oracle (tests/fuzzing.py)


def outcome(case: Case, arg: str | None, value: Any) -> str:
    """Run ``case`` with ``arg`` set to ``value``: 'ok', 'refused' or 'TypeError'; an
    AssertionError for a leaked error or a NaN or infinity in the result."""
    kind = case.args[arg].kind if arg is not None else ""
    return judge(lambda: case.run({} if arg is None else {arg: value}), arg, value, what=case.name,
                 wrong_type=arg is not None and is_wrong_type(value, kind), names=case.aliases.get(arg or "", ()))


# ------------------------------------------------------------------ the tests


@pytest.mark.parametrize("case", CASES, ids=lambda c: c.name)
def test_valid_arguments_give_a_finite_result(case):
    assert outcome(case, None, None) == "ok"


@pytest.mark.parametrize("case", CASES, ids=lambda c: c.name)
def test_every_argument_with_every_hostile_value(case):
    """The fixed lists: each argument of the case spoiled in turn by every hostile value
    and every wrong type. Every failure is listed, not only the first."""
    found = [f for arg, a in case.args.items()
             for f in failures_of(lambda v, arg=arg: outcome(case, arg, v), spoiled(a) + (WRONG_TYPES if a.types else []))]
    assert not found, "\n".join(found)


def random_value(arg: Arg) -> st.SearchStrategy[Any]:
    """Random hostile values of an argument's kind: any float (subnormals, huge, NaN), any
    integer, arrays of any such floats in the right or a wrong shape."""
    floats = st.floats(allow_nan=True, allow_infinity=True, allow_subnormal=True)
    if arg.kind in ("number", "none-or-number"):
        return st.one_of(floats, st.integers(-(2**80), 2**80))
    if arg.kind in ("count", "indices"):
        ints = st.integers(-(2**80), 2**80)
        return ints if arg.kind == "count" else st.lists(st.integers(-(2**62), 2**62), max_size=5)
    if arg.kind == "name":
        return st.text(max_size=20)
    if arg.kind == "array":
        shape = np.shape(arg.value)
        shapes = st.one_of(st.just(shape), st.lists(st.integers(0, 4), min_size=0, max_size=3).map(tuple))
        return shapes.flatmap(lambda s: st.lists(floats, min_size=int(np.prod(s)), max_size=int(np.prod(s)))
                              .map(lambda v, s=s: np.array(v, dtype=float).reshape(s)))
    return st.nothing()


@st.composite
def spoilt_calls(draw: st.DrawFn) -> tuple[Case, str, Any]:
    case = draw(st.sampled_from(CASES))
    arg = draw(st.sampled_from(list(case.args)))
    return case, arg, draw(random_value(case.args[arg]))


@settings(max_examples=FUZZ_EXAMPLES, deadline=None, suppress_health_check=list(HealthCheck))
@given(spoilt_calls())
def test_fuzz_random_hostile_arguments(call):
    case, arg, value = call
    outcome(case, arg, value)


def campaign(n: int) -> Counter[str]:
    """A longer campaign outside pytest: ``n`` random spoilt calls (hypothesis' draws, not
    shrunk); prints each distinct failure and returns the outcomes by kind."""
    counts: Counter[str] = Counter()
    failures: set[str] = set()

    @settings(max_examples=n, deadline=None, suppress_health_check=list(HealthCheck), database=None)
    @given(spoilt_calls())
    def one(call: tuple[Case, str, Any]) -> None:
        case, arg, value = call
        try:
            counts[f"{outcome(case, arg, value)}"] += 1
        except AssertionError as e:
            counts["failure"] += 1
            failures.add(str(e).splitlines()[0])

    one()
    for f in sorted(failures):
        print("FAIL", f)
    return counts


if __name__ == "__main__":
    n = int(sys.argv[1]) if len(sys.argv) > 1 else 2000
    print(f"{n} random spoilt calls over {len(CASES)} functions:", dict(campaign(n)))
