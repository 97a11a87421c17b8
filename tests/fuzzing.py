"""The fuzz harness of tests/test_api_fuzz.py and tests/test_plan_fuzz.py (issue 23, finding 6):
the hostile values, the walk that finds a NaN or an infinity in a result, and the oracle that
judges one call with one spoilt argument.

The oracle (:func:`judge`): the call either

- returns a result with no NaN in it, nor an infinity where the function promises finite
  values (a plan's limits and stated accuracy are infinite where there is none);
- raises a :class:`~planardyn.PlanardynError` that is no internal error and, if it is an
  ``ArgumentError`` (the caller may ask it of every error), unless the value is of the wrong
  type or the error reports a result that overflows, names the argument: its attribute
  ``argument``, or its message (at its start where the caller asks) by its name or one of
  the other names the caller gives (a motion table's ``t`` is refused as "the motion
  table ...");
- raises one of the caller's ``answers`` (``InfeasiblePlan``: the reason, not an argument,
  is the message);
- raises ``TypeError`` for a value of the wrong type;

and, where the caller asks, warns nothing. Anything else (numpy's or scipy's ``ValueError``,
``ZeroDivisionError``, ``OverflowError``, ``LinAlgError``, toppra's or CasADi's errors...) is
a library error leaked to the user: a failure, raised as an ``AssertionError`` naming the
call, the argument and the value.
"""

from __future__ import annotations

import dataclasses
import math
import warnings
from collections.abc import Callable
from typing import Any

import numpy as np
import planardyn as pd
from planardyn import robot

NAN, INF = math.nan, math.inf

#: Numbers no argument should turn into a NaN, an overflow or a library's error: NaN, the
#: infinities, zeros, negatives, subnormal and huge magnitudes, integers beyond a float's
#: exact range.
NUMBERS: list[Any] = [NAN, INF, -INF, 0.0, -0.0, -1.0, -1e-300, 5e-324, 1e-300, 1e300, -1e300, 1e308, -1e308,
                      2**70, -(2**70)]
#: Values of the wrong type: a TypeError (or a PlanardynError) is the answer.
WRONG_TYPES: list[Any] = ["x", b"1", object(), {"a": 1}, [1.0, "a"], [[1.0], [1.0, 2.0]]]
#: Arrays no array argument should accept: empty, non-finite, of the wrong shape, a string.
ARRAYS: list[Any] = [[], [NAN], [INF], [[1.0, 2.0], [3.0, 4.0]], [[[0.0]]], "abc"]
#: Arrays of the right shape for one coordinate: huge, tiny, zero, negative.
ONE: list[Any] = [[1e300], [1e-300], [0.0], [-1.0], [-1e300]]


def non_finite(out: Any, where: str = "result", *, inf: bool = False, seen: set[int] | None = None) -> str | None:
    """Where the first NaN (``inf`` False: or infinity) in a result is (None: none), walking
    its numbers, arrays, containers and dataclasses; the mechanism and end effector a result
    refers to are inputs, not results, and are skipped."""
    seen = set() if seen is None else seen
    if id(out) in seen or isinstance(out, (pd.Mechanism, robot.EndEffector)):
        return None
    seen.add(id(out))
    if isinstance(out, (float, np.floating)):
        return where if math.isnan(out) or (math.isinf(out) and not inf) else None
    if isinstance(out, np.ndarray):
        if out.dtype.kind not in "fc":
            return None
        bad = np.isnan(out) if inf else ~np.isfinite(out)
        return where if bad.any() else None
    if isinstance(out, dict):
        items = list(out.items())
    elif isinstance(out, (list, tuple)):
        items = list(enumerate(out))
    elif dataclasses.is_dataclass(out) and not isinstance(out, type):
        items = [(f.name, getattr(out, f.name)) for f in dataclasses.fields(out)]
    else:
        return None
    return next((w for k, v in items if (w := non_finite(v, f"{where}[{k!r}]", inf=inf, seen=seen))), None)


def judge(call: Callable[[], Any], name: str | None, value: Any, *, what: str = "", wrong_type: bool = False,
          names: tuple[str, ...] = (), naming: type[BaseException] = pd.ArgumentError, start: bool = False,
          answers: tuple[type[BaseException], ...] = (), inf: bool = False, quiet: bool = False) -> str:
    """Run ``call()``, argument ``name`` (None: none spoilt) set to ``value``, against the
    oracle of the module: 'ok', 'refused', 'answered' or 'TypeError', or an AssertionError
    for a leaked error or a NaN result. ``what`` names the function in messages,
    ``wrong_type`` says the value is of the wrong type, ``names`` are other names an error
    may give the argument by, ``naming`` the errors that must name it (an assembly that
    fails at spoilt coordinates names no argument of a core function; a plan names it in
    every error) and ``start`` where (at the start of the message, else anywhere in it),
    ``inf`` allows infinities in the result, ``quiet`` turns a warning into a failure."""
    where = f"{what + ' with ' if what else ''}{name} = {value!r:.80}"
    with warnings.catch_warnings():
        warnings.simplefilter("error" if quiet else "ignore")
        try:
            out = call()
        except answers:
            return "answered"
        except pd.PlanardynError as e:
            msg = str(e)
            assert "internal error" not in msg, f"{where}: {msg}"
            overflow = getattr(e, "quantity", None) is not None  # finite arguments whose result overflows
            if isinstance(e, naming) and name is not None and not wrong_type and not overflow:
                called = (name, *names)
                named = getattr(e, "argument", None) in called or (
                    msg.startswith(called) if start else any(n in msg for n in called))
                assert named, f"{where}: the error does not name {name}: {msg}"
            return "refused"
        except TypeError as e:
            assert name is not None and wrong_type, f"{where}: TypeError for a value of the right type: {e}"
            return "TypeError"
        except Exception as e:  # noqa: BLE001 - what the test is for
            raise AssertionError(f"{where}: leaked {type(e).__module__}.{type(e).__name__}: {e}") from None
    bad = non_finite(out, inf=inf)
    assert bad is None, f"{where}: a NaN{'' if inf else ' or infinity'} in {bad}"
    return "ok"


def failures_of(judged: Callable[[Any], str], values: list[Any]) -> list[str]:
    """The failures of ``judged(value)`` (a :func:`judge` call) over ``values``, every one
    listed, not only the first."""
    out = []
    for value in values:
        try:
            judged(value)
        except AssertionError as e:
            out.append(str(e))
    return out
