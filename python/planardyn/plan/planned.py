"""What every planned motion offers (:class:`PlannedMotion`): its duration, the motion tables
``Mechanism.simulate(motion=...)`` takes, and the open-loop replay of its efforts."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ..mechanism import Mechanism
from ..result import SimulationResult

FloatArray = NDArray[np.float64]


class PlanError(ValueError):
    """A path or limits that cannot be planned, with what to change."""


@dataclass
class PlannedMotion:
    """A motion from rest to rest with the efforts that run it.

    It holds ``mech``, the grid times ``t`` (N,) (s), and ``q``, ``qd``, ``qdd``, ``tau``
    (N, m) there; subclasses give :meth:`state` and :meth:`efforts` between the grid points.
    ``motor_sizing(mech, k, plan.t, plan.qd[:, k], plan.tau[:, k])`` (planardyn.robot.sizing)
    sizes a drive on it.
    """

    mech: Mechanism
    t: FloatArray
    q: FloatArray
    qd: FloatArray
    qdd: FloatArray
    tau: FloatArray

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

    def motion(self, n: int = 400) -> dict[str, dict[str, FloatArray]]:
        """The motion as ``simulate(motion=...)`` tables: {name: {"t", "q"}} at n times."""
        t = np.linspace(0.0, self.duration, n)
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


def effort_bounds(m: int, effort: ArrayLike) -> tuple[FloatArray, FloatArray]:
    """(lo, hi) (m,) from symmetric magnitudes (m,) or [lo, hi] pairs (m, 2) (N m or N)."""
    e = np.asarray(effort, dtype=float)
    if e.shape not in ((m,), (m, 2)):
        raise PlanError(f"effort limits: expected (m,) = ({m},) magnitudes or (m, 2) [lo, hi], got shape {e.shape}")
    lo_hi = np.stack([-e, e], axis=1) if e.ndim == 1 else e
    lo, hi = lo_hi[:, 0].copy(), lo_hi[:, 1].copy()
    if not (np.all(lo < hi) and np.all(np.isfinite(lo)) and np.all(np.isfinite(hi))):
        raise PlanError("effort limits: need finite lo < hi for every coordinate")
    return lo, hi


def speed_bounds(m: int, speed: ArrayLike | None) -> FloatArray:
    """|qd| limits (m,) (rad/s or m/s), inf where none."""
    v = np.full(m, np.inf) if speed is None else np.asarray(speed, dtype=float)
    if v.shape != (m,) or np.any(v <= 0) or np.any(np.isnan(v)):
        raise PlanError(f"speed limits: expected (m,) = ({m},) positive values, got {v}")
    return v
