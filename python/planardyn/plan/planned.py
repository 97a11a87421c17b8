"""What every planned motion offers (:class:`PlannedMotion`): its duration, the motion tables
``Mechanism.simulate(motion=...)`` takes, and the open-loop replay of its efforts."""

from __future__ import annotations

from dataclasses import dataclass
from functools import cached_property
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from .._core import ArgumentError
from ..mechanism import Mechanism
from ..notebook import Summarized, peak_rows
from ..result import SimulationResult
from ..robot.sizing import lowest_first_frequency

FloatArray = NDArray[np.float64]


class PlanError(ArgumentError):
    """A path, limits or an argument that cannot be planned with, with what to change;
    ``argument`` names the argument at fault (None when it is the plan as a whole)."""

    def __init__(self, message: str, argument: str | None = None) -> None:
        super().__init__(message)
        self.argument = argument


class InfeasiblePlan(PlanError):
    """No motion keeps the limits: the message says which and what to change."""


@dataclass(repr=False)
class PlannedMotion(Summarized):
    """A motion from rest to rest with the efforts that run it.

    It holds ``mech``, the grid times ``t`` (N,) (s), and ``q``, ``qd``, ``qdd``, ``tau``
    (N, m) there, and ``limit_ratio``: the largest fraction of an effort, motor torque or
    speed limit the motion uses on a dense check of its own path between the grid points
    (1: a limit reached; each subclass says how it checks); subclasses give :meth:`state`
    and :meth:`efforts` between the grid points. ``first_frequency``: for a model with a
    ``compliance:`` section, the lowest first natural frequency (Hz) at the grid points,
    rotors held (docs/stiffness.md), and the time (s) it is reached; None for a rigid model.
    ``motor_sizing(mech, k, plan.t, plan.qd[:, k], plan.tau[:, k])`` (planardyn.robot.sizing)
    sizes a drive on it.
    """

    mech: Mechanism
    t: FloatArray
    q: FloatArray
    qd: FloatArray
    qdd: FloatArray
    tau: FloatArray
    limit_ratio: float

    def __repr__(self) -> str:
        return (f"{type(self).__name__}({self.mech.name}: {self.duration:.6g} s, limits used to "
                f"{self.limit_ratio:.10g} on the dense check; {self._summary()})")

    def _summary(self) -> str:
        return f"{len(self.t)} grid points"

    def _summary_rows(self) -> list[tuple[str, str]]:
        return [("model", self.mech.name), ("duration", f"{self.duration:.6g} s"),
                ("limits used", f"{self.limit_ratio:.6g} of the largest (dense check)"),
                *peak_rows(self.mech, self.tau, self.qd), ("solution", self._summary()), *self.frequency_rows()]

    @cached_property
    def first_frequency(self) -> tuple[float, float] | None:
        """(f, t): the lowest first natural frequency (Hz) at the grid points and its time (s)."""
        lowest = lowest_first_frequency(self.mech, self.t, self.q)
        return None if lowest is None else lowest[:2]

    def frequency_rows(self) -> list[tuple[str, str]]:
        """The report's line on the first natural frequency (none for a rigid model)."""
        if self.first_frequency is None:
            return []
        f, t = self.first_frequency
        return [("lowest first natural frequency", f"{f:.4g} Hz at t = {t:.4g} s")]

    @property
    def duration(self) -> float:
        """The time to run the motion (s)."""
        return float(self.t[-1])

    def state(self, t: ArrayLike) -> tuple[FloatArray, FloatArray, FloatArray]:
        """q, qd, qdd (N, m) at times t (N,) (s)."""
        raise NotImplementedError

    def efforts(self, t: ArrayLike) -> FloatArray:
        """The efforts (N, m) (N m or N) that run the motion at times t (N,) (s, ascending)."""
        raise NotImplementedError

    def times(self, t: ArrayLike) -> FloatArray:
        """Times t (N,) (s) checked finite, clipped to [0, duration]."""
        tt = np.atleast_1d(_floats("t", t))
        if tt.ndim != 1 or not np.all(np.isfinite(tt)):
            raise PlanError(f"t: expected finite times (s), one axis, got {np.asarray(t).tolist()!r:.80}", "t")
        return np.clip(tt, 0.0, self.duration)

    def motion(self, n: int = 400) -> dict[str, dict[str, FloatArray]]:
        """The motion as ``simulate(motion=...)`` tables: {name: {"t", "q"}} at n times."""
        t = np.linspace(0.0, self.duration, positive_int("n", n, 2, 10**7))
        q = self.state(t)[0]
        return {name: {"t": t, "q": q[:, k]} for k, name in enumerate(self.mech.coordinate_names)}

    def simulate(self, **options: Any) -> SimulationResult:
        """Forward dynamics under the planned efforts (open loop, evaluated exactly at every
        time the integrator asks), from the start at rest; output at the grid times.
        ``options`` go to :meth:`Mechanism.simulate` (default dop853, rtol 1e-11, atol 1e-13)."""
        kw: dict[str, Any] = dict(method="dop853", rtol=1e-11, atol=1e-13, t_eval=self.t, q0=self.q[0],
                                  qd0=self.qd[0], drives=lambda t, q, qd: self.efforts([t])[0])
        kw.update(options)
        return self.mech.simulate(self.duration, **kw)


