"""The rule of each simulation setting, the same for the API, the batch runner and the CLI.

The rules are the core's (``planardyn::error::Setting``, through ``_core.check_setting``), the
ones a run applies whoever made its settings: times and tolerances (``t_end``, ``rtol``,
``atol``, ``dt``, ``output_dt``) are finite numbers > 0; ``atol = 0`` is refused because the
error scale is ``atol + rtol * |y_i|``: a state component that passes through 0 (an angle, a
rate at rest) would have a zero scale, the step size would collapse and the run end in "NaN or
infinity" instead of an answer. ``rtol`` is also at least :data:`MIN_RTOL` (below it the error
test asks for more than double precision holds) and at most 1 (above it a step's error may
exceed the state itself). ``max_steps`` is an integer in
1..=:data:`MAX_STEPS`.

A value that breaks its rule raises what ``Mechanism.simulate`` raises for it:
:class:`~planardyn.ArgumentError` (a ValueError) for ``t_end`` (an argument),
:class:`~planardyn.SimulationError` for a solver option. What stays here is what cannot reach
the core: a value that is not a number (or for ``max_steps`` not an integer) is a TypeError
before it is converted.
"""

from __future__ import annotations

import math
import operator
from typing import Any

from ._core import MAX_STEPS, MIN_RTOL, check_setting

__all__ = ["MAX_STEPS", "MAX_THREADS", "MIN_RTOL", "NUMBERS", "check_settings", "convert_numbers", "convert_settings"]

#: Settings that are numbers (s, or dimensionless for the tolerances).
NUMBERS = ("t_end", "rtol", "atol", "dt", "output_dt")
#: Most native threads of a batch: far more than any machine's cores, far fewer than
#: would exhaust the system's thread table.
MAX_THREADS = 256
#: The types of a number setting that needs no conversion (a float, or None: not given).
_AS_GIVEN = frozenset({float, type(None)})


def _number(name: str, value: Any) -> float:
    """``value`` as a float (an int too large for one is infinite), or the TypeError naming ``name``."""
    if isinstance(value, bool) or not isinstance(value, (int, float)) and not hasattr(value, "__float__"):
        raise TypeError(f"{name} = {value!r} must be a number, not {type(value).__name__}")
    try:
        return float(value)
    except OverflowError:
        return math.inf if value > 0 else -math.inf
    except ValueError:
        return math.nan


def _integer(name: str, value: Any) -> int:
    """``value`` as an int, or the TypeError naming ``name``."""
    if isinstance(value, bool):
        raise TypeError(f"{name} = {value!r} must be an integer, not bool")
    try:
        return operator.index(value)
    except TypeError:
        raise TypeError(f"{name} = {value!r} must be an integer, not {type(value).__name__}") from None


def check_settings(**settings: Any) -> dict[str, Any]:
    """Check the given settings (None: not given, skipped) by their rules; returns them with
    numbers as float or int. Unnamed settings (``method``, ``t_eval``...) pass unchanged."""
    out = convert_settings(**settings)
    for name in NUMBERS:
        if out.get(name) is not None:
            out[name] = check_setting(name, out[name])
    return out


def convert_settings(**settings: Any) -> dict[str, Any]:
    """:func:`check_settings` but for the rules of the numbers, left to the run, which applies
    the same core check with the same errors (``Mechanism.simulate``: checked once); only a
    number that is not one is a TypeError here. ``max_steps``'s range is checked here, since
    a count out of it could not become the native integer."""
    out = dict(settings)
    for name, value in settings.items():
        if value is None:
            continue
        if name in NUMBERS:
            out[name] = _number(name, value)
        elif name == "max_steps":
            n = _integer(name, value)
            check_setting(name, float(n))
            out[name] = n
    return out


def convert_numbers(
    t_end: Any, rtol: Any, atol: Any, dt: Any, output_dt: Any, max_steps: Any
) -> tuple[float | None, float | None, float | None, float | None, float | None, int | None]:
    """:func:`convert_settings` of ``Mechanism.simulate``'s numbers, in this order: floats and
    None, the common case, pass as given after one set test (a short run's fixed cost, issue 25
    item 4); anything else is converted, or refused, by :func:`convert_settings`."""
    if max_steps is None and {type(t_end), type(rtol), type(atol), type(dt), type(output_dt)} <= _AS_GIVEN:
        return t_end, rtol, atol, dt, output_dt, None
    c = convert_settings(t_end=t_end, rtol=rtol, atol=atol, dt=dt, output_dt=output_dt, max_steps=max_steps)
    return c["t_end"], c["rtol"], c["atol"], c["dt"], c["output_dt"], c["max_steps"]
