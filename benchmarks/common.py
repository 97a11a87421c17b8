"""What every peer module shares: a mechanism as drawn, the accuracy measures, the timer.

A benchmark mechanism is read from its planardyn model file (``examples/models/*.yaml``,
the validation benchmarks of tests/data/benchmarks reproduced exactly) by ``load_drawing``, independently of planardyn,
so that every tool models the same numbers: points, bodies (mass, inertia about the centre
of mass, centre of mass, in any of the file's inertia forms), revolute pairs, the
generalized coordinates, constant drive efforts, linear springs and gravity. Each tool's
bodies get frames that are world-aligned in the drawing (every body angle 0 there), which
makes every initial state exactly assembled; the runs start at rest.

Accuracy, the same for every tool:

- energy: E = sum 1/2 m v^2 + 1/2 I w^2 - m g.r of the centres of mass + sum 1/2 k (L - L0)^2
  of the springs - the work of the drives' constant efforts, sum tau (q - q0). For a passive
  mechanism this is the energy; for a driven one the energy balance. Drift: max over every
  step of |E(t) - E(0)| (J);
- loop gap: max over every step and every pair of the distance (m) between the pair's point
  as carried by its two bodies (for a tree joint it is round-off: it matters for the pairs
  that close loops);
- error: max over the grid times and the coordinates of |q(t) - q_ref(t)| (rad), against
  planardyn with DOP853 at rtol = atol = 1e-13; a run of n fixed steps is sampled at its steps
  nearest the grid times and the reference at the same times (``Benchmark.sample_indices``).
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any, Protocol

import cheapest
import numpy as np


@dataclass(frozen=True)
class Body:
    name: str
    mass: float  # kg
    inertia: float  # kg m^2, about the centre of mass
    com: np.ndarray  # (2,) m, in the drawing


@dataclass(frozen=True)
class Pair:
    """A revolute pair: b turns relative to a about the drawn point."""

    name: str
    a: str  # body name, or "ground"
    b: str
    point: str


@dataclass(frozen=True)
class Spring:
    """A linear spring between a point of body a and one of body b (either may be ground)."""

    a: str
    point_a: str
    b: str
    point_b: str
    stiffness: float  # N/m
    rest_length: float  # m


@dataclass(frozen=True)
class Coordinate:
    name: str
    pair: Pair
    value: float  # rad, in the drawing
    effort: float  # N m, constant


@dataclass(frozen=True)
class Drawing:
    """The mechanism as drawn: points (m), bodies, pairs, coordinates, springs, gravity (m/s^2)."""

    name: str
    points: dict[str, np.ndarray]
    bodies: dict[str, Body]
    pairs: list[Pair]
    coordinates: list[Coordinate]
    springs: list[Spring]
    gravity: np.ndarray

    def point_on(self, body: str, point: str) -> np.ndarray:
        """(2,) a drawn point relative to the body's centre of mass (ground: to the origin)."""
        return self.points[point] - (0.0 if body == "ground" else self.bodies[body].com)

    def tree(self) -> tuple[list[Pair], list[Pair]]:
        """A spanning tree of the pairs, for the tools that model a kinematic tree plus
        loop-closure constraints: (tree pairs, each oriented parent a -> child b, in depth-first
        order; the closing pairs). The tree is grown breadth-first from ground (short chains),
        the coordinates' pairs first, so that every drive acts on a tree joint."""
        coord = {c.pair.name for c in self.coordinates}
        pending = sorted(self.pairs, key=lambda p: p.name not in coord)
        queue, placed, tree = ["ground"], {"ground"}, []
        for body in queue:  # the queue grows while it is walked
            for p in [p for p in pending if body in (p.a, p.b)]:
                child = p.b if p.a == body else p.a
                if child in placed:
                    continue
                tree.append(p if p.a == body else Pair(p.name, p.b, p.a, p.point))
                pending.remove(p)
                placed.add(child)
                queue.append(child)
        # Depth-first order (each subtree contiguous): Pinocchio's sparse algorithms need it.
        order: list[Pair] = []

        def visit(body: str) -> None:
            for p in tree:
                if p.a == body:
                    order.append(p)
                    visit(p.b)

        visit("ground")
        tree = order
        if placed != {"ground", *self.bodies}:
            raise ValueError(f"{self.name}: bodies {sorted(set(self.bodies) - placed)} are not connected to ground")
        for c in self.coordinates:
            if c.pair not in tree:
                raise NotImplementedError(f"{self.name}: coordinate {c.name}'s pair must be a tree joint a -> b")
        return tree, pending


def _xy(spec: dict, v) -> np.ndarray:
    return np.array(spec["points"][v] if isinstance(v, str) else v, dtype=float)


