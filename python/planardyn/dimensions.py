"""The dimensions of a mechanism as drawn, for ``planardyn check``: each body's lengths (from
its first point to each other one) and the direction of its first line, each pair's own
dimensions (a gear's pitch radii, a guide's direction), and the coordinates of the points a
model file gives by construction (``planardyn docs model-format``, "Points by construction"),
which the loader placed."""

from __future__ import annotations

import math
import os
from collections.abc import Sequence

from ._core import resolve_model
from .mechanism import Mechanism

__all__ = ["constructed_points", "report"]

#: A coordinate below this fraction of the mechanism's size is printed as 0: the round-off of a
#: construction (sin 180 deg = 1.2e-16, not 0), not a dimension.
ROUND_OFF = 1e-12


def constructed_points(path: str | os.PathLike[str]) -> list[str]:
    """The names of the points the model file ``path`` gives by construction."""
    fmt = "json" if os.fspath(path).lower().endswith(".json") else "yaml"
    with open(path, encoding="utf-8") as f:
        _, names = resolve_model(f.read(), fmt, os.fspath(path))
    return names


def report(mech: Mechanism, constructed: Sequence[str] = ()) -> str:
    """The dimensions of ``mech`` as drawn (m, deg), and where the ``constructed`` points are."""
    where = {n: (float(p[0]), float(p[1])) for n, p in zip(mech.point_names, mech.point_positions(mech.x0))}
    lines = ["dimensions of the drawing (m, angles in deg from the x axis):"]
    for body, pts in zip(mech.body_names, mech.body_points):
        names = [n for n, _ in pts]
        if len(names) < 2:
            continue
        first = names[0]
        lengths = ", ".join(f"{first}-{n} {_length(where[first], where[n]):.6g}" for n in names[1:])
        lines.append(f"  {body}: {lengths}; {first}->{names[1]} at {_angle(where[first], where[names[1]]):.6g} deg")
    for pair in mech.to_dict()["pairs"]:
        label = pair.get("name", pair["type"])
        if pair["type"] == "gear":
            lines.append(f"  {label} (gear): pitch radii {', '.join(f'{r:.6g}' for r in pair['radii'])}")
        elif "axis" in pair:
            lines.append(f"  {label} ({pair['type']}): guide at {math.degrees(math.atan2(pair['axis'][1], pair['axis'][0])):.6g} deg")
        elif "along" in pair:
            a, b = pair["along"]
            lines.append(f"  {label} ({pair['type']}): guide {a}->{b} at {_angle(where[a], where[b]):.6g} deg")
    if constructed:
        lines.append("points by construction:")
        tiny = ROUND_OFF * mech.scale
        for n in constructed:
            x, y = (0.0 if abs(v) < tiny else v for v in where[n])
            lines.append(f"  {n} = ({x:.9g}, {y:.9g})")
    return "\n".join(lines)


def _length(p: tuple[float, float], q: tuple[float, float]) -> float:
    return math.hypot(q[0] - p[0], q[1] - p[1])


def _angle(p: tuple[float, float], q: tuple[float, float]) -> float:
    return math.degrees(math.atan2(q[1] - p[1], q[0] - p[0]))
