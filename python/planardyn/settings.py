"""The rule of each simulation setting, in one place for the API, the batch runner and the CLI.

Times and tolerances (``t_end``, ``rtol``, ``atol``, ``dt``, ``output_dt``) are finite numbers
> 0, the rule the model loader and the integrator's own check apply. ``atol = 0`` is refused
because the error scale is ``atol + rtol * |y_i|``: a state component that passes through 0
(an angle, a rate at rest) would have a zero scale, the step size would collapse and the run
end in "NaN or infinity" instead of an answer. ``rtol`` is also at least :data:`MIN_RTOL`
(below it the error test asks for more than double precision holds). ``max_steps`` is an integer in 1..=:data:`MAX_STEPS`.

A value that breaks its rule raises what ``Mechanism.simulate`` raises for it:
:class:`~planardyn.ArgumentError` (a ValueError) for ``t_end`` (an argument),
:class:`~planardyn.SimulationError` for a solver option, TypeError for something that is not
a number.
"""

from __future__ import annotations

import math
import sys
from typing import Any

from ._core import SimulationError
from .arguments import count, error

#: Settings that are finite numbers > 0 (s, or dimensionless for the tolerances).
POSITIVE = ("t_end", "rtol", "atol", "dt", "output_dt")
#: Smallest relative tolerance: 100 machine epsilons.
MIN_RTOL = 100 * sys.float_info.epsilon
#: Most step attempts a run may be given: days of computing at a microsecond a step.
MAX_STEPS = 10**12
#: Most native threads of a batch: far more than any machine's cores, far fewer than
#: would exhaust the system's thread table.
MAX_THREADS = 256


def _error(name: str, text: str) -> Exception:
    return error(name, text) if name == "t_end" else SimulationError(f"invalid option: {text}")


def positive(name: str, value: Any) -> float:
    """``value`` as a float if it is finite and > 0, else the error naming ``name``."""
    if isinstance(value, bool) or not isinstance(value, (int, float)) and not hasattr(value, "__float__"):
        raise TypeError(f"{name} = {value!r} must be a number, not {type(value).__name__}")
    try:
        x = float(value)
    except (OverflowError, ValueError):
        x = math.nan
    if not (math.isfinite(x) and x > 0.0):
        raise _error(name, f"{name} = {value!r} must be a finite number > 0")
    return x


def check_settings(**settings: Any) -> dict[str, Any]:
    """Check the given settings (None: not given, skipped) by their rules; returns them with
    numbers as float or int. Unnamed settings (``method``, ``t_eval``...) pass unchanged."""
    out = dict(settings)
    for name, value in settings.items():
        if value is None:
            continue
        if name in POSITIVE:
            out[name] = positive(name, value)
            if name == "rtol" and out[name] < MIN_RTOL:
                raise SimulationError(f"invalid option: rtol = {value!r} is below 100 machine epsilons and "
                                      f"cannot be met: use rtol >= {MIN_RTOL:.3g}")
        elif name == "max_steps":
            try:
                out[name] = count(name, value, 1, MAX_STEPS)
            except ValueError as e:
                raise SimulationError(f"invalid option: {e}") from None
    return out
