"""Families of mechanisms of growing size, as planardyn model dicts (``planardyn.from_dict``).

- ``parallelograms(n)``: n parallelograms in a row, hanging from the ground: n + 1 rods of
  length 1 m hinged at (i, 0), their lower ends joined by n couplers. Rod: 1 kg, centre of mass
  at mid-length, inertia 0.25 kg m^2 about it; coupler: 1 kg uniform bar. Every rod then has
  J = m L^2 / 2 about its pivot and the couplers translate, so the kinetic and potential
  energies are those of (2n + 1) kg on a simple pendulum of length 1 m: theta'' = -g sin(theta)
  for every n, released from rest at ``theta0`` from the vertical (never near the horizontal, so
  no change point).
- ``five_bars(n)``: n passive five-bars (the 5R of examples/models/five-bar-free-fall.yaml,
  hanging below the ground) side by side, 0.6 m apart, each started from its stable pose with
  rates (1, -0.5) rad/s: 2n coordinates, the same small oscillation in every copy.
- ``ladder(n)``: a ladder of 2n - 1 five-bar loops, each sharing its rods with its neighbours:
  2n rods of 0.2 m hanging from the ground at (0.3 i, 0), their tips joined in turn by RRR dyads
  of two 0.25 m links (every link 1 kg per metre, uniform), started hanging with rates 1 and
  -0.5 rad/s on alternate rods: 2n coordinates (one per rod), coupled (rod i moves the dyads on
  both its sides, so A = U^T M U is tridiagonal, not block diagonal); n = 1 is a five-bar.
- ``a02(n)``: IFToMM benchmark A02, the N-four-bar: n + 1 upright rods of 1 m hinged to the
  ground at (i, 0), n couplers joining their tops, every link a uniform 1 kg bar, gravity -y,
  B0 (the first rod's top) moving at +1 m/s in x. One coordinate; its mobility jumps to n + 1
  whenever the rods are horizontal (the first time at t = 0.714 s for N = 2, 0.722 s for N = 40).
"""

from __future__ import annotations

import math
from typing import Any

G = 9.81


def _bar(a: list[float], b: list[float], mass: float) -> dict[str, Any]:
    length = math.dist(a, b)
    return {"mass": mass, "inertia": mass * length**2 / 12, "com": [(a[0] + b[0]) / 2, (a[1] + b[1]) / 2]}


def _direction(angle: float) -> tuple[float, float]:
    """(cos, sin) of `angle` rounded to multiples of 2^-40, so that i + cos is exact for every
    i < 2^12: the tips A_i = O_i + (cos, sin) are then drawn exactly one apart and every window is
    an exact parallelogram. Unrounded, cos(pi/2) = 6.1e-17 put A0 off the grid, coupler 1 came
    out 1.1e-16 m shorter than its ground, and the change points of that window were imperfect
    (not singular: a crossing with no rank drop, and 1.3e-6 rad from the reduction at N = 40). The
    rods are then 1 m to about 1e-12."""
    q = 2.0**40
    return round(math.cos(angle) * q) / q, round(math.sin(angle) * q) / q


def _chain(n: int, angle: float, rod: dict[str, float] | None, name: str, qd0: float) -> dict[str, Any]:
    """n + 1 rods of 1 m at `angle` (rad, from +x) hinged at (i, 0), tops joined by couplers."""
    c, s = _direction(angle)
    ground = {f"O{i}": [float(i), 0.0] for i in range(n + 1)}
    tips = {f"A{i}": [i + c, s] for i in range(n + 1)}
    bodies: dict[str, Any] = {}
    pairs: list[dict[str, Any]] = []
    for i in range(n + 1):
        o, a = ground[f"O{i}"], tips[f"A{i}"]
        props = _bar(o, a, 1.0) if rod is None else {**_bar(o, a, rod["mass"]), "inertia": rod["inertia"]}
        bodies[f"rod{i}"] = {"points": [f"O{i}", f"A{i}"], **props}
        pairs.append({"type": "revolute", "name": f"ground_rod{i}", "at": f"O{i}", "bodies": ["ground", f"rod{i}"]})
    for i in range(1, n + 1):
        a, b = tips[f"A{i - 1}"], tips[f"A{i}"]
        bodies[f"coupler{i}"] = {"points": [f"A{i - 1}", f"A{i}"], **_bar(a, b, 1.0)}
        pairs.append({"type": "revolute", "at": f"A{i - 1}", "bodies": [f"rod{i - 1}", f"coupler{i}"]})
        pairs.append({"type": "revolute", "at": f"A{i}", "bodies": [f"coupler{i}", f"rod{i}"]})
    return {
        "name": name,
        "units": "SI",
        "gravity": [0.0, -G],
        "points": {**ground, **tips},
        "ground": list(ground),
        "bodies": bodies,
        "pairs": pairs,
        "coordinates": [{"name": "theta", "pair": "ground_rod0", "value": angle, "qd0": qd0}],
    }


def parallelograms(n: int, theta0: float = math.radians(30)) -> dict[str, Any]:
    """n hanging parallelograms released from rest at theta0 (rad) from the vertical."""
    rod = {"mass": 1.0, "inertia": 0.25}
    return _chain(n, -math.pi / 2 + theta0, rod, f"{n} hanging parallelograms", 0.0)


