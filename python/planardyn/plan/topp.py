"""Time-optimal path parameterisation (TOPP) of a closed-chain mechanism with toppra, within
its limits along the whole timed path.

Along a path q = p(s), s in [0, 1], the drive efforts are

    tau = a(s) s'' + b(s) s'^2 + c(s),   a = A p',  b = A p'' + (convective terms of p'),  c = gravity and springs,

which planardyn's inverse dynamics gives exactly at any s, continuing the assembly branch
along the path (planardyn.plan.path_limits). toppra (reachability analysis, Pham and Pham
2018) finds the fastest s'(s) on a grid of s with s'' constant on each interval, so the timing
s(t) is piecewise quadratic in t and s'^2 linear in s between grid points.

The limits hold between the grid points too, not only at them: each stage's linear program
takes the limits at both ends of its interval (toppra's interpolation scheme), and the timing
is then checked at ten times the grid's density and at the path's knots
(planardyn.plan.dense_check); an interval where a limit is still exceeded gets the limit at
its worst point as one more row, and toppra is solved again, until no limit is exceeded by
more than :data:`RATIO_TOL` of itself. A timing that keeps every limit everywhere is a
feasible timing of the path, so the duration is never shorter than the optimum. It is longer
by O(grid spacing) (first order: a constant s'' per interval must meet the limits at the
interval's worst point, where the optimum's s'' varies across it); with ``rtol`` the grid is
doubled until the duration changes by less than rtol of itself, and that change, the
first-order estimate of the remaining excess, is reported (``TimedPath.time_error``).

The model planned is the user's with its drive laws replaced by the planned efforts: its
drives and its drives' servos are left out (``TimedPath.ignored`` lists them), a damper that
is not a servo is refused (its c s' is not of this form), and Coulomb friction (the pins'
mu r |F|, the motors' T_c) is taken by tangent rows about the previous timing with the least
favourable value of its band at rest (planardyn.plan.planning_model, friction_rows).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray
from toppra.constants import MAXU, MAXX

from .._core import AssemblyError, PlanardynError, SingularityError
from ..mechanism import Mechanism
from ..robot import EndEffector
from .actuator_limits import MotorMap, drives, exact_bounds
from .dense_check import check
from .friction_rows import variants
from .path_limits import EffortLimit, Limit, MotorLimit, PathPoints, SpeedLimit, path_points, rows_at, stage_rows
from .planned import (
    MAX_COORDINATE,
    MAX_DURATION,
    InfeasiblePlan,
    PlanError,
    PlannedMotion,
    effort_bounds,
    positive_int,
    positive_number,
    speed_bounds,
)
from .planning_model import PlanningModel, planning_model

FloatArray = NDArray[np.float64]

#: effort="actuators": the rounds of tangents stop when the time changes by less than this
#: fraction.
ACTUATOR_TOL = 1e-7

#: Rounds of toppra on one grid (with new cuts, and new tangents for motor envelopes) before
#: the plan is given up: the cuts settle in a few rounds, the tangents in ten to twenty.
MAX_ROUNDS = 60

#: A timing is accepted when its dense check finds no limit exceeded by more than this fraction
#: of itself: toppra's linear programs hold their rows to about 1e-12 of the row's scale.
RATIO_TOL = 1e-10

#: Default ``rtol`` of :func:`time_optimal`: the duration within about 0.1 % of the optimum.
RTOL = 1e-3

#: toppra bounds s'^2 by MAXX and |s''| by MAXU (1e4 each) and decides with absolute
#: tolerances of 1e-8 and more on them, so the path parameter's span S is fitted to the
#: duration T: s' ~ S / T and s'' ~ S / T^2 must stay within FAST_FRACTION of the bounds and
#: far above the tolerances (see _span). A timing that meets a bound is timed again with S
#: fitted to it (it is then too slow, so S shrinks), at most SPAN_ROUNDS times; a motion
#: faster than MIN_DURATION is refused.
FAST_FRACTION = 0.25
SPAN_ROUNDS = 8
MIN_DURATION = 1e-4

#: task_waypoints solves inverse kinematics at most this many times (a few seconds).
MAX_WAYPOINTS = 100_000

#: Grid refinement stops at this many grid points (the status then says the tolerance was not
#: reached).
MAX_GRID = 12801

#: An effort limit that may depend on the coordinates: ``f(q) -> (lo, hi)``, each (m,) in
#: N m or N. Limits that depend on the speed: ``effort="actuators"``.
EffortFunction = Callable[[FloatArray], tuple[ArrayLike, ArrayLike]]


@dataclass(repr=False)
class TimedPath(PlannedMotion):
    """A path with its time-optimal timing.

    ``s`` (N,) the grid of the path parameter (dimensionless, 0 to S: S is 1, or 1e-2, 1e-4 ...
    for a path so fast that s' would pass toppra's bound, see FAST_SPAN); ``sd`` (N,) s' at the
    grid points (1/s); ``sdd`` (N - 1,) the constant s'' on each interval (1/s^2); ``t`` (N,)
    the times the grid points are reached (s); ``x`` (N, 3n) the body coordinates there (the
    branch, continued from the drawing); ``q``, ``qd``, ``qdd`` (N, m) the coordinates,
    rates and accelerations at the grid points (rad or m, per s, per s^2), ``tau`` (N, m) the
    efforts there (N m or N; with s'' of the interval that starts there, the last with the
    last interval's); ``lo``, ``hi`` (N, m) the effort limits, ``speed`` (m,) the speed limits
    (inf where none); ``limit_ratio`` the largest fraction of a limit used on the dense check
    (planardyn.plan.dense_check); ``time_error`` the estimated excess of the duration over
    the optimum (s: the change over the last doubling of the grid; None without refinement);
    ``status`` toppra's, with the rounds and grids; ``ignored`` the parts of the model the
    plan leaves out, and why (its drives and their servos: the planned efforts replace them;
    ``mech`` is the model without them).
    """

    path: Any
    s: FloatArray
    sd: FloatArray
    sdd: FloatArray
    x: FloatArray
    lo: FloatArray
    hi: FloatArray
    speed: FloatArray
    time_error: float | None
    status: str
    ignored: list[str]

    def _summary(self) -> str:
        error = "not estimated" if self.time_error is None else f"{self.time_error:.2g} s"
        return f"{len(self.s)} grid points, time error {error}, {self.status}"

    def timing(self, t: ArrayLike) -> tuple[FloatArray, FloatArray, FloatArray]:
        """s, s', s'' at times t (s), from the piecewise-quadratic s(t)."""
        tt = self.times(t)
        i = np.clip(np.searchsorted(self.t, tt, side="right") - 1, 0, len(self.sdd) - 1)
        tau = tt - self.t[i]
        u = self.sdd[i]
        return self.s[i] + self.sd[i] * tau + 0.5 * u * tau**2, self.sd[i] + u * tau, u

    def state(self, t: ArrayLike) -> tuple[FloatArray, FloatArray, FloatArray]:
        """q, qd, qdd (N, m) at times t (N,) (s): q = p(s), qd = p' s', qdd = p' s'' + p'' s'^2."""
        s, sd, sdd = self.timing(t)
        p1, p2 = self.path(s, 1), self.path(s, 2)
        return self.path(s), p1 * sd[:, None], p1 * sdd[:, None] + p2 * (sd**2)[:, None]

    def efforts(self, t: ArrayLike) -> FloatArray:
        """The efforts (N, m) that run the timed path at times t (N,) (s, ascending), by
        inverse dynamics on the plan's branch."""
        t = self.times(t)
        q, qd, qdd = self.state(t)
        i = int(np.clip(np.searchsorted(self.t, t[0]), 0, len(self.t) - 1))
        return np.asarray(self.mech.inverse_dynamics(q, qd, qdd, x=self.x[i]))


def _effort_limit(mech: Mechanism, effort: ArrayLike | EffortFunction) -> EffortLimit:
    m = mech.dof
    if not callable(effort):
        lo1, hi1 = effort_bounds(m, effort)
        return EffortLimit(lambda q: (np.tile(lo1, (len(q), 1)), np.tile(hi1, (len(q), 1))))

    def bounds(q: FloatArray) -> tuple[FloatArray, FloatArray]:
        pairs = [effort(qi) for qi in q]
        try:
            lo = np.array([np.broadcast_to(np.asarray(p[0], dtype=float), (m,)) for p in pairs])
            hi = np.array([np.broadcast_to(np.asarray(p[1], dtype=float), (m,)) for p in pairs])
        except (TypeError, ValueError, IndexError) as exc:
            raise PlanError(f"effort: the function must return (lo, hi), each ({m},) N m or N: {exc}") from exc
        bad = ~(np.isfinite(lo) & np.isfinite(hi) & (lo < hi)).all(axis=1)
        if bad.any():
            k = int(np.argmax(bad))
            raise PlanError(f"effort: the function gives lo = {lo[k]}, hi = {hi[k]} at q = {q[k]}; it must give "
                            "finite lo < hi for every coordinate")
        return lo, hi

    return EffortLimit(bounds)


def _limits(mech: Mechanism, effort: ArrayLike | EffortFunction | str | None,
            speed: ArrayLike | None) -> tuple[list[Limit], MotorLimit | None, FloatArray]:
    """The limits, the motor limits among them (effort="actuators") and the speed limits (m,)."""
    v = speed_bounds(mech.dof, speed)
    if isinstance(effort, str):
        if effort != "actuators":
            raise PlanError(f"effort: limits, a function of q, 'actuators' or None, got {effort!r}")
        ds = drives(mech)
        v = np.minimum(v, [d.max_speed / d.ratio for d in ds])
        motor = MotorLimit(mech, ds)
        return [motor, *([SpeedLimit(v)] if np.isfinite(v).any() else [])], motor, v
    limits: list[Limit] = [] if effort is None else [_effort_limit(mech, effort)]
    if np.isfinite(v).any():
        limits.append(SpeedLimit(v))
    if not limits:
        raise PlanError("effort, speed: no limits: give effort limits, speed limits or both", "effort")
    return limits, None, v


def branch(mech: Mechanism, q: FloatArray) -> FloatArray:
    """Body coordinates (N, 3n) along coordinates q (N, m), each row continued from the one
    before it, from the drawing."""
    x = [np.asarray(mech.assemble(q[0]))]
    for qi in q[1:]:
        x.append(np.asarray(mech.assemble(qi, x_start=x[-1])))
    return np.array(x)


def time_optimal(
    mech: Mechanism,
    waypoints: ArrayLike,
    effort: ArrayLike | EffortFunction | str | None,
    speed: ArrayLike | None = None,
    n_grid: int = 200,
    *,
    rtol: float | None = RTOL,
) -> TimedPath:
    """The fastest timing of a joint-space path within effort and speed limits, everywhere
    along it (see the module).

    Parameters
    ----------
    mech : Mechanism
        The model; its drives and their servos (spring-dampers at a driven coordinate's pair)
        are not used, the efforts are the plan's (see the module; ``TimedPath.ignored``).
    waypoints : (K, m) array_like
        Coordinates (rad or m) the path passes through, K >= 2, joined by a C2 cubic spline
        in s (not-a-knot; a straight line for K = 2), s spaced by chord length in [0, S]. For
        a task-space path, :func:`task_waypoints`.
    effort : (m,) or (m, 2) array_like, or callable ``f(q) -> (lo, hi)``, "actuators", or None
        Effort limits (N m or N): symmetric magnitudes, [lo, hi] per coordinate, or a function
        of the coordinates (see :data:`EffortFunction`); "actuators": every coordinate's motor
        torque within the torque its envelope offers at its speed, through its transmission
        (planardyn.plan.actuator_limits says how; the motors' top speeds become speed limits);
        None: none (then ``speed`` is needed).
    speed : (m,) array_like, optional
        Speed limits |qd| (rad/s or m/s); none by default.
    n_grid : int
        Grid points in s to start with (toppra's stages + 1), >= 3.
    rtol : float or None
        Double the grid until the duration changes by less than this fraction of itself
        (default 1e-3: within about 0.1 % of the optimum); None: keep ``n_grid``.

    Returns
    -------
    TimedPath
        Starting and ending at rest, within every limit along the whole path (its
        ``limit_ratio`` <= 1 + :data:`RATIO_TOL`).

    Raises
    ------
    PlanError
        Bad arguments, a model with dampers that are not servos, or a path no timing can
        follow within the limits.
    """

    m = mech.dof
    try:
        q_w = np.atleast_2d(np.asarray(waypoints, dtype=float))
    except (TypeError, ValueError) as exc:
        raise PlanError(f"waypoints: expected (K, m) = (K >= 2, {m}) coordinates: {exc}") from exc
    if q_w.ndim != 2 or q_w.shape[1] != m or len(q_w) < 2 or not np.all(np.abs(q_w) <= MAX_COORDINATE):
        raise PlanError(f"waypoints: expected (K, m) = (K >= 2, {m}) finite coordinates within {MAX_COORDINATE:g} (rad "
                        f"or m), got shape {q_w.shape}", "waypoints")
    n_grid = positive_int("n_grid", n_grid, 3)
    if rtol is not None:
        rtol = positive_number("rtol", rtol)
    chord = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(q_w, axis=0), axis=1))])
    if not np.isfinite(chord[-1]) or np.any(np.diff(chord) == 0.0):
        raise PlanError("waypoints: consecutive waypoints must differ (and their distances be finite)")
    model = planning_model(mech)
    limits, motor, v = _limits(model.mech, effort, speed)
    try:
        return _time_optimal(model, q_w, chord, limits, motor, v, n_grid, rtol)
    except ValueError as exc:  # the core's refusal of a coordinate (far from the drawing)
        if isinstance(exc, PlanardynError):
            raise
        raise PlanError(f"waypoints: the path cannot be followed: {exc}", "waypoints") from exc


