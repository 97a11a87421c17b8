"""Motor limits as TOPP constraints: the torque a motor offers falls with its speed (its
torque-speed envelope), so the joint-side bound on tau depends on s'^2 as well as s.

Each drive's envelope T(w) (motor torque against motor speed w = n qd, planardyn's model of
the actuator) must be concave: a flat part and drooping lines, T(w) = min_j (T0_j - T1_j |w|)
up to its last speed. Along the path qd = p' s', so a line's bound is linear in s' = sqrt(x),
x = s'^2: convex in x. The motor torque t_m that gives a joint effort tau is the core's
(Mechanism.motor_torques: t_m = tau / (n eta) + friction while motoring, tau eta / n +
friction while generating); the joint-side bound is its inverse at T_j. Without motor
friction each line's joint-side bound is convex in x, so its tangent at any x0 lies below it:
the tangent rows are a conservative, linear inner approximation that is exact at x0. TOPP is
solved with the tangents at the previous profile (first at the profile the flat peak torque
allows) until the time settles; each profile is feasible for the next tangents, so the time
never grows between rounds. The final profile is checked against the exact bounds by the
caller (TimedPath.lo, hi hold them at its speeds).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from ..mechanism import Mechanism
from .planned import PlanError

FloatArray = NDArray[np.float64]

#: Relative step of the tangents' central differences in x = s'^2.
TANGENT_STEP = 1e-6

#: The rows are scaled by the half-width of the joint-side bounds, at least this fraction of
#: its largest along the path (where a motor runs out of torque the bounds close).
ROW_SCALE_MIN = 1e-6


@dataclass
class Drive:
    """Coordinate k's motor: ratio n, envelope lines (J, 2) [T0, T1] (T = T0 - T1 |w|, N m
    and N m s/rad) and the largest motor speed with torque (rad/s)."""

    k: int
    ratio: float
    lines: FloatArray
    max_speed: float


def drives(mech: Mechanism) -> list[Drive]:
    """Every coordinate's motor limits, or a PlanError naming what is missing."""
    out = []
    for k, (name, act) in enumerate(zip(mech.coordinate_names, mech.actuators)):
        if act is None:
            raise PlanError(f"effort='actuators': coordinate {name} has no actuator; give it one or pass effort limits")
        env = np.asarray(act.get("envelope", np.zeros((0, 2))), dtype=float).reshape(-1, 2)
        peak, top = act.get("peak_torque"), act.get("max_speed")
        if len(env) >= 2:
            slope = np.diff(env[:, 1]) / np.diff(env[:, 0])
            if np.any(np.diff(slope) > 1e-12 * max(1.0, float(np.abs(slope).max()))):
                raise PlanError(f"actuator {act['name']}: its torque-speed envelope is not concave (a flat part and "
                                "drooping lines); TOPP's linear bounds need that")
            lines = np.column_stack([env[:-1, 1] - slope * env[:-1, 0], -slope])
            w_max = float(env[-1, 0])
        elif peak is not None:
            lines = np.array([[float(peak), 0.0]])
            w_max = np.inf if top is None else float(top)
        else:
            raise PlanError(f"actuator {act['name']}: no peak torque or torque-speed envelope to plan with")
        out.append(Drive(k, float(act["gear_ratio"]), lines, w_max))
    return out


def joint_bounds(mech: Mechanism, qd: FloatArray, torque: FloatArray) -> tuple[FloatArray, FloatArray]:
    """Joint-side (lo, hi) (N, m) that keep |t_m| <= torque (N, m) at rates qd (N, m), through
    the core's motor torque map (linear on either side of tau = 0 at a given rate)."""
    f = np.asarray(mech.motor_torques(qd, np.zeros_like(qd)))
    up = np.asarray(mech.motor_torques(qd, np.ones_like(qd))) - f
    down = f - np.asarray(mech.motor_torques(qd, -np.ones_like(qd)))
    hi = np.where(torque >= f, (torque - f) / up, (torque - f) / down)
    lo = np.where(-torque <= f, (-torque - f) / down, (-torque - f) / up)
    return lo, hi


def exact_bounds(mech: Mechanism, qd: FloatArray) -> tuple[FloatArray, FloatArray]:
    """Joint-side (lo, hi) (N, m) at rates qd from the core's available torque at n qd."""
    torque = np.column_stack([
        np.asarray(mech.available_torque(d.k, d.ratio * qd[:, d.k]), dtype=float) for d in drives(mech)])
    return joint_bounds(mech, qd, torque)


def tangent_rows(mech: Mechanism, ds: list[Drive], a: FloatArray, b: FloatArray, c: FloatArray, p1: FloatArray,
                 x0: FloatArray) -> tuple[FloatArray, FloatArray, FloatArray]:
    """Rows (N, R) of A u + B x + C <= 0: for each drive and envelope line, tau below the
    tangent at x0 (N,) of its upper bound and above that of its lower bound."""
    x0 = np.maximum(x0, 1e-6 * max(float(x0.max()), 1e-12))
    rows_a, rows_b, rows_c = [], [], []
    dx = TANGENT_STEP * x0
    for d in ds:
        for t0, t1 in d.lines:
            lo0, hi0 = _line_bounds(mech, d, t0, t1, p1, x0)
            lo_p, hi_p = _line_bounds(mech, d, t0, t1, p1, x0 + dx)
            lo_m, hi_m = _line_bounds(mech, d, t0, t1, p1, x0 - dx)
            dhi, dlo = (hi_p - hi_m) / (2 * dx), (lo_p - lo_m) / (2 * dx)
            k = d.k
            # Scaled by the half-width of the bounds at x0, as effort limits' rows are.
            half = np.maximum((hi0 - lo0) / 2, ROW_SCALE_MIN * max(float(np.abs(hi0 - lo0).max()), 1e-300))
            rows_a += [a[:, k] / half, -a[:, k] / half]
            rows_b += [(b[:, k] - dhi) / half, (dlo - b[:, k]) / half]
            rows_c += [(c[:, k] - hi0 + dhi * x0) / half, (lo0 - dlo * x0 - c[:, k]) / half]
    return np.column_stack(rows_a), np.column_stack(rows_b), np.column_stack(rows_c)


def _line_bounds(mech: Mechanism, d: Drive, t0: float, t1: float, p1: FloatArray,
                 x: FloatArray) -> tuple[FloatArray, FloatArray]:
    """Coordinate d.k's joint-side (lo, hi) (N,) from one envelope line T0 - T1 |w| at
    s'^2 = x (N,) along the path's tangent p1 (N, m)."""
    qd = p1 * np.sqrt(x)[:, None]
    lo, hi = joint_bounds(mech, qd, t0 - t1 * d.ratio * np.abs(qd))
    return lo[:, d.k], hi[:, d.k]
