"""The limits of a timed path at any point s of it, not only at TOPP's grid points: as linear
rows in (s'', s'^2) for toppra, and as the fraction of each limit the timing uses there.

At a point s of the path q = p(s), with u = s'' and x = s'^2 there, the efforts and rates are

    tau(s) = a(s) u + b(s) x + c(s),   qd = p'(s) sqrt(x),

and each kind of limit gives rows A u + B x + C <= 0 at s: exact for effort limits
(:class:`EffortLimit`) and speed limits (:class:`SpeedLimit`), tangents for the motors'
torque-speed envelopes (:class:`MotorLimit`, planardyn.plan.actuator_limits), each row
scaled so that C is of order one. Inside the grid interval [s_i, s_i+1] toppra keeps s'' = u_i
constant, so x(s) = x_i + 2 (s - s_i) u_i and a row at s is a row of stage i,

    (A + 2 d B) u_i + B x_i + C <= 0,   d = s - s_i,

which is toppra's interpolation scheme (Pham and Pham 2018, sec. VI) at d = s_i+1 - s_i and
holds at any point inside: :func:`stage_rows`.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import Any, Protocol

import numpy as np
from numpy.typing import NDArray

from ..mechanism import Mechanism
from .actuator_limits import Drive, MotorMap, tangent_rows
from .planned import PlanError

FloatArray = NDArray[np.float64]
Rows = tuple[FloatArray, FloatArray, FloatArray]

#: The s'^2 (1/s^2) at which a motor's torque at rest is taken: its sign decides whether the
#: motor drives or brakes, its size (rates of 1e-150 rad/s) changes nothing else.
X_REST = 1e-300

#: Every effort row (scaled to a limit of 1) is tightened by this: toppra's stage programs
#: hold them to a few 1e-9 where the timing runs along the maximum-velocity curve with two
#: efforts at their limits together, and the timing must keep its limits to RATIO_TOL (1e-10).
#: The time it costs is of the same relative size. Speed rows bound s'^2 alone, which toppra
#: holds exactly.
ROW_MARGIN = 3e-8

#: Relative size of the s'-linear part of the efforts beyond which a model is refused.
LINEAR_TOL = 1e-9


@dataclass
class PathPoints:
    """Points s (P,) of a path (dimensionless), with q = p(s), p'(s), p''(s) (P, m), the
    efforts' coefficients a, b, c (P, m) (N m or N) there, and the branch's body coordinates
    x (P, 3n) they were computed on (a motor's torque needs its rotor's acceleration)."""

    s: FloatArray
    q: FloatArray
    p1: FloatArray
    p2: FloatArray
    a: FloatArray
    b: FloatArray
    c: FloatArray
    x: FloatArray
    #: The motors' torque map at the points (planardyn.plan.actuator_limits), made once.
    motors: MotorMap | None = None
    #: A model whose efforts are not linear in (s'', s'^2) (Coulomb friction in its pins):
    #: :meth:`efforts` are then its inverse dynamics, and a, b, c only its rows' start.
    exact: Mechanism | None = None

    def efforts(self, u: FloatArray, x: FloatArray) -> FloatArray:
        """tau (P, m) at s'' = u and s'^2 = x (P,)."""
        if self.exact is not None:
            return inverse_along(self.exact, self, u, x)
        return np.asarray(self.a * u[:, None] + self.b * x[:, None] + self.c)

    def rates(self, x: FloatArray) -> FloatArray:
        """qd (P, m) at s'^2 = x (P,)."""
        return np.asarray(self.p1 * np.sqrt(np.maximum(x, 0.0))[:, None])


def inverse_along(mech: Mechanism, pts: PathPoints, u: FloatArray, x: FloatArray, sign: float = 1.0) -> FloatArray:
    """The efforts (P, m) of ``mech`` at the points at s'' = u and s'^2 = x (P,), moving along
    the path (``sign`` -1: against it, at the same speed), by inverse dynamics."""
    sd = sign * np.sqrt(np.maximum(x, 0.0))[:, None]
    return np.asarray(mech.inverse_dynamics(pts.q, pts.p1 * sd, pts.p1 * u[:, None] + pts.p2 * x[:, None], x=pts.x))