def _time_optimal(model: PlanningModel, q_w: FloatArray, chord: FloatArray, limits: list[Limit],
                  motor: MotorLimit | None, v: FloatArray, n_grid: int, rtol: float | None) -> TimedPath:
    """time_optimal on checked arguments: the span fitted, then the grid refined."""
    import toppra

    mech = model.mech
    m = mech.dof
    span = 1.0
    for _ in range(SPAN_ROUNDS):
        path = toppra.SplineInterpolator(chord / chord[-1] * span, q_w)
        s = np.linspace(0.0, span, n_grid)
        plan = _time_on_grid(model, path, s, limits, motor is not None)
        capped = plan.sd.max() ** 2 >= FAST_FRACTION * MAXX or np.abs(plan.sdd).max() >= FAST_FRACTION * MAXU
        if plan.duration < MIN_DURATION:
            raise InfeasiblePlan(f"the limits let this path run in {plan.duration:.3g} s or less, faster than toppra "
                                 f"can time (its s' and s'' are bounded): give limits of a motion of {MIN_DURATION:g} s "
                                 "or more", "effort")
        if plan.duration > MAX_DURATION:
            raise InfeasiblePlan(f"the limits make this path take {plan.duration:.3g} s, more than {MAX_DURATION:g} s: "
                                 "give limits of a shorter motion")
        want = _span(plan.duration)
        if not capped and 0.1 < span / want < 10:
            break
        span = want
    grids = [len(s)]
    time_error: float | None = None
    while rtol is not None:
        s = np.sort(np.concatenate([s, (s[:-1] + s[1:]) / 2]))
        finer = _time_on_grid(model, path, s, limits, motor is not None)
        grids.append(len(s))
        time_error = abs(plan.duration - finer.duration)
        plan = finer
        if time_error <= rtol * plan.duration or len(s) >= MAX_GRID:
            break
    note = f"grids {'-'.join(map(str, grids))}" if len(grids) > 1 else f"grid {grids[0]}"
    if rtol is not None and time_error is not None and time_error > rtol * plan.duration:
        note += f"; rtol {rtol:g} not reached within {MAX_GRID} grid points"
    if motor is not None:
        motors = MotorMap.along(mech, plan.q, path(plan.s, 1), path(plan.s, 2), plan.x)
        lo, hi = exact_bounds(mech, motors, np.append(plan.sdd, plan.sdd[-1]), plan.sd**2)
    elif isinstance(limits[0], EffortLimit):
        lo, hi = limits[0].bounds(plan.q)
    else:
        lo, hi = np.full((len(s), m), -np.inf), np.full((len(s), m), np.inf)
    plan.lo, plan.hi, plan.speed, plan.time_error, plan.ignored = lo, hi, v, time_error, model.ignored
    plan.status = f"{plan.status}; {note}"
    return plan


