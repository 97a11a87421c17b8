"""Dynamic capability: the end-effector acceleration that the drives can give in every
direction, at rest, within their effort limits |tau_k| <= tau_max_k.

At rest (qd = 0) the convective term vanishes, so an end-effector acceleration a needs
qdd = J^-1 a and

    tau = A J^-1 a + g,        g = inverse_dynamics(q, 0, 0)

(g: the efforts that hold the robot still against gravity and the model's springs). Along a
direction d = (cos t, sin t), a = r d is feasible iff |(A J^-1 d)_k r + g_k| <= tau_max_k for
every drive k; the largest feasible r is a minimum of ratios. The guaranteed acceleration
is the minimum over ``N_DIRECTIONS`` directions (0 where g alone exceeds a limit).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ..arguments import error
from .effector import EndEffector
from .maps import TaskGrid, flood, grid_size

FloatArray = NDArray[np.float64]

N_DIRECTIONS = 72


def max_acceleration(M: FloatArray, g: FloatArray, tau_max: FloatArray, d: FloatArray) -> float:
    """Largest r >= 0 with |M d r + g| <= tau_max (all drives); 0 if g alone exceeds them."""
    if np.any(np.abs(g) > tau_max):
        return 0.0
    v = M @ d
    r = np.inf
    for vk, gk, tk in zip(v, g, tau_max):
        if vk > 0:
            r = min(r, (tk - gk) / vk)
        elif vk < 0:
            r = min(r, (-tk - gk) / vk)
    return float(r)


def capability_at(ee: EndEffector, q: ArrayLike, tau_max: ArrayLike, n_dir: int = N_DIRECTIONS) -> tuple[float, float]:
    """(guaranteed acceleration (m/s^2), its limiting direction t (rad)) at inputs q, at rest."""
    mech = ee.mech
    q = np.asarray(q, dtype=float)
    tau_max = np.broadcast_to(np.asarray(tau_max, dtype=float), (mech.dof,))
    J = ee.state(q).J[:2]
    if ee.dim != 2:
        raise error("ee", "the capability map is for a point end effector (m = 2)")
    M = mech.mass_matrix(q) @ np.linalg.inv(J)
    g = mech.inverse_dynamics(q, np.zeros(mech.dof), np.zeros(mech.dof))
    ts = np.linspace(0.0, 2 * np.pi, n_dir, endpoint=False)
    r = [max_acceleration(M, g, tau_max, np.array([np.cos(t), np.sin(t)])) for t in ts]
    k = int(np.argmin(r))
    return float(r[k]), float(ts[k])


@dataclass(repr=False)
class CapabilityMap:
    """Guaranteed end-effector acceleration at rest on a grid.

    ``x`` (nx,), ``y`` (ny,) m; ``accel`` (ny, nx) m/s^2, the smallest over directions of the
    largest feasible acceleration (0 where holding still already exceeds a limit, NaN where
    unreachable); ``direction`` (ny, nx) rad, the limiting direction; ``holding`` (ny, nx, m)
    efforts g that hold the robot at rest; ``tau_max`` (m,); ``grid`` the TaskGrid (q,
    singularity measures) it was computed on.
    """

    effector: EndEffector
    x: FloatArray
    y: FloatArray
    accel: FloatArray
    direction: FloatArray
    holding: FloatArray
    tau_max: FloatArray
    grid: TaskGrid

    def __repr__(self) -> str:
        inside = self.accel[np.isfinite(self.accel)]
        span = f"{inside.min():.4g} .. {inside.max():.4g} m/s^2" if inside.size else "no reachable cell"
        return (f"CapabilityMap({self.effector.point} of {self.effector.mech.name}: {len(self.y)} x {len(self.x)} "
                f"cells, guaranteed acceleration {span}, |tau| <= {np.round(self.tau_max, 6).tolist()})")


def capability_map(ee: EndEffector, xlim: tuple[float, float], ylim: tuple[float, float],
                   n: int | tuple[int, int], tau_max: ArrayLike, q_start: ArrayLike | None = None,
                   n_dir: int = N_DIRECTIONS) -> CapabilityMap:
    """Guaranteed acceleration of the end-effector point at rest over a grid of positions
    (inverse kinematics by :func:`flood` on the working mode of ``q_start``, default the
    drawing). ``tau_max``: (m,) or scalar effort limits (N m or N)."""
    nx, ny = grid_size(n)
    grid = flood(ee, np.linspace(*xlim, nx), np.linspace(*ylim, ny), 0.0, q_start)
    m = ee.mech.dof
    tmax = np.broadcast_to(np.asarray(tau_max, dtype=float), (m,)).copy()
    acc = np.full((ny, nx), np.nan)
    direc = np.full((ny, nx), np.nan)
    hold = np.full((ny, nx, m), np.nan)
    for j in range(ny):
        for i in range(nx):
            if not grid.reachable[j, i]:
                continue
            q = grid.q[j, i]
            acc[j, i], direc[j, i] = capability_at(ee, q, tmax, n_dir)
            hold[j, i] = ee.mech.inverse_dynamics(q, np.zeros(m), np.zeros(m))
    return CapabilityMap(ee, grid.x, grid.y, acc, direc, hold, tmax, grid)


__all__ = ["CapabilityMap", "capability_at", "capability_map", "max_acceleration"]