def path_points(mech: Mechanism, path: Any, s: FloatArray, x: FloatArray, linear_check: bool = False,
                exact: Mechanism | None = None) -> PathPoints:
    """a(s), b(s), c(s) by inverse dynamics, each point assembled from the body coordinates
    x (P, 3n) of a nearby point of the branch: c = ID(p, 0, 0), a = ID(p, 0, p') - c,
    b = ID(p, p', p'') - c. With ``linear_check``, refuses efforts linear in the rates
    (dampers), which are not of this form: then ID(p, 2 p', 4 p'') - c differs from 4 b.
    With ``exact``, the points' efforts are that model's (:attr:`PathPoints.exact`)."""
    p, p1, p2 = path(s), path(s, 1), path(s, 2)
    zero = np.zeros_like(p)

    def inverse(qd: FloatArray, qdd: FloatArray) -> FloatArray:
        return np.asarray(mech.inverse_dynamics(p, qd, qdd, x=x))

    c = inverse(zero, zero)
    a = inverse(zero, p1) - c
    b = inverse(p1, p2) - c
    if linear_check:
        b4 = inverse(2 * p1, 4 * p2) - c
        scale = max(float(np.abs(b).max()), float(np.abs(a).max()), float(np.abs(c).max()), 1e-300)
        if np.abs(b4 - 4 * b).max() > LINEAR_TOL * scale:
            raise PlanError(f"{mech.name}: efforts linear in the rates (dampers or viscous friction) are not of "
                            "TOPP's form a s'' + b s'^2 + c; plan on a copy of the model without them")
    return PathPoints(s, p, p1, p2, a, b, c, x, exact=exact)


class Limit(Protocol):
    """One kind of limit along a path."""

    def rows(self, pts: PathPoints, x0: FloatArray) -> Rows:
        """Rows (P, R) of A u + B x + C <= 0 at the points; x0 (P,) the s'^2 about which a
        nonlinear limit is linearised (the previous timing's)."""
        ...

    def ratio(self, pts: PathPoints, u: FloatArray, x: FloatArray) -> FloatArray:
        """The largest fraction (P,) of a limit used at s'' = u, s'^2 = x (P,): <= 1 within."""
        ...


@dataclass
class EffortLimit:
    """lo <= tau <= hi, with (lo, hi) (P, m) = ``bounds(q)`` (N m or N); the ratio is
    |tau - mid| / half (mid and half the middle and half-width of [lo, hi]: |tau| / limit
    for symmetric limits). Halves are taken before the sums (hi / 2 - lo / 2, as exact): hi - lo
    overflows for limits near 1e308."""

    bounds: Callable[[FloatArray], tuple[FloatArray, FloatArray]]

    def rows(self, pts: PathPoints, x0: FloatArray) -> Rows:
        lo, hi = self.bounds(pts.q)
        half = np.hstack([hi / 2 - lo / 2, hi / 2 - lo / 2])
        return (np.hstack([pts.a, -pts.a]) / half, np.hstack([pts.b, -pts.b]) / half,
                np.hstack([pts.c - hi, lo - pts.c]) / half + ROW_MARGIN)

    def ratio(self, pts: PathPoints, u: FloatArray, x: FloatArray) -> FloatArray:
        lo, hi = self.bounds(pts.q)
        return np.asarray(np.max(np.abs(pts.efforts(u, x) - (lo / 2 + hi / 2)) / (hi / 2 - lo / 2), axis=1))


@dataclass
class SpeedLimit:
    """|qd_k| <= v_k (m,) (rad/s or m/s, inf where none): p'_k^2 x / v_k^2 - 1 <= 0."""

    v: FloatArray

    def rows(self, pts: PathPoints, x0: FloatArray) -> Rows:
        k = np.isfinite(self.v)
        b = (pts.p1[:, k] / self.v[k]) ** 2
        return np.zeros_like(b), b, -np.ones_like(b)

    def ratio(self, pts: PathPoints, u: FloatArray, x: FloatArray) -> FloatArray:
        return np.asarray(np.max(np.abs(pts.rates(x)) / self.v, axis=1))