def _span(duration: float) -> float:
    """The path parameter's span for a motion of about this duration (s): S = T (s' ~ 1,
    s'' ~ 1 / T) down to 10 ms, then S = 100 T^2 (s'' ~ 100, s'^2 ~ 1e4 T^2, 1e-4 at the
    shortest motion timed, MIN_DURATION)."""
    return float(duration if duration >= 1e-2 else 100 * duration**2)


def _time_on_grid(model: PlanningModel, path: Any, s: FloatArray, limits: list[Limit], envelopes: bool) -> TimedPath:
    """toppra's timing on the grid s within the limits at both ends of every interval, cut
    where the dense check still finds a limit exceeded (see the module); with tangents (motor
    envelopes, Coulomb friction) the rows are linearised at the previous timing until the
    time settles."""
    n = len(s)
    mech = model.mech
    exact = None if model.bare is None else mech
    tangents = envelopes or model.has_coulomb
    x = branch(mech, path(s))
    grid = path_points(model.bare or mech, path, s, x, linear_check=True, exact=exact)
    # Each stage i < n - 1 holds its interval's start (d = 0) and end (d = s_i+1 - s_i).
    pts = _take(grid, np.concatenate([np.arange(n), np.arange(1, n)]))
    stage = np.concatenate([np.arange(n), np.arange(n - 1)])
    d = np.concatenate([np.zeros(n), np.diff(s)])
    x0 = _first_speeds(limits, pts)
    u0 = np.zeros_like(x0)
    duration, rounds = np.inf, 0
    # (time s, limits used, (sdd, sd, status, dense check)) of each round
    history: list[tuple[float, float, tuple[Any, ...]]] = []
    alternation = ""
    while True:
        rounds += 1
        rows = stage_rows(stage, d, rows_at(limits, variants(model, pts, u0, x0) if model.has_coulomb else [(pts, None)],
                                            x0), n)
        sdd, sd, status = _toppra(path, s, rows)
        with np.errstate(divide="ignore"):
            t_new = float(np.sum(2 * np.diff(s) / (sd[:-1] + sd[1:])))
        if not np.isfinite(t_new):
            raise InfeasiblePlan(f"no timing follows this path within the limits (toppra: {status}, but at rest "
                                 "somewhere along it): raise the limits or move the path")
        found = check(mech, path, s, x, sd, sdd, limits, path.ss_waypoints, exact)
        settled = not tangents or _same(duration, t_new)
        # Rounds that alternate between two timings never settle: the shorter of the two that
        # the dense check holds within the limits is the plan (where neither is: _unsettled).
        if len(history) >= 2 and _same(history[-2][0], t_new) and not settled:
            pair = [(t_new, found.ratio, (sdd, sd, status, found)), history[-1]]
            within = [p for p in pair if p[1] <= 1 + RATIO_TOL]
            if within:
                taken = min(within, key=lambda p: p[0])
                other = pair[1] if taken is pair[0] else pair[0]
                sdd, sd, status, found = taken[2]
                alternation = (f", alternating between {taken[0]:.9g} s (taken: limits used to {taken[1]:.9g}) and "
                               f"{other[0]:.9g} s (limits used to {other[1]:.9g})")
                break
        if found.ratio <= 1 + RATIO_TOL and settled:
            break
        history.append((t_new, found.ratio, (sdd, sd, status, found)))
        if rounds == MAX_ROUNDS:
            raise PlanError(_unsettled(history, n))
        bad = np.flatnonzero(found.worst > 1 + RATIO_TOL)
        if len(bad):
            cut = path_points(model.bare or mech, path, found.at[bad], x[bad], exact=exact)
            pts = _join(pts, cut)
            stage = np.concatenate([stage, bad])
            d = np.concatenate([d, found.at[bad] - s[bad]])
        duration = t_new
        u0 = np.append(sdd, 0.0)[stage]
        x0 = sd[stage] ** 2 + 2 * d * u0
    status = f"{status}; {rounds} rounds" + (" of tangents" if tangents else "") + alternation
    sd2 = sd**2
    dt = 2 * np.diff(s) / (sd[:-1] + sd[1:])
    u = np.append(sdd, sdd[-1])
    return TimedPath(mech=mech, path=path, s=s, sd=sd, sdd=sdd, t=np.concatenate([[0.0], np.cumsum(dt)]), x=x,
                     q=grid.q, qd=grid.p1 * sd[:, None], qdd=grid.p1 * u[:, None] + grid.p2 * sd2[:, None],
                     tau=grid.efforts(u, sd2), limit_ratio=found.ratio, lo=grid.a * np.nan, hi=grid.a * np.nan,
                     speed=np.full(mech.dof, np.inf), time_error=None, status=status, ignored=[])


