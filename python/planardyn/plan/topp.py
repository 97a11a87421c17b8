"""Time-optimal path parameterisation (TOPP) of a closed-chain mechanism with toppra.

Along a path q = p(s), s in [0, 1], the drive efforts are

    tau = a(s) s'' + b(s) s'^2 + c(s),   a = A p',  b = A p'' + (convective terms of p'),  c = gravity and springs,

which planardyn's inverse dynamics gives exactly at every grid point of s, continuing the
assembly branch from one point to the next: c = ID(p, 0, 0), a = ID(p, 0, p') - c,
b = ID(p, p', p'') - c. toppra (reachability analysis, Pham and Pham 2018) then finds the
fastest s'(s) within effort limits F tau <= g and speed limits on q'. Between grid points
s'' is constant (toppra's discretisation), so the timing s(t) is piecewise quadratic in t.

Dampers add efforts linear in s', which this form cannot hold: such a model is refused.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ..mechanism import Mechanism
from ..robot import EndEffector
from .actuator_limits import MotorMap, drives, exact_bounds, tangent_rows
from .planned import PlanError, PlannedMotion, effort_bounds, speed_bounds

FloatArray = NDArray[np.float64]

#: effort="actuators": the rounds of tangents stop when the time changes by less than this
#: fraction, and fail after ACTUATOR_ROUNDS rounds.
ACTUATOR_TOL = 1e-7
ACTUATOR_ROUNDS = 60

#: Relative size of the s'-linear part of the efforts beyond which a model is refused.
LINEAR_TOL = 1e-9

#: An effort limit that may depend on the coordinates: ``f(q) -> (lo, hi)``, each (m,) in
#: N m or N. Limits that depend on the speed: ``effort="actuators"``.
EffortLimit = Callable[[FloatArray], tuple[ArrayLike, ArrayLike]]


@dataclass
class TimedPath(PlannedMotion):
    """A path with its time-optimal timing.

    ``s`` (N,) the grid of the path parameter (dimensionless, 0 to 1); ``sd`` (N,) s' at the
    grid points (1/s); ``sdd`` (N - 1,) the constant s'' on each interval (1/s^2); ``t`` (N,)
    the times the grid points are reached (s); ``x`` (N, 3n) the body coordinates there (the
    branch, continued from the drawing); ``q``, ``qd``, ``qdd`` (N, m) the coordinates,
    rates and accelerations at the grid points (rad or m, per s, per s^2), ``tau`` (N, m) the
    efforts there (N m or N; with s'' of the interval that starts there, the last with the
    last interval's); ``lo``, ``hi`` (N, m) the effort limits, ``speed`` (m,) the speed limits
    (inf where none); ``status`` toppra's.
    """

    path: Any
    s: FloatArray
    sd: FloatArray
    sdd: FloatArray
    x: FloatArray
    lo: FloatArray
    hi: FloatArray
    speed: FloatArray
    status: str

    def timing(self, t: ArrayLike) -> tuple[FloatArray, FloatArray, FloatArray]:
        """s, s', s'' at times t (s), from the piecewise-quadratic s(t)."""
        tt = np.clip(np.asarray(t, dtype=float), 0.0, self.t[-1])
        i = np.clip(np.searchsorted(self.t, tt, side="right") - 1, 0, len(self.sdd) - 1)
        tau = tt - self.t[i]
        u = self.sdd[i]
        return self.s[i] + self.sd[i] * tau + 0.5 * u * tau**2, self.sd[i] + u * tau, u

    def state(self, t: ArrayLike) -> tuple[FloatArray, FloatArray, FloatArray]:
        """q, qd, qdd (N, m) at times t (N,) (s): q = p(s), qd = p' s', qdd = p' s'' + p'' s'^2."""
        s, sd, sdd = self.timing(np.atleast_1d(t))
        p1, p2 = self.path(s, 1), self.path(s, 2)
        return self.path(s), p1 * sd[:, None], p1 * sdd[:, None] + p2 * (sd**2)[:, None]

    def efforts(self, t: ArrayLike) -> FloatArray:
        """The efforts (N, m) that run the timed path at times t (N,) (s, ascending), by
        inverse dynamics on the plan's branch."""
        t = np.atleast_1d(np.asarray(t, dtype=float))
        q, qd, qdd = self.state(t)
        i = int(np.clip(np.searchsorted(self.t, t[0]), 0, len(self.t) - 1))
        return np.asarray(self.mech.inverse_dynamics(q, qd, qdd, x=self.x[i]))


def _limits(mech: Mechanism, effort: ArrayLike | EffortLimit, q: FloatArray) -> tuple[FloatArray, FloatArray]:
    m = mech.dof
    if callable(effort):
        pairs = [effort(qi) for qi in q]
        lo = np.array([np.broadcast_to(np.asarray(p[0], dtype=float), (m,)) for p in pairs])
        hi = np.array([np.broadcast_to(np.asarray(p[1], dtype=float), (m,)) for p in pairs])
    else:
        lo1, hi1 = effort_bounds(m, effort)
        lo, hi = np.tile(lo1, (len(q), 1)), np.tile(hi1, (len(q), 1))
    if not (np.all(lo < hi) and np.all(np.isfinite(lo)) and np.all(np.isfinite(hi))):
        raise PlanError("effort limits: need finite lo < hi for every coordinate")
    return lo, hi


def branch(mech: Mechanism, q: FloatArray) -> FloatArray:
    """Body coordinates (N, 3n) along coordinates q (N, m), each row continued from the one
    before it, from the drawing."""
    x = [np.asarray(mech.assemble(q[0]))]
    for qi in q[1:]:
        x.append(np.asarray(mech.assemble(qi, x_start=x[-1])))
    return np.array(x)


def _coefficients(mech: Mechanism, path: Any, s: FloatArray,
                  x: FloatArray) -> tuple[FloatArray, FloatArray, FloatArray]:
    """a(s), b(s), c(s) (N, m) by inverse dynamics along the grid, on the branch x (N, 3n)."""
    p, p1, p2 = path(s), path(s, 1), path(s, 2)
    zero = np.zeros_like(p)

    def inverse(qd: FloatArray, qdd: FloatArray) -> FloatArray:
        return np.asarray(mech.inverse_dynamics(p, qd, qdd, x=x))

    c = inverse(zero, zero)
    a = inverse(zero, p1) - c
    b = inverse(p1, p2) - c
    # Quadratic in s' only if no effort is linear in the rates: tau(2 p', 4 p'') = 4 b + c.
    b4 = inverse(2 * p1, 4 * p2) - c
    scale = max(float(np.abs(b).max()), float(np.abs(a).max()), float(np.abs(c).max()), 1e-300)
    if np.abs(b4 - 4 * b).max() > LINEAR_TOL * scale:
        raise PlanError(f"{mech.name}: efforts linear in the rates (dampers or viscous friction) are not of "
                        "TOPP's form a s'' + b s'^2 + c; plan on a copy of the model without them")
    return a, b, c


def time_optimal(
    mech: Mechanism,
    waypoints: ArrayLike,
    effort: ArrayLike | EffortLimit | str | None,
    speed: ArrayLike | None = None,
    n_grid: int = 200,
) -> TimedPath:
    """The fastest timing of a joint-space path within effort and speed limits.

    Parameters
    ----------
    mech : Mechanism
        The model; its drives are not used, the efforts are the plan's.
    waypoints : (K, m) array_like
        Coordinates (rad or m) the path passes through, K >= 2, joined by a C2 cubic spline
        in s (not-a-knot; a straight line for K = 2), s spaced by chord length in [0, 1]. For
        a task-space path, :func:`task_waypoints`.
    effort : (m,) or (m, 2) array_like, or callable ``f(q) -> (lo, hi)``, "actuators", or None
        Effort limits (N m or N): symmetric magnitudes, [lo, hi] per coordinate, or a function
        of the coordinates (see :data:`EffortLimit`); "actuators": every coordinate's motor
        torque within the torque its envelope offers at its speed, through its transmission
        (planardyn.plan.actuator_limits says how; the motors' top speeds become speed limits);
        None: none (then ``speed`` is needed).
    speed : (m,) array_like, optional
        Speed limits |qd| (rad/s or m/s); none by default.
    n_grid : int
        Grid points in s (toppra's stages + 1).

    Returns
    -------
    TimedPath
        Starting and ending at rest.

    Raises
    ------
    PlanError
        Bad arguments, a model with dampers, or a path no timing can follow within the limits.
    """
    import toppra

    q_w = np.atleast_2d(np.asarray(waypoints, dtype=float))
    m = mech.dof
    if q_w.ndim != 2 or q_w.shape[1] != m or len(q_w) < 2 or not np.all(np.isfinite(q_w)):
        raise PlanError(f"waypoints: expected (K, m) = (K >= 2, {m}) finite coordinates, got shape {q_w.shape}")
    if n_grid < 3:
        raise PlanError(f"n_grid: need at least 3 grid points, got {n_grid}")
    chord = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(q_w, axis=0), axis=1))])
    if chord[-1] == 0.0 or np.any(np.diff(chord) == 0.0):
        raise PlanError("waypoints: consecutive waypoints must differ")
    path = toppra.SplineInterpolator(chord / chord[-1], q_w)
    s = np.linspace(0.0, 1.0, n_grid)
    v = speed_bounds(m, speed)
    if effort is None and not np.isfinite(v).any():
        raise PlanError("no limits: give effort limits, speed limits or both")
    x = branch(mech, path(s))
    a, b, c = _coefficients(mech, path, s, x)
    p1 = path(s, 1)
    if isinstance(effort, str):
        if effort != "actuators":
            raise PlanError(f"effort: limits, a function of q, 'actuators' or None, got {effort!r}")
        ds = drives(mech)
        v = np.minimum(v, [d.max_speed / d.ratio for d in ds])
        # The speed limits' s'^2 bound (a quarter of it) as the first tangent point.
        with np.errstate(divide="ignore"):
            x_v = np.min((v / np.abs(p1)) ** 2, axis=1)
        x0 = np.minimum(np.where(np.isfinite(x_v), x_v / 4, 1.0), 1e6)
        motor = MotorMap.along(mech, path(s), p1, path(s, 2), x)
        duration, rounds = np.inf, 0
        while True:
            rounds += 1
            sdd, sd, status = _toppra(path, s, tangent_rows(motor, ds, a, b, c, x0), v)
            t_new = float(np.sum(2 * np.diff(s) / (sd[:-1] + sd[1:])))
            if abs(duration - t_new) <= ACTUATOR_TOL * t_new:
                break
            if rounds == ACTUATOR_ROUNDS:
                raise PlanError(f"effort='actuators': the time did not settle in {rounds} rounds of tangents "
                                f"({duration:.9g} s, then {t_new:.9g} s); use a finer n_grid")
            duration, x0 = t_new, sd**2
        status = f"{status}; {rounds} rounds of tangents"
        lo, hi = exact_bounds(mech, motor, np.append(sdd, sdd[-1]), sd**2)
    else:
        if effort is None:
            lo, hi = np.full((n_grid, m), -np.inf), np.full((n_grid, m), np.inf)
        else:
            lo, hi = _limits(mech, effort, path(s))
        rows = (np.hstack([a, -a]), np.hstack([b, -b]), np.hstack([c - hi, lo - c]))
        sdd, sd, status = _toppra(path, s, None if effort is None else rows, v)
    sd2 = sd**2
    dt = 2 * np.diff(s) / (sd[:-1] + sd[1:])
    t = np.concatenate([[0.0], np.cumsum(dt)])
    u = np.append(sdd, sdd[-1])
    p2 = path(s, 2)
    tau = a * u[:, None] + b * sd2[:, None] + c
    return TimedPath(mech=mech, path=path, s=s, sd=sd, sdd=sdd, t=t, x=x, q=path(s), qd=p1 * sd[:, None],
                     qdd=p1 * u[:, None] + p2 * sd2[:, None], tau=tau, lo=lo, hi=hi, speed=v, status=status)