def _inertia(spec: dict, part: dict) -> tuple[float, float, np.ndarray]:
    """(mass, inertia about the CoM, CoM) of a body or part in any of the file's forms."""
    m = float(part.get("mass", 0.0))
    if "parts" in part:
        parts = [_inertia(spec, p) for p in part["parts"]]
        m = sum(p[0] for p in parts)
        com = sum(p[0] * p[2] for p in parts) / m
        return m, sum(p[1] + p[0] * float(np.sum((p[2] - com) ** 2)) for p in parts), com
    if "uniform_bar" in part:
        p, q = (_xy(spec, k) for k in part["uniform_bar"])
        return m, m * float(np.sum((q - p) ** 2)) / 12.0, 0.5 * (p + q)
    if "point_mass" in part or "point_mass_at" in part:
        return m, 0.0, _xy(spec, part.get("point_mass", part.get("point_mass_at")))
    return m, float(part.get("inertia", part.get("inertia_about_com"))), _xy(spec, part["com"])


def load_drawing(spec: dict) -> Drawing:
    """The drawing from a model-file dict (``Benchmark.spec``). Raises NotImplementedError for
    what the peer models do not handle (prismatic pairs, tables, dampers, ...): none of the
    benchmark mechanisms uses it."""
    points = {k: np.array(v, dtype=float) for k, v in spec["points"].items()}
    bodies = {k: Body(k, *_inertia(spec, b)) for k, b in spec["bodies"].items()}
    pairs = []
    for p in spec["pairs"]:
        if p.get("type", "revolute") != "revolute":
            raise NotImplementedError(f"{spec['name']}: only revolute pairs")
        a, b = p["bodies"]
        pairs.append(Pair(p.get("name", f"{a}-{b}@{p['at']}"), a, b, p["at"]))
    by_name = {p.name: p for p in pairs}
    efforts = {}
    for d in spec.get("drives", []):
        if "effort" not in d:
            raise NotImplementedError(f"{spec['name']}: drive on {d['coordinate']} is not a constant effort")
        efforts[d["coordinate"]] = float(d["effort"])
    coords = []
    for c in spec["coordinates"]:
        if c.get("qd0", 0.0) != 0.0 or "q0" in c:
            raise NotImplementedError(f"{spec['name']}: the peers start from rest in the drawing")
        coords.append(Coordinate(c["name"], by_name[c["pair"]], float(c["value"]), efforts.get(c["name"], 0.0)))
    springs = []
    for ld in spec.get("loads", []):
        if ld["type"] != "spring" or ld.get("damping", 0.0) != 0.0:
            raise NotImplementedError(f"{spec['name']}: only undamped linear springs")
        (a, pa), (b, pb) = ld["between"]
        rest = ld.get("rest_length", float(np.linalg.norm(points[pa] - points[pb])))
        springs.append(Spring(a, pa, b, pb, float(ld["stiffness"]), float(rest)))
    gravity = np.array(spec.get("gravity", [0.0, 0.0]), dtype=float)
    return Drawing(spec["name"], points, bodies, pairs, coords, springs, gravity)


# --------------------------------------------------------------------------- measures
# Poses: per body (N, 3) [X, Y, phi] of the centre of mass, phi measured from the drawing;
# rates: per body (N, 3) [vx, vy, w] of the centre of mass.


def carried_point(d: Drawing, body: str, point: str, pose: np.ndarray | None) -> np.ndarray:
    """(N, 2) world position of a drawn point as carried by a body at (N, 3) poses
    (ground: pose None, the drawn point)."""
    if body == "ground":
        return d.points[point][None, :]
    s = d.point_on(body, point)
    c, sn = np.cos(pose[:, 2]), np.sin(pose[:, 2])
    return np.c_[pose[:, 0] + c * s[0] - sn * s[1], pose[:, 1] + sn * s[0] + c * s[1]]


def coordinates(d: Drawing, poses: dict[str, np.ndarray]) -> np.ndarray:
    """(N, m) generalized coordinates: q = value + phi_b - phi_a, each pair's relative turn."""
    def phi(body: str):
        return 0.0 if body == "ground" else poses[body][:, 2]
    return np.stack([c.value + phi(c.pair.b) - phi(c.pair.a) for c in d.coordinates], axis=1)


def energy(d: Drawing, poses: dict[str, np.ndarray], rates: dict[str, np.ndarray]) -> np.ndarray:
    """(N,) energy, or energy balance with the drives' work subtracted (J); see the module."""
    e = 0.0
    for name, b in d.bodies.items():
        v, p = rates[name], poses[name]
        e = e + 0.5 * b.mass * (v[:, 0] ** 2 + v[:, 1] ** 2) + 0.5 * b.inertia * v[:, 2] ** 2
        e = e - b.mass * (d.gravity[0] * p[:, 0] + d.gravity[1] * p[:, 1])
    for s in d.springs:
        gap = carried_point(d, s.a, s.point_a, poses.get(s.a)) - carried_point(d, s.b, s.point_b, poses.get(s.b))
        e = e + 0.5 * s.stiffness * (np.hypot(gap[:, 0], gap[:, 1]) - s.rest_length) ** 2
    q = coordinates(d, poses)
    for i, c in enumerate(d.coordinates):
        e = e - c.effort * (q[:, i] - c.value)
    return np.asarray(e)


