"""What every peer module shares: the four-bar as drawn, the accuracy measures, the timer.

The four-bar is read from ``examples/models/four-bar-gravity.yaml`` (the shared benchmark
``four-bar-gravity.json`` reproduced exactly), so every tool models the same numbers.
Each tool's bodies are given frames that are world-aligned in the drawing (q = 0 there),
which makes every initial state exactly assembled and at rest.

Accuracy, the same for every tool:

- energy drift: max over every step of |E(t) - E(0)| (J), E = sum 1/2 m v^2 + 1/2 I w^2 + m g y
  of the centres of mass (the model's potential: zero at y = 0);
- loop gap: max over every step of the distance (m) between the two copies of a closing
  joint (the point B as carried by the coupler and by the rocker);
- error: max over t = 0, 0.1, ..., 10 s of |theta1(t) - theta1_ref(t)| (rad), theta1 the
  crank's absolute angle, against planardyn with DOP853 at rtol = atol = 1e-13.
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
import yaml

ROOT = Path(__file__).resolve().parent.parent
MODEL = ROOT / "examples" / "models" / "four-bar-gravity.yaml"

#: Targets of issue 6 for the peers (J, m) and for planardyn (J).
PEER_DRIFT_TARGET = 1e-3
PEER_GAP_TARGET = 1e-6
PLANARDYN_DRIFT_TARGET = 1e-6
#: Simulated time (s) and the spacing of the error samples (s): every fixed step in the
#: sweeps divides it, so each tool has a state exactly at every sample time.
T_END = 10.0
GRID_DT = 0.1


@dataclass(frozen=True)
class Body:
    name: str
    mass: float  # kg
    inertia: float  # kg m^2, about the centre of mass
    com: np.ndarray  # (2,) m, in the drawing


@dataclass(frozen=True)
class FourBar:
    """The drawing: points (m), bodies, gravity (m/s^2), the crank's start angle (rad)."""

    points: dict[str, np.ndarray]
    bodies: dict[str, Body]
    gravity: np.ndarray
    theta1_0: float

    @property
    def g(self) -> float:
        """Gravity's magnitude (m/s^2), acting along -y."""
        return float(-self.gravity[1])


def load_four_bar(path: Path = MODEL) -> FourBar:
    spec = yaml.safe_load(path.read_text())
    points = {k: np.array(v, dtype=float) for k, v in spec["points"].items()}
    bodies = {
        k: Body(k, float(b["mass"]), float(b["inertia"]), np.array(b["com"], dtype=float))
        for k, b in spec["bodies"].items()
    }
    gravity = np.array(spec["gravity"], dtype=float)
    assert gravity[0] == 0.0, "the peers put gravity along -y"
    assert set(bodies) == {"crank", "coupler", "rocker"} and set(points) == {"O", "A", "B", "D"}
    (coord,) = spec["coordinates"]
    assert coord.get("qd0", 0.0) == 0.0, "released from rest"
    return FourBar(points, bodies, gravity, float(coord["value"]))


def energy(fb: FourBar, poses: dict[str, np.ndarray], rates: dict[str, np.ndarray]) -> np.ndarray:
    """(N,) total energy (J) from per-body (N, 3) [X, Y, phi] and (N, 3) rates of the CoM."""
    e = 0.0
    for name, b in fb.bodies.items():
        v = rates[name]
        e = e + 0.5 * b.mass * (v[:, 0] ** 2 + v[:, 1] ** 2) + 0.5 * b.inertia * v[:, 2] ** 2
        e = e + b.mass * fb.g * poses[name][:, 1]
    return np.asarray(e)


def carried_point(fb: FourBar, body: str, point: str, pose: np.ndarray) -> np.ndarray:
    """(N, 2) world position of a drawn point as carried by a body at (N, 3) poses whose
    angle phi is 0 in the drawing."""
    s = fb.points[point] - fb.bodies[body].com
    c, sn = np.cos(pose[:, 2]), np.sin(pose[:, 2])
    return np.c_[pose[:, 0] + c * s[0] - sn * s[1], pose[:, 1] + sn * s[0] + c * s[1]]


def loop_gap(fb: FourBar, poses: dict[str, np.ndarray]) -> np.ndarray:
    """(N,) distance (m) between B on the coupler and B on the rocker."""
    d = carried_point(fb, "coupler", "B", poses["coupler"]) - carried_point(fb, "rocker", "B", poses["rocker"])
    return np.hypot(d[:, 0], d[:, 1])


def grid_times() -> np.ndarray:
    n = int(round(T_END / GRID_DT))
    return np.arange(n + 1) * GRID_DT


def grid_indices(dt: float) -> np.ndarray:
    """Step indices of the grid times for a fixed step dt that divides GRID_DT."""
    k = GRID_DT / dt
    assert abs(k - round(k)) < 1e-9, f"dt = {dt} does not divide {GRID_DT}"
    return np.arange(len(grid_times())) * int(round(k))


def best_time(fn: Callable[[], Any], *, budget: float = 1.0, max_repeats: int = 5) -> tuple[float, Any]:
    """Run fn at least twice (one warm-up if it is quick), up to max_repeats or until budget
    seconds have gone; return the best wall time (s) and the last result."""
    times = []
    out = None
    start = time.perf_counter()
    while True:
        t0 = time.perf_counter()
        out = fn()
        times.append(time.perf_counter() - t0)
        if len(times) >= max_repeats or (len(times) >= 2 and time.perf_counter() - start > budget):
            break
    return min(times), out


@dataclass
class Run:
    """One setting of one tool: what it cost and how accurate it was."""

    tool: str
    method: str  # integrator and constraint handling, for the table
    setting: str  # the swept parameter(s), for the table
    ok: bool = True
    note: str = ""
    wall: float = math.nan  # s, best of the repeats
    steps: int = 0
    drift: float = math.nan  # J
    gap: float = math.nan  # m
    error: float = math.nan  # rad, max over the grid against the reference
    theta_end: float = math.nan  # rad
    e0: float = math.nan  # J, the tool's own start energy (a check of the model)
    extra: dict[str, Any] = field(default_factory=dict)

    def finish(self, e: np.ndarray, gap: np.ndarray, theta_grid: np.ndarray, ref_grid: np.ndarray) -> Run:
        """Fill the accuracy fields from per-step energy and gap and the crank angle at the
        grid times. A non-finite value anywhere marks the run as failed."""
        if not (np.all(np.isfinite(e)) and np.all(np.isfinite(gap)) and np.all(np.isfinite(theta_grid))):
            self.ok = False
            self.note = self.note or "non-finite state (unstable)"
        with np.errstate(invalid="ignore"):
            self.e0 = float(e[0])
            self.drift = float(np.max(np.abs(e - e[0])))
            self.gap = float(np.max(gap))
            self.error = float(np.max(np.abs(theta_grid - ref_grid)))
            self.theta_end = float(theta_grid[-1])
        if not self.ok:
            self.drift = self.gap = self.error = math.nan
        return self

    def meets(self, drift: float, gap: float | None = None) -> bool:
        return self.ok and self.drift < drift and (gap is None or self.gap < gap)