def _same(a: float, b: float) -> bool:
    """Two rounds' times (s) the same to ACTUATOR_TOL."""
    return abs(a - b) <= ACTUATOR_TOL * b


def _unsettled(history: list[tuple[float, float, Any]], n: int) -> str:
    """Why the rounds on a grid of n points did not end, from each round's time (s) and limits
    used: the time still changing, alternating between two timings that both exceed a limit
    (the motor envelopes' tangents taken at one give the other; where one of the two is within
    the limits, it is taken), or settled with a limit still exceeded."""
    (t_2, _, _), (t_1, r_1, _), (t, r, _) = history[-3:]
    if _same(t, t_2) and not _same(t, t_1):
        what = (f"alternates between {t_1:.9g} s (limits used to {r_1:.9g}) and {t:.9g} s (limits used to {r:.9g}) "
                "from round to round: the motor envelopes' tangents taken at either timing give the other")
    elif _same(t, t_1):
        what = f"settled at {t:.9g} s, but the dense check still finds the limits used to {r:.9g}"
    else:
        what = f"still changes ({t_1:.9g} s, then {t:.9g} s, limits used to {r:.9g})"
    return f"the timing did not settle in {len(history)} rounds on a grid of {n} points: its time {what}; try another n_grid"


def _first_speeds(limits: list[Limit], pts: PathPoints) -> FloatArray:
    """The s'^2 at which the first tangents of motor envelopes are taken: a quarter of the
    speed limits' bound (1 where none; at most 1e6)."""
    bound = np.full(len(pts.s), np.inf)
    for lim in limits:
        if isinstance(lim, SpeedLimit):
            with np.errstate(divide="ignore", over="ignore"):  # no bound: inf
                bound = np.minimum(bound, np.min((lim.v / np.abs(pts.p1)) ** 2, axis=1))
    return np.minimum(np.where(np.isfinite(bound), bound / 4, 1.0), 1e6)