#: Coordinates farther than this from 0 (rad or m) are refused: the core continues the
#: assembly in moves of at most 1e3 from the drawing, and splines through 1e300 overflow.
MAX_COORDINATE = 1e6

#: The smallest speed limit (rad/s or m/s): a path of 1 rad then takes 1e6 s, MAX_DURATION.
MIN_SPEED = 1e-6

#: Limits must let the motion take at most this long (s, about 11 days): slower ones are
#: refused (their numbers leave the range the solvers work in).
MAX_DURATION = 1e6


def _floats(name: str, value: ArrayLike) -> FloatArray:
    try:
        return np.asarray(value, dtype=float)
    except (TypeError, ValueError) as exc:
        raise PlanError(f"{name}: expected numbers, got {value!r} ({exc})", name) from exc


def effort_bounds(m: int, effort: ArrayLike) -> tuple[FloatArray, FloatArray]:
    """(lo, hi) (m,) from symmetric magnitudes (m,) or [lo, hi] pairs (m, 2) (N m or N)."""
    e = _floats("effort", effort)
    if e.shape not in ((m,), (m, 2)):
        raise PlanError(f"effort: expected ({m},) magnitudes or ({m}, 2) [lo, hi] pairs (N m or N), one per "
                        f"coordinate, got shape {e.shape}", "effort")
    lo_hi = np.stack([-e, e], axis=1) if e.ndim == 1 else e
    lo, hi = lo_hi[:, 0].copy(), lo_hi[:, 1].copy()
    if not (np.all(lo < hi) and np.all(np.isfinite(lo)) and np.all(np.isfinite(hi))):
        raise PlanError(f"effort: need finite limits with lo < hi for every coordinate (magnitudes > 0), got "
                        f"{e.tolist()}", "effort")
    return lo, hi


def speed_bounds(m: int, speed: ArrayLike | None) -> FloatArray:
    """|qd| limits (m,) (rad/s or m/s), inf where none."""
    if speed is None:
        return np.full(m, np.inf)
    v = _floats("speed", speed)
    if v.shape != (m,) or not np.all(v >= MIN_SPEED):
        raise PlanError(f"speed: expected ({m},) limits >= {MIN_SPEED:g} (rad/s or m/s; inf for none), one per "
                        f"coordinate, got {v.tolist()}", "speed")
    return v


def positive_number(name: str, value: object, unit: str = "") -> float:
    """A finite number > 0, or a PlanError naming the argument."""
    try:
        x = float(value)  # type: ignore[arg-type]
    except (TypeError, ValueError, OverflowError):
        x = np.nan
    if isinstance(value, bool) or not (np.isfinite(x) and x > 0):
        raise PlanError(f"{name}: expected a finite number > 0{f' ({unit})' if unit else ''}, got {value!r}", name)
    return x


def positive_int(name: str, value: object, low: int, high: int = 10**6) -> int:
    """An integer from low to high, or a PlanError naming the argument."""
    if isinstance(value, (bool, float)) or not isinstance(value, (int, np.integer)) or not low <= value <= high:
        raise PlanError(f"{name}: expected an integer from {low} to {high}, got {value!r}", name)
    return int(value)
