"""collocate's arguments, checked one rule each (:func:`problem`), and the ends checked
against the margin and the workspace box (:func:`check_ends`)."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ..mechanism import Mechanism
from ..robot import EndEffector
from .planned import (
    MAX_COORDINATE,
    MAX_DURATION,
    PlanError,
    PlannedMotion,
    effort_bounds,
    positive_int,
    positive_number,
    speed_bounds,
)

FloatArray = NDArray[np.float64]


@dataclass
class Workspace:
    """A box the effector's task coordinates X (m, m[, rad]) stay in: lo <= X(q) <= hi at
    every node (inf where unbounded)."""

    effector: EndEffector
    lo: ArrayLike
    hi: ArrayLike


@dataclass
class Problem:
    """collocate's arguments, checked: the limits as arrays (inf where none)."""

    q0: FloatArray
    q1: FloatArray
    objective: str
    duration: float | None
    lo: FloatArray | None
    hi: FloatArray | None
    v: FloatArray
    sigma_min: float | None
    box: tuple[EndEffector, FloatArray, FloatArray] | None
    n: int
    tol: float
    max_iter: int


def problem(mech: Mechanism, q_start: ArrayLike, q_end: ArrayLike, objective: str, duration: float | None,
             effort: ArrayLike | None, speed: ArrayLike | None, sigma_min: float | None, workspace: Workspace | None,
             n_intervals: int, warm_start: PlannedMotion | None, tol: float, max_iter: int) -> Problem:
    """The arguments checked, one rule each, the error naming the argument (PlanError)."""
    m = mech.dof
    ends = []
    for name, value in (("q_start", q_start), ("q_end", q_end)):
        try:
            qe = np.asarray(value, dtype=float)
        except (TypeError, ValueError):
            qe = np.full(0, np.nan)
        if qe.shape != (m,) or not np.all(np.abs(qe) <= MAX_COORDINATE):
            raise PlanError(f"{name}: expected ({m},) finite coordinates within {MAX_COORDINATE:g} (rad or m), got "
                            f"{value!r}", name)
        ends.append(qe)
    if objective not in ("time", "effort"):
        raise PlanError(f"objective: 'time' or 'effort', got {objective!r}", "objective")
    if duration is not None or objective == "effort":
        duration = positive_number("duration", duration, "s; objective 'effort' needs one")
        if duration > MAX_DURATION:
            raise PlanError(f"duration: at most {MAX_DURATION:g} s, got {duration:g}", "duration")
    if objective == "time" and effort is None and speed is None:
        raise PlanError("effort, speed: objective 'time' needs effort or speed limits", "effort")
    if sigma_min is not None:
        sigma_min = positive_number("sigma_min", sigma_min)
        if sigma_min >= 1:
            raise PlanError(f"sigma_min: sigma_II lies in [0, 1]; a margin must be below 1, got {sigma_min}", "sigma_min")
    if warm_start is not None and (not isinstance(warm_start, PlannedMotion) or warm_start.q.shape[1:] != (m,)):
        raise PlanError(f"warm_start: expected a planned motion of this model ({m} coordinates), got "
                        f"{type(warm_start).__name__}", "warm_start")
    lo, hi = effort_bounds(m, effort) if effort is not None else (None, None)
    return Problem(ends[0], ends[1], objective, duration, lo, hi, speed_bounds(m, speed), sigma_min,
                    _box(workspace), positive_int("n_intervals", n_intervals, 2, 10_000),
                    positive_number("tol", tol), positive_int("max_iter", max_iter, 1))


def _box(workspace: Workspace | None) -> tuple[EndEffector, FloatArray, FloatArray] | None:
    if workspace is None:
        return None
    if not isinstance(workspace, Workspace) or not isinstance(workspace.effector, EndEffector):
        raise PlanError("workspace: expected Workspace(effector, lo, hi)", "workspace")
    k = len(workspace.effector.names)
    box = []
    for name in ("lo", "hi"):
        try:
            b = np.broadcast_to(np.asarray(getattr(workspace, name), dtype=float), (k,))
        except (TypeError, ValueError) as exc:
            raise PlanError(f"workspace.{name}: expected one bound or {k} (m, m[, rad]): {exc}", "workspace") from exc
        if np.isnan(b).any():
            raise PlanError(f"workspace.{name}: NaN in {b.tolist()}; use inf where unbounded", "workspace")
        box.append(b)
    if not np.all(box[0] < box[1]):
        raise PlanError(f"workspace: need lo < hi, got {box[0].tolist()} and {box[1].tolist()}", "workspace")
    return workspace.effector, box[0], box[1]


def check_ends(mech: Mechanism, p: Problem) -> None:
    """Ends that break the margin or leave the box are refused before solving."""
    for name, qe in (("q_start", p.q0), ("q_end", p.q1)):
        if p.sigma_min is not None and sigma(mech, qe) < p.sigma_min:
            raise PlanError(f"{name}: sigma_II {sigma(mech, qe):.3g} is below the margin {p.sigma_min}; move it or "
                            "lower sigma_min", name)
        if p.box is not None:
            ee, lo, hi = p.box
            X = ee.state(qe).X
            if np.any(X < lo) or np.any(X > hi):
                raise PlanError(f"{name}: the effector at {np.round(X, 6).tolist()} is outside the workspace box", name)


def sigma(mech: Mechanism, q: FloatArray) -> float:
    """The type II measure sigma_II at q (dimensionless)."""
    return float(mech.kinematics(q)["sigma_min"])
