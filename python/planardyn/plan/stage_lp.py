"""toppra's stage-wise linear programs solved exactly by their vertices.

toppra's default solver (Seidel's algorithm) can fail numerically on a feasible stage, a known
toppra limitation (its issue #14): it returns NaN and toppra reports the path as not
controllable. That happens on paths whose time-optimal timing runs along the maximum-velocity
curve with two efforts at their limits together, as a minimum-time collocation's path does.
:class:`VertexWrapper` solves the same programs (variables u = s'', x = s'^2) again.

Why hand-written: each program has two variables and a few tens of rows, so its optimum is one
of the few hundred pairwise intersections of its rows (the box |u| <= MAXU, 0 <= x <= MAXX
keeps it bounded); checking them all takes some 50 microseconds with numpy, where a general
solver's call (scipy's linprog with HiGHS) costs 4 ms of set-up, and a tolerance of
VERTEX_TOL of each row's scale accepts the stages whose feasible set has shrunk to a point.
"""

from __future__ import annotations

from typing import Any

import numpy as np
from numpy.typing import NDArray
from toppra.constants import MAXU, MAXX
from toppra.constraint import ConstraintType
from toppra.solverwrapper.solverwrapper import SolverWrapper

FloatArray = NDArray[np.float64]

#: A vertex is feasible when it breaks no row by more than this fraction of the row's scale
#: (its coefficients' and right-hand side's size, the vertex's coordinates included).
VERTEX_TOL = 1e-10

#: Rows whose normal is shorter than this (relative to the largest) are dropped as parallel
#: to nothing: 0 u + 0 x <= h holds or fails whatever the vertex.
DEGENERATE = 1e-14


class VertexWrapper(SolverWrapper):
    """A toppra solver wrapper for canonical linear constraints, exact by vertex enumeration."""

    def solve_stagewise_optim(self, i: int, H: Any, g: Any, x_min: float, x_max: float, x_next_min: float,
                              x_next_max: float) -> FloatArray:
        rows: list[FloatArray] = [np.array([[1.0, 0.0], [-1.0, 0.0], [0.0, 1.0], [0.0, -1.0]])]
        lo_x, hi_x = 0.0, float(MAXX)
        if not np.isnan(x_min):
            lo_x = max(lo_x, x_min)
        if not np.isnan(x_max):
            hi_x = min(hi_x, x_max)
        rhs: list[FloatArray] = [np.array([MAXU, MAXU, hi_x, -lo_x])]
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
                raise NotImplementedError("VertexWrapper: linear constraints only")
            a, b, c, F, h, ubound, xbound = self.params[k]
            if a is not None:
                Fi, hi_ = (F, h) if constraint.identical else (F[i], h[i])
                # F (a u + b x + c) <= h
                rows.append(np.column_stack([Fi @ a[i], Fi @ b[i]]))
                rhs.append(hi_ - Fi @ c[i])
            if ubound is not None:
                rows.append(np.array([[1.0, 0.0], [-1.0, 0.0]]))
                rhs.append(np.array([ubound[i, 1], -ubound[i, 0]]))
            if xbound is not None:
                rows.append(np.array([[0.0, 1.0], [0.0, -1.0]]))
                rhs.append(np.array([xbound[i, 1], -xbound[i, 0]]))
        return lp2(np.asarray(g, dtype=float), np.vstack(rows), np.concatenate(rhs))


def lp2(cost: FloatArray, A: FloatArray, b: FloatArray) -> FloatArray:
    """argmin cost . z over A z <= b (R, 2), a bounded set, by its vertices; NaN (2,) when
    no vertex is feasible."""
    norm = np.hypot(A[:, 0], A[:, 1])
    flat = norm <= DEGENERATE * norm.max()
    if np.any(b[flat] < -VERTEX_TOL * np.maximum(np.abs(b[flat]), 1.0)):
        return np.full(2, np.nan)
    A, b = A[~flat] / norm[~flat, None], b[~flat] / norm[~flat]
    i, j = np.triu_indices(len(b), 1)
    det = A[i, 0] * A[j, 1] - A[i, 1] * A[j, 0]
    ok = np.abs(det) > DEGENERATE
    i, j, det = i[ok], j[ok], det[ok]
    z = np.column_stack([(b[i] * A[j, 1] - A[i, 1] * b[j]) / det, (A[i, 0] * b[j] - b[i] * A[j, 0]) / det])
    scale = 1.0 + np.abs(b)[None, :] + np.abs(z) @ np.abs(A).T
    feasible = np.all(z @ A.T - b[None, :] <= VERTEX_TOL * scale, axis=1)
    if not feasible.any():
        return np.full(2, np.nan)
    z = z[feasible]
    return np.asarray(z[np.argmin(z @ cost)], dtype=float)