def _take(p: PathPoints, i: NDArray[np.intp]) -> PathPoints:
    return PathPoints(p.s[i], p.q[i], p.p1[i], p.p2[i], p.a[i], p.b[i], p.c[i], p.x[i], exact=p.exact)


def _join(p: PathPoints, r: PathPoints) -> PathPoints:
    s, q, p1, p2, a, b, c, x = (np.concatenate([getattr(p, k), getattr(r, k)]) for k in ("s", "q", "p1", "p2", "a", "b",
                                                                                          "c", "x"))
    return PathPoints(s, q, p1, p2, a, b, c, x, exact=p.exact)


def _toppra(path: Any, s: FloatArray, rows: tuple[FloatArray, FloatArray, FloatArray]) -> tuple[FloatArray, FloatArray, str]:
    """toppra's timing (s'' per interval, s' at the grid) within the stages' rows (N, R)
    A u + B x + C <= 0 (u = s'', x = s'^2)."""
    import toppra.algorithm as algo
    import toppra.constraint as constraint

    r = rows[0].shape[1]

    class _Rows(constraint.SecondOrderConstraint):
        def __init__(self) -> None:
            super().__init__(None, lambda q: np.eye(r), lambda q: np.zeros(r), len(s))
            self.identical = True

        def compute_constraint_params(self, _path: Any, gridpoints: FloatArray) -> tuple[Any, ...]:
            if not np.array_equal(gridpoints, s):
                raise PlanError("toppra asked for limits off the planned grid")
            return rows[0], rows[1], rows[2], np.eye(r), np.zeros(r), None, None

    instance = algo.TOPPRA([_Rows()], path, gridpoints=s, parametrizer="ParametrizeConstAccel")
    sdd, sd, _, status = _solve(instance)
    if sd is None:
        from .stage_lp import VertexWrapper

        instance.solver_wrapper = VertexWrapper(instance.constraints, instance.path, instance.gridpoints)
        sdd, sd, _, status = _solve(instance)
    if sd is None:
        raise InfeasiblePlan(f"no timing follows this path within the limits (toppra: {status}); the efforts at rest "
                        "(gravity, springs) may exceed them somewhere: raise the limits or move the path")
    return sdd, sd, status