def loop_gap(d: Drawing, poses: dict[str, np.ndarray]) -> np.ndarray:
    """(N,) the largest distance (m) between a pair's point as carried by its two bodies."""
    gaps = []
    for p in d.pairs:
        g = carried_point(d, p.a, p.point, poses.get(p.a)) - carried_point(d, p.b, p.point, poses.get(p.b))
        gaps.append(np.hypot(g[:, 0], g[:, 1]))
    return np.max(np.broadcast_arrays(*gaps), axis=0)


@dataclass(frozen=True)
class Variant:
    """One method of one tool (an integrator with its constraint handling and gains), whose cost
    is swept along one integer setting by ``cheapest.cheapest``: the number of fixed steps n over
    the run (dt = t_end / n), or for an adaptive integrator the tolerance index k
    (rtol = atol = ``cheapest.rtol(k)``)."""

    tool: str
    method: str  # for the tables
    params: tuple  # the tool's own parameters of the method
    #: (cheapest, dearest) number of steps over the run to search; None: a tolerance index instead.
    steps: tuple[int, int] | None

    def grid(self) -> list[int]:
        """The settings to scan, cheapest first, each within cheapest.SCAN_RATIO of the one before."""
        if self.steps is None:
            return cheapest.tolerance_grid(*TOLERANCE_RANGE)
        return cheapest.steps_grid(*self.steps)

    def label(self, t_end: float, s: int) -> str:
        """The setting as a user would write it: rtol, or the number of steps and dt."""
        if self.steps is None:
            return f"rtol={cheapest.rtol(s):.3g}"
        return f"n={s} (dt={t_end / s:.4g} s)"


#: The loosest and the tightest rtol (= atol) an adaptive method is searched over.
TOLERANCE_RANGE = (1.0, 1e-12)


def one_shot(fn: Callable[[], Any]) -> tuple[float, Any]:
    """The wall time (s) of one call of fn and its result: the search's own runs, which only
    place a setting on the work-precision plot (timing.py measures the winners properly)."""
    t0 = time.perf_counter()
    out = fn()
    return time.perf_counter() - t0, out


class ReferenceFailed(RuntimeError):
    """The reference run failed: a fault of the benchmark, never of the tool being measured."""


class Reference(Protocol):
    """The reference coordinates (K, m) in rad at the times a run is sampled at (planardyn_peer's)."""

    def grid(self) -> np.ndarray:
        """At the grid times ``Benchmark.grid_times``."""
        ...

    def steps(self, n: int) -> np.ndarray:
        """At the steps of a run of n fixed steps nearest the grid times (``Benchmark.sample_times``)."""
        ...


@dataclass
class Run:
    """One setting of one tool on one mechanism: what it cost and how accurate it was."""

    tool: str
    method: str  # integrator and constraint handling, for the table (Variant.method)
    setting: str  # the swept setting, for the table (Variant.label)
    value: int = 0  # the setting as cheapest.py searches it: steps, or tolerance index
    mechanism: str = ""  # Benchmark.key, set by bench.py
    ok: bool = True
    note: str = ""
    wall: float = math.nan  # s, one call (the search's run; timing.py times the winners)
    steps: int = 0
    drift: float = math.nan  # J
    gap: float = math.nan  # m
    error: float = math.nan  # rad, max over the grid and the coordinates against the reference
    q_end: list[float] = field(default_factory=list)  # rad, the coordinates at t_end
    e0: float = math.nan  # J, the tool's own start energy (a check of the model)
    extra: dict[str, Any] = field(default_factory=dict)

    def finish(self, e: np.ndarray, gap: np.ndarray, q_grid: np.ndarray, ref_grid: np.ndarray) -> Run:
        """Fill the accuracy fields from per-step energy and gap and the (K, m) coordinates at
        the grid times. A non-finite value anywhere marks the run as failed."""
        if not (np.all(np.isfinite(e)) and np.all(np.isfinite(gap)) and np.all(np.isfinite(q_grid))):
            self.ok = False
            self.note = self.note or "non-finite state (unstable)"
        with np.errstate(invalid="ignore"):
            self.e0 = float(e[0])
            self.drift = float(np.max(np.abs(e - e[0])))
            self.gap = float(np.max(gap))
            self.error = float(np.max(np.abs(q_grid - ref_grid)))
            self.q_end = [float(v) for v in q_grid[-1]]
        if not self.ok:
            self.drift = self.gap = self.error = math.nan
        return self

    def fail(self, why: str) -> Run:
        self.ok, self.note = False, why
        return self

    def meets(self, drift: float | None = None, gap: float | None = None, error: float | None = None) -> bool:
        return (self.ok and (drift is None or self.drift < drift) and (gap is None or self.gap < gap)
                and (error is None or self.error < error))
