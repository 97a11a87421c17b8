"""toppra's stage-wise linear programs solved by HiGHS (scipy.optimize.linprog).

toppra's default solver (Seidel's algorithm) can fail numerically on a feasible stage, a known
toppra limitation (its issue #14): it returns NaN and toppra reports the path as not
controllable. That happens on paths whose time-optimal timing runs along the maximum-velocity
curve with two efforts at their limits together, as a minimum-time collocation's path does.
:class:`HighsWrapper` solves the same programs (variables u = s'', x = s'^2) with HiGHS.
"""

from __future__ import annotations

from typing import Any

import numpy as np
from numpy.typing import NDArray
from scipy.optimize import linprog
from toppra.constants import MAXU, MAXX
from toppra.constraint import ConstraintType
from toppra.solverwrapper.solverwrapper import SolverWrapper


class HighsWrapper(SolverWrapper):
    """A toppra solver wrapper for canonical linear constraints, by HiGHS."""

    def solve_stagewise_optim(self, i: int, H: Any, g: Any, x_min: float, x_max: float, x_next_min: float,
                              x_next_max: float) -> NDArray[np.float64]:
        rows: list[NDArray[np.float64]] = []
        rhs: list[NDArray[np.float64]] = []
        lo, hi = [-MAXU, 0.0], [MAXU, MAXX]
        if not np.isnan(x_min):
            lo[1] = max(lo[1], x_min)
        if not np.isnan(x_max):
            hi[1] = min(hi[1], x_max)
        if i < self.N:
            delta = self.get_deltas()[i]
            if not np.isnan(x_next_max):
                rows.append(np.array([[2 * delta, 1.0]]))
                rhs.append(np.array([x_next_max]))
            if not np.isnan(x_next_min):
                rows.append(np.array([[-2 * delta, -1.0]]))
                rhs.append(np.array([-x_next_min]))
        for k, constraint in enumerate(self.constraints):
            if constraint.get_constraint_type() != ConstraintType.CanonicalLinear:
                raise NotImplementedError("HighsWrapper: linear constraints only")
            a, b, c, F, h, ubound, xbound = self.params[k]
            if a is not None:
                Fi, hi_ = (F, h) if constraint.identical else (F[i], h[i])
                # F (a u + b x + c) <= h
                rows.append(np.column_stack([Fi @ a[i], Fi @ b[i]]))
                rhs.append(hi_ - Fi @ c[i])
            if ubound is not None:
                lo[0], hi[0] = max(lo[0], ubound[i, 0]), min(hi[0], ubound[i, 1])
            if xbound is not None:
                lo[1], hi[1] = max(lo[1], xbound[i, 0]), min(hi[1], xbound[i, 1])
        cost = np.asarray(g, dtype=float)
        res = linprog(cost, A_ub=np.vstack(rows) if rows else None, b_ub=np.concatenate(rhs) if rhs else None,
                      bounds=list(zip(lo, hi)), method="highs")
        if res.status != 0:
            return np.full(self.get_no_vars(), np.nan)
        return np.asarray(res.x, dtype=float)