def _toppra(path: Any, s: FloatArray, rows: tuple[FloatArray, FloatArray, FloatArray] | None,
            v: FloatArray) -> tuple[FloatArray, FloatArray, str]:
    """toppra's timing (s'' per interval, s' at the grid) within rows (N, R) A u + B x + C <= 0
    (u = s'', x = s'^2) and speed limits v."""
    import toppra.algorithm as algo
    import toppra.constraint as constraint

    class _Rows(constraint.SecondOrderConstraint):
        def compute_constraint_params(self, _path: Any, gridpoints: FloatArray) -> tuple[Any, ...]:
            if not np.array_equal(gridpoints, s):
                raise PlanError("toppra asked for efforts off the planned grid")
            assert rows is not None
            r = rows[0].shape[1]
            return rows[0], rows[1], rows[2], np.tile(np.eye(r), (len(s), 1, 1)), np.zeros((len(s), r)), None, None

    constraints: list[Any] = []
    m = len(v)
    if rows is not None:
        r = rows[0].shape[1]
        constraints.append(_Rows(None, lambda q: np.eye(r), lambda q: np.zeros(r), m))
    if np.isfinite(v).any():
        vmax = np.where(np.isfinite(v), v, 1e300)
        constraints.append(constraint.JointVelocityConstraint(np.stack([-vmax, vmax], axis=1)))
    instance = algo.TOPPRA(constraints, path, gridpoints=s, parametrizer="ParametrizeConstAccel")
    sdd, sd, _, status = _solve(instance)
    if sd is None:
        from .stage_lp import HighsWrapper

        instance.solver_wrapper = HighsWrapper(instance.constraints, instance.path, instance.gridpoints)
        sdd, sd, _, status = _solve(instance)
    if sd is None:
        raise PlanError(f"no timing follows this path within the limits (toppra: {status}); the efforts at rest "
                        "(gravity, springs) may exceed them somewhere: raise the limits or move the path")
    return sdd, sd, status