def pendulum_period(theta0: float) -> float:
    """Period (s) of theta'' = -g sin(theta) from rest at theta0: 4 K(sin(theta0 / 2)) / sqrt(g)
    by the arithmetic-geometric mean (K(k) = pi / (2 AGM(1, sqrt(1 - k^2))))."""
    a, b = 1.0, math.cos(theta0 / 2)
    while abs(a - b) > 1e-16:
        a, b = (a + b) / 2, math.sqrt(a * b)
    return 4 * (math.pi / (2 * a)) / math.sqrt(G)


def a02(n: int) -> dict[str, Any]:
    """IFToMM A02 with n four-bar windows: rods upright, B0 at +1 m/s in x (theta' = -1 rad/s)."""
    return _chain(n, math.pi / 2, None, f"IFToMM A02 N-four-bar, N = {n}", -1.0)


def five_bars(n: int, gap: float = 0.6) -> dict[str, Any]:
    """n hanging 5R five-bars side by side (proximal 0.2 m, distal 0.25 m, base 0.2 m)."""
    s3 = math.sqrt(3)
    points: dict[str, list[float]] = {}
    ground: list[str] = []
    bodies: dict[str, Any] = {}
    pairs: list[dict[str, Any]] = []
    coordinates: list[dict[str, Any]] = []
    for k in range(n):
        x0 = k * gap
        p = {
            f"A1_{k}": [x0 - 0.1, 0.0],
            f"A2_{k}": [x0 + 0.1, 0.0],
            f"C1_{k}": [x0 - 0.2, -0.1 * s3],
            f"C2_{k}": [x0 + 0.2, -0.1 * s3],
            f"P_{k}": [x0, -0.1 * s3 - 0.15],
        }
        points.update(p)
        ground += [f"A1_{k}", f"A2_{k}"]
        links = [
            ("pl", "A1", "C1", 0.2),
            ("pr", "A2", "C2", 0.2),
            ("dl", "C1", "P", 0.25),
            ("dr", "C2", "P", 0.25),
        ]
        for name, a, b, mass in links:
            bodies[f"{name}{k}"] = {"points": [f"{a}_{k}", f"{b}_{k}"], **_bar(p[f"{a}_{k}"], p[f"{b}_{k}"], mass)}
        for at, b1, b2, pname in [
            ("A1", "ground", f"pl{k}", f"g_pl{k}"),
            ("C1", f"pl{k}", f"dl{k}", None),
            ("P", f"dl{k}", f"dr{k}", None),
            ("C2", f"dr{k}", f"pr{k}", None),
            ("A2", "ground", f"pr{k}", f"g_pr{k}"),
        ]:
            pairs.append(
                {"type": "revolute", "at": f"{at}_{k}", "bodies": [b1, b2], **({"name": pname} if pname else {})}
            )
        coordinates += [
            {"name": f"theta1_{k}", "pair": f"g_pl{k}", "value": -2 * math.pi / 3, "qd0": 1.0},
            {"name": f"theta2_{k}", "pair": f"g_pr{k}", "value": -math.pi / 3, "qd0": -0.5},
        ]
    return {
        "name": f"{n} hanging five-bars",
        "units": "SI",
        "gravity": [0.0, -G],
        "points": points,
        "ground": ground,
        "bodies": bodies,
        "pairs": pairs,
        "coordinates": coordinates,
    }


def ladder(n: int, gap: float = 0.3, rod: float = 0.2, link: float = 0.25) -> dict[str, Any]:
    """2n hanging rods (m) `gap` apart, consecutive tips joined by a dyad of two `link` links."""
    depth = math.sqrt(link**2 - (gap / 2) ** 2)
    points: dict[str, list[float]] = {}
    bodies: dict[str, Any] = {}
    pairs: list[dict[str, Any]] = []
    coordinates: list[dict[str, Any]] = []
    for i in range(2 * n):
        o, c = [gap * i, 0.0], [gap * i, -rod]
        points.update({f"O{i}": o, f"C{i}": c})
        bodies[f"rod{i}"] = {"points": [f"O{i}", f"C{i}"], **_bar(o, c, rod)}
        pairs.append({"type": "revolute", "name": f"g_rod{i}", "at": f"O{i}", "bodies": ["ground", f"rod{i}"]})
        coordinates.append({"name": f"theta{i}", "pair": f"g_rod{i}", "value": -math.pi / 2, "qd0": (1.0, -0.5)[i % 2]})
    for i in range(2 * n - 1):
        p = [gap * (i + 0.5), -rod - depth]
        points[f"P{i}"] = p
        for side, tip in (("l", i), ("r", i + 1)):
            bodies[f"{side}{i}"] = {"points": [f"C{tip}", f"P{i}"], **_bar(points[f"C{tip}"], p, link)}
            pairs.append({"type": "revolute", "at": f"C{tip}", "bodies": [f"rod{tip}", f"{side}{i}"]})
        pairs.append({"type": "revolute", "at": f"P{i}", "bodies": [f"l{i}", f"r{i}"]})
    return {
        "name": f"ladder of {2 * n - 1} five-bar loops",
        "units": "SI",
        "gravity": [0.0, -G],
        "points": points,
        "ground": [f"O{i}" for i in range(2 * n)],
        "bodies": bodies,
        "pairs": pairs,
        "coordinates": coordinates,
    }


FAMILIES = {"parallelograms": parallelograms, "five-bars": five_bars, "ladder": ladder, "a02": a02}
