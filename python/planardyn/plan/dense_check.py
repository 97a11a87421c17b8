"""The dense check of a timing against its limits between the grid points, and where to add
the rows that still lack (TOPP's cuts).

A timing of toppra's form (s'' = u_i constant on each interval of the grid, s'^2 = x linear
in s there) is evaluated at :data:`CHECK_POINTS` points of each interval, ends included, by
inverse dynamics (planardyn.plan.path_limits). The largest fraction of a limit used in each
interval is then refined at the vertex of the parabola through the largest sample and its two
neighbours (an error of third order in the sample spacing). An interval whose refined
maximum exceeds its limit gets that point's rows as one more row set of its stage: a cutting
plane, exact at the point, after which toppra is solved again.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import NDArray

from ..mechanism import Mechanism
from .path_limits import Limit, path_points, ratio_at

FloatArray = NDArray[np.float64]

#: Points of each grid interval the timing is checked at, its ends included (a 10x denser
#: grid than the plan's, with the parabolic refinement of each interval's largest sample).
CHECK_POINTS = 11


@dataclass
class Check:
    """The fractions of the limits a timing uses: ``ratio`` the largest of all (1: a limit
    reached), ``worst`` (I,) each interval's largest and ``at`` (I,) the s where it is."""

    ratio: float
    worst: FloatArray
    at: FloatArray


def check(mech: Mechanism, path: Any, s: FloatArray, x: FloatArray, sd: FloatArray, sdd: FloatArray,
          limits: list[Limit], exact: Mechanism | None = None) -> Check:
    """The check of the timing (s' (N,) at the grid s (N,), s'' (N - 1,) on its intervals)
    on the branch x (N, 3n) at the grid points; see the module. With ``exact`` (a model with
    Coulomb friction in its pins), its inverse dynamics gives the efforts."""
    n_int, k = len(s) - 1, CHECK_POINTS
    f = np.linspace(0.0, 1.0, k)
    delta = np.diff(s)
    sk = s[:-1, None] + delta[:, None] * f  # (I, K)
    use = _ratios(mech, path, sk, s[:-1], x[:-1], sd, sdd, limits, exact)
    j = np.clip(np.argmax(use, axis=1), 1, k - 2)
    rows = np.arange(n_int)
    y0, y1, y2 = use[rows, j - 1], use[rows, j], use[rows, j + 1]
    curv = y0 - 2 * y1 + y2
    with np.errstate(divide="ignore", invalid="ignore"):
        shift = np.where(curv < 0, 0.5 * (y0 - y2) / curv, 0.0)
    shift = np.clip(np.nan_to_num(shift), -1.0, 1.0)
    s_v = s[:-1] + delta * (f[j] + shift * (f[1] - f[0]))
    use_v = _ratios(mech, path, s_v[:, None], s[:-1], x[:-1], sd, sdd, limits, exact)[:, 0]
    best = np.argmax(use, axis=1)
    worst = np.maximum(use[rows, best], use_v)
    at = np.where(use_v >= use[rows, best], s_v, sk[rows, best])
    return Check(float(worst.max()), worst, at)


def _ratios(mech: Mechanism, path: Any, sk: FloatArray, s: FloatArray, x: FloatArray, sd: FloatArray,
            sdd: FloatArray, limits: list[Limit], exact: Mechanism | None) -> FloatArray:
    """The largest fraction of a limit used (I, K) at points sk (I, K) of the intervals that
    start at s (I,), where x (I, 3n) is the branch, s' is sd and s'' is sdd."""
    n_int, k = sk.shape
    i = np.repeat(np.arange(n_int), k)
    flat = sk.ravel()
    pts = path_points(mech, path, flat, np.repeat(x, k, axis=0), exact=exact)
    u = sdd[i]
    return ratio_at(limits, pts, u, sd[i] ** 2 + 2 * (flat - s[i]) * u).reshape(n_int, k)
