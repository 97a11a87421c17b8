"""The dense check of a timing against its limits between the grid points, and where to add
the rows that still lack (TOPP's cuts).

A timing of toppra's form (s'' = u_i constant on each interval of the grid, s'^2 = x linear
in s there) is evaluated at :data:`CHECK_POINTS` points of each interval, ends included, by
inverse dynamics (planardyn.plan.path_limits). The largest fraction of a limit used in each
interval is then refined at the vertex of the parabola through the largest sample and its two
neighbours (an error of third order in the sample spacing), and checked at the path's knots
inside the interval: the spline's third derivative jumps there, so the efforts have a kink
where a parabola does not reach (1e-5 of the limit over it on a 5R's line). An interval whose
largest value exceeds its limit gets that point's rows as one more row set of its stage: a
cutting plane, exact at the point, after which toppra is solved again.
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
          limits: list[Limit], knots: FloatArray, exact: Mechanism | None = None) -> Check:
    """The check of the timing (s' (N,) at the grid s (N,), s'' (N - 1,) on its intervals)
    on the branch x (N, 3n) at the grid points, and at the path's knots (K,); see the module.
    With ``exact`` (a model with Coulomb friction in its pins), its inverse dynamics gives
    the efforts."""
    n_int, k = len(s) - 1, CHECK_POINTS
    rows = np.arange(n_int)
    f = np.linspace(0.0, 1.0, k)
    delta = np.diff(s)
    sk = s[:-1, None] + delta[:, None] * f  # (I, K)
    use = _ratios(mech, path, sk.ravel(), np.repeat(rows, k), s, x, sd, sdd, limits, exact).reshape(n_int, k)
    j = np.clip(np.argmax(use, axis=1), 1, k - 2)
    y0, y1, y2 = use[rows, j - 1], use[rows, j], use[rows, j + 1]
    curv = y0 - 2 * y1 + y2
    with np.errstate(divide="ignore", invalid="ignore"):
        shift = np.where(curv < 0, 0.5 * (y0 - y2) / curv, 0.0)
    shift = np.clip(np.nan_to_num(shift), -1.0, 1.0)
    s_v = s[:-1] + delta * (f[j] + shift * (f[1] - f[0]))
    use_v = _ratios(mech, path, s_v, rows, s, x, sd, sdd, limits, exact)
    best = np.argmax(use, axis=1)
    worst = np.maximum(use[rows, best], use_v)
    at = np.where(use_v >= use[rows, best], s_v, sk[rows, best])
    i_k = np.searchsorted(s, knots, side="right") - 1
    inner = (i_k >= 0) & (i_k < n_int) & (knots > s[np.clip(i_k, 0, n_int - 1)])
    s_k, i_k = knots[inner], i_k[inner]
    for sj, ij, used in zip(s_k, i_k, _ratios(mech, path, s_k, i_k, s, x, sd, sdd, limits, exact), strict=True):
        if used > worst[ij]:
            worst[ij], at[ij] = used, sj
    return Check(float(worst.max()), worst, at)


def _ratios(mech: Mechanism, path: Any, sp: FloatArray, i: NDArray[np.intp], s: FloatArray, x: FloatArray,
            sd: FloatArray, sdd: FloatArray, limits: list[Limit], exact: Mechanism | None) -> FloatArray:
    """The largest fraction of a limit used (P,) at the points sp (P,) of the intervals i (P,)
    of the grid s, where x (N, 3n) is the branch, s' is sd and s'' is sdd."""
    pts = path_points(mech, path, sp, x[i], exact=exact)
    u = sdd[i]
    return ratio_at(limits, pts, u, sd[i] ** 2 + 2 * (sp - s[i]) * u)
