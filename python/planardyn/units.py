"""Units of a group of coordinates: an angle is in rad (driven by a torque, N m), a
displacement in m (driven by a force, N)."""

from __future__ import annotations

import math
import re
from collections.abc import Iterable


def group_unit(kinds: Iterable[str], angle: str, displacement: str, mixed: str = "mixed units") -> str:
    """The unit of coordinates of these kinds (``'angle'`` or ``'displacement'``): ``angle``
    when all are angles, ``displacement`` when all are displacements, else ``mixed``."""
    units = {angle if k == "angle" else displacement for k in kinds}
    return units.pop() if len(units) == 1 else mixed


#: Rate units of ``planardyn simulate --speed``: the kind of coordinate each fits and its
#: value in SI (rad/s or m/s).
RATE_UNITS = {
    "rad/s": ("angle", 1.0),
    "rev/s": ("angle", 2.0 * math.pi),
    "rpm": ("angle", 2.0 * math.pi / 60.0),
    "deg/s": ("angle", math.pi / 180.0),
    "m/s": ("displacement", 1.0),
    "mm/s": ("displacement", 1e-3),
}


def parse_rate(text: str, kind: str) -> float:
    """A rate such as ``"1rev/s"``, ``"60 rpm"`` or ``"0.2m/s"`` in SI (rad/s for an
    ``'angle'`` coordinate, m/s for a ``'displacement'``); a bare number is taken in SI.

    Raises
    ------
    ValueError
        Not a number with one of :data:`RATE_UNITS`, a unit of the other kind of coordinate,
        or not finite.
    """
    match = re.fullmatch(r"\s*([-+]?[0-9.]+(?:[eE][-+]?[0-9]+)?)\s*([a-z/]*)\s*", text)
    units = ", ".join(u for u, (k, _) in RATE_UNITS.items() if k == kind)
    if match is None or (match[2] and match[2] not in RATE_UNITS):
        raise ValueError(f"{text!r} is not a rate: give a number and one of {units}")
    try:
        value = float(match[1])
    except ValueError:
        raise ValueError(f"{text!r} is not a rate: give a number and one of {units}") from None
    unit_kind, factor = RATE_UNITS.get(match[2], (kind, 1.0))
    if unit_kind != kind:
        raise ValueError(f"{text!r} is a rate of {'an' if unit_kind == 'angle' else 'a'} {unit_kind}, "
                         f"but the coordinate is {'an' if kind == 'angle' else 'a'} {kind}: use {units}")
    if not math.isfinite(value * factor):
        raise ValueError(f"{text!r} is not a finite rate")
    return value * factor