def _solve(instance: Any) -> tuple[Any, Any, Any, str]:
    sdd, sd, v, data = instance.compute_parameterization(0.0, 0.0, return_data=True)
    code = getattr(instance.problem_data, "return_code", "unknown")
    status = str(getattr(code, "value", code))
    return sdd, sd, v, status


def task_waypoints(effector: EndEffector, X: ArrayLike, spacing: float) -> FloatArray:
    """Coordinates (K, m) along a task-space polyline, for :func:`time_optimal`.

    Each segment between the rows of ``X`` ((J, k) task coordinates, J >= 2: m, m[, rad], k
    the effector's) is cut into pieces no longer than ``spacing`` (m, > 0; at most
    MAX_WAYPOINTS pieces in all) and solved by inverse kinematics, continued from the drawing
    through the first point (on the drawing's working mode). The joint-space spline through
    them leaves the task path by O(spacing^4) between them: check with
    ``effector.state(q).X`` along the plan's ``q``.
    """
    if not isinstance(effector, EndEffector):
        raise PlanError(f"effector: expected an EndEffector, got {type(effector).__name__}", "effector")
    k = len(effector.names)
    try:
        X = np.atleast_2d(np.asarray(X, dtype=float))
    except (TypeError, ValueError):
        X = np.full((0, 0), np.nan)
    if X.ndim != 2 or X.shape[1] != k or len(X) < 2 or not np.all(np.isfinite(X)):
        raise PlanError(f"X: expected (J, {k}) finite task coordinates ({', '.join(effector.names)}), J >= 2, got "
                        f"shape {X.shape}", "X")
    spacing = positive_number("spacing", spacing, "m")
    with np.errstate(over="ignore"):  # a subnormal spacing: infinitely many pieces, refused below
        pieces = np.ceil(np.linalg.norm(np.diff(X[:, :2], axis=0), axis=1) / spacing)
    if pieces.sum() > MAX_WAYPOINTS:
        raise PlanError(f"spacing: {spacing:g} m cuts the path into {pieces.sum():.3g} pieces, more than "
                        f"{MAX_WAYPOINTS}; give a larger spacing", "spacing")
    points = [X[0]]
    for a, b, n in zip(X[:-1], X[1:], pieces.astype(int)):
        points.extend(a + (b - a) * f for f in np.linspace(0.0, 1.0, max(1, n) + 1)[1:])
    try:
        state = effector.inverse(points[0])
        q = [state.q]
        for Xi in points[1:]:
            state = effector.solve(Xi, state.q, state.kin["x"])
            q.append(state.q)
    except (AssemblyError, SingularityError) as exc:
        raise PlanError(f"X: the effector cannot follow the polyline on its working mode: {exc}", "X") from exc
    return np.array(q)