def _solve(instance: Any) -> tuple[Any, Any, Any, str]:
    sdd, sd, v, data = instance.compute_parameterization(0.0, 0.0, return_data=True)
    code = getattr(instance.problem_data, "return_code", "unknown")
    status = str(getattr(code, "value", code))
    return sdd, sd, v, status


def task_waypoints(effector: EndEffector, X: ArrayLike, spacing: float) -> FloatArray:
    """Coordinates (K, m) along a task-space polyline, for :func:`time_optimal`.

    Each segment between the rows of ``X`` ((J, k) task coordinates: m, m[, rad]) is cut into
    pieces no longer than ``spacing`` (m) and solved by inverse kinematics, continued from
    the drawing through the first point (on the drawing's working mode). The joint-space
    spline through them leaves the task path by O(spacing^4) between them: check with
    ``effector.state(q).X`` along the plan's ``q``.
    """
    X = np.atleast_2d(np.asarray(X, dtype=float))
    if len(X) < 2 or spacing <= 0:
        raise PlanError(f"task path: need >= 2 points and a positive spacing, got {len(X)} points, {spacing}")
    points = [X[0]]
    for a, b in zip(X[:-1], X[1:]):
        n = max(1, int(np.ceil(np.linalg.norm(b[:2] - a[:2]) / spacing)))
        points.extend(a + (b - a) * f for f in np.linspace(0.0, 1.0, n + 1)[1:])
    state = effector.inverse(points[0])
    q = [state.q]
    for Xi in points[1:]:
        state = effector.solve(Xi, state.q, state.kin["x"])
        q.append(state.q)
    return np.array(q)
