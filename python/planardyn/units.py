"""Units of a group of coordinates: an angle is in rad (driven by a torque, N m), a
displacement in m (driven by a force, N)."""

from __future__ import annotations

from collections.abc import Iterable


def group_unit(kinds: Iterable[str], angle: str, displacement: str, mixed: str = "mixed units") -> str:
    """The unit of coordinates of these kinds (``'angle'`` or ``'displacement'``): ``angle``
    when all are angles, ``displacement`` when all are displacements, else ``mixed``."""
    units = {angle if k == "angle" else displacement for k in kinds}
    return units.pop() if len(units) == 1 else mixed