@dataclass
class MotorLimit:
    """Every drive's motor torque within its torque-speed envelope at its speed: the tangents
    of planardyn.plan.actuator_limits at x0; the ratio is |t_m| / the available torque, t_m on
    the gear's branch of the path's direction (as the rows: at rest, s' = 0 at the path's
    ends, its limit from the side the path moves on; braking into the end back-drives the
    gear, as just before it), the available torque at rates along p' of size X_REST."""

    mech: Mechanism
    drives: list[Drive]

    def _map(self, pts: PathPoints) -> MotorMap:
        if pts.motors is None:
            pts.motors = MotorMap.along(self.mech, pts.q, pts.p1, pts.p2, pts.x)
        return pts.motors

    def rows(self, pts: PathPoints, x0: FloatArray) -> Rows:
        a, b, c = tangent_rows(self._map(pts), self.drives, pts.a, pts.b, pts.c, x0)
        return a, b, c + ROW_MARGIN

    def ratio(self, pts: PathPoints, u: FloatArray, x: FloatArray) -> FloatArray:
        qd = pts.rates(np.maximum(x, X_REST))
        t_m = self._map(pts).torques(pts.efforts(u, x), u, x)
        out = np.zeros(len(x))
        for d in self.drives:
            avail = np.asarray(self.mech.available_torque(d.k, d.ratio * qd[:, d.k]), dtype=float)
            used = np.abs(t_m[:, d.k])
            with np.errstate(divide="ignore", invalid="ignore"):
                r = np.where(used == 0.0, 0.0, used / avail)
            out = np.maximum(out, r)
        return out


def rows_at(limits: list[Limit], variants: list[tuple[PathPoints, NDArray[np.bool_] | None]], x0: FloatArray) -> Rows:
    """Every limit's rows (P, R) at the points, for each of their variants (the linear rows of
    the efforts, planardyn.plan.friction_rows): a variant held only where its mask is true
    has rows 0 <= 1 elsewhere."""
    parts = []
    for pts, mask in variants:
        for lim in limits:
            A, B, C = lim.rows(pts, x0)
            if mask is not None:
                A, B, C = (np.where(mask[:, None], r, v) for r, v in ((A, 0.0), (B, 0.0), (C, -1.0)))
            parts.append((A, B, C))
    return tuple(np.hstack([p[i] for p in parts]) for i in range(3))  # type: ignore[return-value]


def ratio_at(limits: list[Limit], pts: PathPoints, u: FloatArray, x: FloatArray) -> FloatArray:
    """The largest fraction (P,) of any limit used at the points."""
    return np.asarray(np.max([lim.ratio(pts, u, x) for lim in limits], axis=0))


def stage_rows(stage: NDArray[np.intp], d: FloatArray, rows: Rows, n_stages: int) -> Rows:
    """Rows (n_stages, Q) of toppra's stages from rows (P, R) at points inside them: point j
    lies d_j past the start of stage ``stage_j`` (see the module). Stages with fewer points
    are padded with rows 0 <= 1."""
    A, B, C = rows
    A = A + 2 * d[:, None] * B
    r = A.shape[1]
    order = np.argsort(stage, kind="stable")
    counts = np.bincount(stage, minlength=n_stages)
    starts = np.concatenate([[0], np.cumsum(counts)[:-1]])
    slot = np.empty_like(stage)
    slot[order] = np.arange(len(stage)) - starts[stage[order]]
    width = int(counts.max()) * r
    cols = slot[:, None] * r + np.arange(r)
    out_a, out_b, out_c = np.zeros((n_stages, width)), np.zeros((n_stages, width)), np.full((n_stages, width), -1.0)
    out_a[stage[:, None], cols], out_b[stage[:, None], cols], out_c[stage[:, None], cols] = A, B, C
    return out_a, out_b, out_c
