"""Events of a simulation, as in scipy's ``solve_ivp``: functions g(t, q, qd) whose zeros a
run reports in ``SimulationResult.t_events`` (with the states there), a terminal one ending
the run at its time.

An event is a callable ``g(t, q, qd) -> float`` (t in s, q and qd (m,) arrays) with optional
attributes ``terminal`` (bool, default False) and ``direction`` (> 0: only zeros where g
rises, < 0: only where it falls, 0 (default): both), or a :class:`Crossing` of a coordinate,
which the core evaluates without calling Python (an end stop, a crank angle reached).
"""

from __future__ import annotations

import math
from collections.abc import Callable, Iterable, Mapping, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import NDArray

from .arguments import error, number

#: g(t, q, qd) -> float.
EventFunction = Callable[[float, NDArray[np.float64], NDArray[np.float64]], float]


@dataclass(frozen=True)
class Crossing:
    """Coordinate ``coordinate`` (by name) crossing ``value`` (rad or m): g = q - value."""

    coordinate: str
    value: float
    terminal: bool = False
    direction: float = 0.0


Event = Crossing | EventFunction


def parse_crossing(text: str) -> Crossing:
    """A terminal :class:`Crossing` from the CLI's ``NAME=VALUE``, ``NAME>VALUE`` (rising
    through it) or ``NAME<VALUE`` (falling), e.g. ``theta=1.5`` or ``s>0.2``."""
    for op, direction in (("=", 0.0), (">", 1.0), ("<", -1.0)):
        name, sep, value = text.partition(op)
        if sep and name.strip():
            try:
                if math.isfinite(float(value)):
                    return Crossing(name.strip(), float(value), terminal=True, direction=direction)
            except ValueError:
                pass
            break
    raise ValueError(f"--stop-when {text!r}: write NAME=VALUE, NAME>VALUE (rising) or NAME<VALUE (falling), "
                     "a coordinate's name and a finite number in rad or m, e.g. theta=1.5")


def event_list(events: Event | Sequence[Event] | None) -> list[Event] | None:
    """``Mechanism.simulate``'s ``events`` as a list: one event alone (a function or a
    :class:`Crossing`) stands for the list of it, as in ``solve_ivp``."""
    if events is None:
        return None
    if isinstance(events, Crossing) or callable(events):
        return [events]
    if isinstance(events, (str, bytes, Mapping)) or not isinstance(events, Iterable):
        raise TypeError(f"events must be an event or a list of them (functions g(t, q, qd) -> float or "
                        f"planardyn.Crossing), got {type(events).__name__}")
    return list(events)


def native_events(events: Sequence[Event | Mapping[str, Any]] | None, names: list[str]) -> list[tuple[Any, ...]]:
    """``Mechanism.simulate``'s ``events`` as the native call takes them: (index, value,
    terminal, direction) for a crossing, (g, terminal, direction) for a function."""
    out: list[tuple[Any, ...]] = []
    for e in events or ():
        if isinstance(e, Mapping):  # a crossing as a results file's settings hold it
            e = Crossing(**e)
        if isinstance(e, Crossing):
            if e.coordinate not in names:
                raise error("events", f"event: unknown coordinate {e.coordinate!r}; coordinates are: {', '.join(names)}")
            value = number("event's value", e.value, "rad or m")
            out.append((names.index(e.coordinate), value, bool(e.terminal), number("event's direction", e.direction)))
        elif callable(e):
            out.append((e, bool(getattr(e, "terminal", False)),
                        number("event's direction", getattr(e, "direction", 0.0))))
        else:
            raise TypeError(f"an event is a function g(t, q, qd) -> float or a planardyn.Crossing, "
                            f"got {type(e).__name__}")
    return out
