"""Point-to-point trajectory optimisation by direct collocation in minimal coordinates.

The motion from q_start to q_end, at rest at both ends, is cut into N intervals of equal
length h = T / N. At the nodes t_k = k h the unknowns are q_k, qd_k and the efforts tau_k
(and T itself for minimum time); the dynamics qdd = f(q, qd, tau) (forward dynamics) hold
through the trapezoidal defects

    q_{k+1} - q_k - h/2 (qd_k + qd_{k+1}) = 0,   qd_{k+1} - qd_k - h/2 (f_k + f_{k+1}) = 0,

with the efforts linear in t between nodes. The trapezoidal rule is second order: the states
it gives differ from the true motion under those efforts by O(h^2). The error is stated per
solution (:attr:`CollocatedMotion.error`) from the residual of the dynamics at the interval
midpoints on the collocation's own interpolant (Betts, *Practical Methods for Optimal
Control*, 2010, sec. 4.7.4): q and qd are the quadratics that meet the defects, and the
residual r_k at the midpoint, integrated over the interval by Simpson's rule (zero at the
nodes), gives eta_k = 2 h / 3 |r_k|. A qd error made at t_k moves q by eta_k (T - t_k) by the
end, so the stated bound on q is the sum of eta_q,k + eta_qd,k (T - t_{k+1}) over the
intervals; it neglects how the dynamics amplify an error, which over a short point-to-point
motion is small (the tests compare with an open-loop replay).

The limits hold between the nodes too. The efforts are linear between nodes, so within
[lo, hi] wherever they are at the nodes. The rate between nodes is the interpolant's
quadratic, whose Bernstein control points are qd_k, qd_k + h f_k / 2 and qd_{k+1}: it stays
within their hull, so |qd_k + h f_k / 2| <= v (one more row per interval) keeps it within
the speed limit everywhere. The singularity margin and the workspace box are imposed at the
nodes. Each solution's ``limit_ratio`` is the largest fraction of an effort or speed limit
used at :data:`CHECK_POINTS` points of every interval.

f and its Jacobian are planardyn's (Mechanism.forward_dynamics and the exact
forward_dynamics_derivatives), handed to CasADi as callbacks (planardyn.plan.casadi_callbacks).
IPOPT solves the NLP with a limited-memory Hessian, silently: its return status is the
result's ``status``. The type II measure sigma_II's gradient (for the singularity margin) is
by central differences of the kinematics, step SIGMA_STEP; the effector's task coordinates
use its exact Jacobian.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, Literal

import numpy as np
from numpy.typing import ArrayLike, NDArray

from .._core import AssemblyError, SingularityError
from ..mechanism import Mechanism
from .casadi_callbacks import callback, or_nan
from .collocation_problem import Problem, Workspace, check_ends, problem, sigma
from .dense_check import CHECK_POINTS
from .planned import InfeasiblePlan, PlanError, PlannedMotion
from .topp import time_optimal

FloatArray = NDArray[np.float64]

#: Central-difference step (rad or m) of the type II measure's gradient.
SIGMA_STEP = 1e-6

#: A minimum time within this fraction of the bounds put on T is taken as held by them.
T_BOUND_TOL = 1e-6

#: IPOPT's final status when it converged.
CONVERGED = ("Solve_Succeeded", "Solved_To_Acceptable_Level")


@dataclass(repr=False)
class CollocatedMotion(PlannedMotion):
    """The solution of :func:`collocate` and IPOPT's report on it.

    ``t`` (N + 1,) node times (s); ``q``, ``qd``, ``qdd``, ``tau`` (N + 1, m) there (qdd the
    forward dynamics at the node); ``objective`` "time" or "effort"; ``cost`` its value (s,
    or the integral of sum tau^2, N^2 m^2 s); ``status`` IPOPT's return status, ``success``
    True only when IPOPT converged (``Solve_Succeeded`` or ``Solved_To_Acceptable_Level``),
    ``iterations`` its iteration count, ``violation`` the largest constraint violation of the
    final point as IPOPT measured it, ``max_defect`` the largest trapezoidal defect
    (rad or m, and per s); ``error`` (m,) the stated accuracy of q (rad or m; see the module;
    inf when the motion between nodes meets a singularity); ``limit_ratio`` the largest
    fraction of an effort or speed limit used between the nodes (0 without limits).
    """

    objective: str
    cost: float
    status: str
    success: bool
    iterations: int
    violation: float
    max_defect: float
    error: FloatArray

    def _summary(self) -> str:
        return (f"{len(self.t) - 1} intervals, minimum {self.objective}, IPOPT {self.status} in {self.iterations} "
                f"iterations, stated accuracy of q {self.error.max():.2g}")

    def _interval(self, t: ArrayLike) -> tuple[Any, FloatArray, FloatArray]:
        tt = self.times(t)
        i = np.clip(np.searchsorted(self.t, tt, side="right") - 1, 0, len(self.t) - 2)
        h = (self.t[i + 1] - self.t[i])[:, None]
        return i, (tt - self.t[i])[:, None], h

    def state(self, t: ArrayLike) -> tuple[FloatArray, FloatArray, FloatArray]:
        """q, qd, qdd (N, m) at times t (N,) (s): the trapezoidal rule's quadratics."""
        i, s, h = self._interval(t)
        q = self.q[i] + self.qd[i] * s + s**2 / (2 * h) * (self.qd[i + 1] - self.qd[i])
        qd = self.qd[i] + self.qdd[i] * s + s**2 / (2 * h) * (self.qdd[i + 1] - self.qdd[i])
        return q, qd, self.qdd[i] + s / h * (self.qdd[i + 1] - self.qdd[i])

    def efforts(self, t: ArrayLike) -> FloatArray:
        """The efforts (N, m) at times t (N,) (s): linear between the nodes."""
        i, s, h = self._interval(t)
        return self.tau[i] + s / h * (self.tau[i + 1] - self.tau[i])


def _straight(mech: Mechanism, p: Problem) -> tuple[PlannedMotion | None, PlanError | None]:
    """The straight joint path timed by TOPP within the limits, or None and why not (no
    limits, limits no timing keeps, or a model TOPP refuses: dampers)."""
    effort = None if p.lo is None or p.hi is None else np.stack([p.lo, p.hi], axis=1)
    if effort is None and not np.isfinite(p.v).any():
        return None, PlanError("no limits to time the warm start with")
    try:
        return time_optimal(mech, [p.q0, p.q1], effort, None if not np.isfinite(p.v).any() else p.v,
                            n_grid=max(2 * p.n, 50), rtol=None), None
    except PlanError as exc:
        return None, exc


def _warm_start(mech: Mechanism, p: Problem, duration: float | None, previous: PlannedMotion | None,
                why: PlanError | None) -> tuple[Any, ...]:
    """(T, q, qd, tau) at n + 1 nodes: a previous motion (by default the straight path's
    fastest timing), stretched to ``duration`` when one is given (efforts by inverse dynamics
    of the stretched motion); without one (``why`` says why), the straight path in
    ``duration`` with the cubic timing s = 3 r^2 - 2 r^3, r = t / T (the minimum-effort
    timing of a double integrator)."""
    n = p.n
    if previous is None:
        if duration is None:
            # Limits no timing of the straight path keeps stay the reason; else the start is missing.
            kind, argument = (InfeasiblePlan, None) if isinstance(why, InfeasiblePlan) else (PlanError, "duration")
            raise kind(f"duration: the straight path cannot be timed for a start ({why}); give a first guess "
                       "duration= (s) or warm_start=", argument)
        r = np.linspace(0.0, 1.0, n + 1)[:, None]
        dq = p.q1 - p.q0
        q = p.q0 + dq * (3 * r**2 - 2 * r**3)
        qd = dq * (6 * r - 6 * r**2) / duration
        qdd = dq * (6 - 12 * r) / duration**2
        return duration, q, qd, np.asarray(mech.inverse_dynamics(q, qd, qdd))
    t_ref = previous.duration
    T = t_ref if duration is None else duration
    t = np.linspace(0.0, T, n + 1)
    q, qd, qdd = previous.state(t * t_ref / T)
    stretch = t_ref / T
    qd, qdd = qd * stretch, qdd * stretch**2
    tau = np.asarray(mech.inverse_dynamics(q, qd, qdd))
    return T, q, qd, tau


def collocate(
    mech: Mechanism,
    q_start: ArrayLike,
    q_end: ArrayLike,
    *,
    objective: Literal["time", "effort"] = "time",
    duration: float | None = None,
    effort: ArrayLike | None = None,
    speed: ArrayLike | None = None,
    sigma_min: float | None = None,
    workspace: Workspace | None = None,
    n_intervals: int = 30,
    warm_start: PlannedMotion | None = None,
    tol: float = 1e-8,
    max_iter: int = 500,
) -> CollocatedMotion:
    """A minimum-time or minimum-effort motion from q_start to q_end, at rest at both ends.

    Parameters
    ----------
    mech : Mechanism
        The model; its drives are not used, the efforts are the plan's.
    q_start, q_end : (m,) array_like
        Coordinates (rad or m) at the start and the end.
    objective : "time" or "effort"
        Minimise the duration T, or the integral over [0, T] of sum tau_i^2 at a given T.
    duration : float, optional
        T (s): for "effort" required, and fixed; for "time" a first guess (the warm start is
        stretched to it; needed where TOPP cannot time the warm start, e.g. with dampers).
    effort : (m,) or (m, 2) array_like, optional
        Effort limits (N m or N): magnitudes or [lo, hi]; "time" needs them or ``speed``.
    speed : (m,) array_like, optional
        Speed limits |qd| (rad/s or m/s).
    sigma_min : float, optional
        A type II singularity margin in (0, 1): sigma_II(q_k) >= sigma_min at every node.
    workspace : Workspace, optional
        A box for the effector's task coordinates at every node.
    n_intervals : int
        N, the collocation intervals (2 to 10000).
    warm_start : PlannedMotion, optional
        A motion to start from (e.g. a previous solution), stretched to ``duration``;
        default the straight joint path timed by :func:`time_optimal` within the limits.
    tol, max_iter
        IPOPT's tolerance (> 0) and iteration limit (>= 1).

    Returns
    -------
    CollocatedMotion
        With IPOPT's status; ``success`` is False when IPOPT did not converge.

    Raises
    ------
    PlanError
        Bad arguments (the error's ``argument`` names which), ends that break the margin or
        the workspace, or a minimum-effort duration shorter than the fastest motion within
        the limits (found first by minimum time when the straight path's is longer).
    """
    p = problem(mech, q_start, q_end, objective, duration, effort, speed, sigma_min, workspace, n_intervals,
                 warm_start, tol, max_iter)
    check_ends(mech, p)
    try:
        mech.forward_dynamics_derivatives(p.q0, np.zeros(mech.dof), tau=np.zeros(mech.dof))
    except ValueError as exc:
        raise PlanError(f"collocation needs the exact derivatives of forward dynamics: {exc}") from exc
    why = None
    if warm_start is None:
        warm_start, why = _straight(mech, p)
        if p.objective == "effort" and p.duration is not None and warm_start is not None \
                and warm_start.duration > p.duration:
            warm_start = _fastest(mech, p, warm_start)
    return _solve(mech, p, p.objective, _warm_start(mech, p, p.duration, warm_start, why))


def _fastest(mech: Mechanism, p: Problem, line: PlannedMotion) -> PlannedMotion:
    """The minimum-time motion, a start for minimum effort in a duration shorter than the
    straight path's fastest timing ``line``; a duration no motion within the limits can
    keep is refused."""
    assert p.duration is not None
    fastest = _solve(mech, p, "time", _warm_start(mech, p, None, line, None))
    if not fastest.success:
        raise InfeasiblePlan(f"duration: {p.duration:g} s is shorter than the straight path's fastest timing within "
                             f"the limits ({line.duration:.6g} s), and the minimum-time motion that would say whether "
                             f"any is that fast did not converge (IPOPT: {fastest.status}); give a longer duration")
    if fastest.duration > p.duration:
        raise InfeasiblePlan(f"duration: no motion within the limits takes {p.duration:g} s; the fastest takes "
                             f"{fastest.duration:.6g} s (minimum time, {p.n} intervals): give at least that")
    return fastest


def _solve(mech: Mechanism, p: Problem, objective: str, start: tuple[Any, ...]) -> CollocatedMotion:
    """IPOPT on the collocation NLP from the start (T, q, qd, tau) at the nodes."""
    import casadi as ca

    m, n = mech.dof, p.n
    T0, q_w, qd_w, tau_w = start
    keep: list[Any] = []
    w = ca.MX.sym("w", 3 * m * (n + 1) + 1)
    Q = ca.reshape(w[0:m * (n + 1)], m, n + 1)
    QD = ca.reshape(w[m * (n + 1):2 * m * (n + 1)], m, n + 1)
    U = ca.reshape(w[2 * m * (n + 1):3 * m * (n + 1)], m, n + 1)
    T = w[-1]
    h = T / n
    g, lbg, ubg = _constraints(ca, mech, p, Q, QD, U, h, keep)
    if objective == "time":
        J = T
    else:
        Ua, Ub = U[:, :-1], U[:, 1:]
        J = h / 3 * ca.sum1(ca.sum2(Ua**2 + Ua * Ub + Ub**2))
    inf = np.inf
    lbq, ubq = np.full((n + 1, m), -inf), np.full((n + 1, m), inf)
    lbq[0] = ubq[0] = p.q0
    lbq[-1] = ubq[-1] = p.q1
    lbqd, ubqd = np.tile(-p.v, (n + 1, 1)), np.tile(p.v, (n + 1, 1))
    lbqd[[0, -1]] = ubqd[[0, -1]] = 0.0
    lbu = np.tile(p.lo if p.lo is not None else np.full(m, -inf), (n + 1, 1))
    ubu = np.tile(p.hi if p.hi is not None else np.full(m, inf), (n + 1, 1))
    lbT, ubT = (T0, T0) if objective == "effort" else (1e-3 * T0, 1e3 * T0)
    # Columns of the casadi matrices are the nodes: (n + 1, m) row-major is their column-major.
    lbx = np.concatenate([lbq.ravel(), lbqd.ravel(), lbu.ravel(), [lbT]])
    ubx = np.concatenate([ubq.ravel(), ubqd.ravel(), ubu.ravel(), [ubT]])
    x0 = np.concatenate([q_w.ravel(), qd_w.ravel(), np.clip(tau_w, lbu, ubu).ravel(), [T0]])
    opts: dict[str, Any] = {"ipopt.hessian_approximation": "limited-memory", "ipopt.tol": p.tol,
                            "ipopt.max_iter": p.max_iter, "ipopt.print_level": 0, "print_time": False,
                            "ipopt.sb": "yes", "ipopt.bound_relax_factor": 0.0, "show_eval_warnings": False}
    solver = ca.nlpsol("collocation", "ipopt", {"x": w, "f": J, "g": ca.vertcat(*g)}, opts)
    try:
        sol = solver(x0=x0, lbx=lbx, ubx=ubx, lbg=lbg, ubg=ubg)
    except RuntimeError as exc:
        last = str(exc).strip().splitlines()[-1]
        raise PlanError(f"IPOPT (through CasADi) refused the problem: {last}") from exc
    return _result(mech, p, objective, sol, solver.stats(), (lbT, ubT))


def _constraints(ca: Any, mech: Mechanism, p: Problem, Q: Any, QD: Any, U: Any, h: Any,
                 keep: list[Any]) -> tuple[list[Any], list[float], list[float]]:
    """The defects, the speed limits between the nodes (see the module), the margin and the
    box at the inner nodes: g with its bounds."""
    m, n = mech.dof, p.n
    fd = callback(
        ca, "forward_dynamics", [m, m, m], m,
        or_nan([(m,)])(lambda q, qd, tau: mech.forward_dynamics(q, qd, tau=tau)),
        or_nan([(m, m)] * 3)(lambda q, qd, tau: [(d := mech.forward_dynamics_derivatives(q, qd, tau=tau))["dq"],
                                                    d["dqd"], d["dtau"]]),
        keep)
    F = [fd(Q[:, k], QD[:, k], U[:, k]) for k in range(n + 1)]
    g = []
    for k in range(n):
        g.append(Q[:, k + 1] - Q[:, k] - h / 2 * (QD[:, k] + QD[:, k + 1]))
        g.append(QD[:, k + 1] - QD[:, k] - h / 2 * (F[k] + F[k + 1]))
    lbg, ubg = [0.0] * (2 * m * n), [0.0] * (2 * m * n)
    limited = np.flatnonzero(np.isfinite(p.v)).tolist()
    if limited:
        g += [QD[limited, k] + h / 2 * F[k][limited] for k in range(n)]
        lbg += list(-p.v[limited]) * n
        ubg += list(p.v[limited]) * n
    if p.sigma_min is not None:
        def sigma_grad(q: FloatArray) -> list[FloatArray]:
            e = SIGMA_STEP * np.eye(m)
            return [np.array([[(sigma(mech, q + ei) - sigma(mech, q - ei)) / (2 * SIGMA_STEP) for ei in e]])]

        sig = callback(ca, "sigma_II", [m], 1, or_nan([(1,)])(lambda q: np.array([sigma(mech, q)])),
                       or_nan([(1, m)])(sigma_grad), keep)
        g += [sig(Q[:, k]) for k in range(1, n)]
        lbg += [p.sigma_min] * (n - 1)
        ubg += [np.inf] * (n - 1)
    if p.box is not None:
        ee, box_lo, box_hi = p.box
        k_x = len(box_lo)
        task = callback(ca, "task", [m], k_x, or_nan([(k_x,)])(lambda q: ee.state(q).X),
                        or_nan([(k_x, m)])(lambda q: [ee.state(q).J]), keep)
        g += [task(Q[:, k]) for k in range(1, n)]
        lbg += list(box_lo) * (n - 1)
        ubg += list(box_hi) * (n - 1)
    return g, lbg, ubg


def _result(mech: Mechanism, p: Problem, objective: str, sol: Any, stats: dict[str, Any],
            t_bounds: tuple[float, float]) -> CollocatedMotion:
    """The motion at IPOPT's final point, with its report, error estimate and dense check; a
    minimum time at the bounds put on T (1e-3 and 1e3 times the start's) is no minimum."""
    m, n = mech.dof, p.n
    status = str(stats.get("return_status", "unknown"))
    xs = np.asarray(sol["x"], dtype=float).ravel()
    at_bound = objective == "time" and not t_bounds[0] * (1 + T_BOUND_TOL) < xs[-1] < t_bounds[1] * (1 - T_BOUND_TOL)
    if at_bound:
        status = (f"{status}; T = {xs[-1]:.6g} s is at its bound (1e-3 to 1e3 times the start's {t_bounds[0] * 1e3:.6g} "
                  "s): give a first guess duration= nearer the minimum")
    if not np.all(np.isfinite(xs)):
        raise PlanError(f"IPOPT ended ({status}) at a point where the dynamics are undefined; start nearer (warm_start=) "
                        "or add a singularity margin (sigma_min=)")
    nm = m * (n + 1)
    q, qd, tau = xs[:nm].reshape(n + 1, m), xs[nm:2 * nm].reshape(n + 1, m), xs[2 * nm:3 * nm].reshape(n + 1, m)
    t = np.linspace(0.0, xs[-1], n + 1)
    try:
        qdd = np.array([mech.forward_dynamics(a, b, tau=c) for a, b, c in zip(q, qd, tau)])
    except (SingularityError, AssemblyError, ValueError) as exc:
        raise PlanError(f"IPOPT ended ({status}) at a configuration where the dynamics are undefined: {exc}; add a "
                        "margin (sigma_min=) or start nearer (warm_start=)") from exc
    hk = t[1] - t[0]
    defect = max(np.abs(np.diff(q, axis=0) - hk / 2 * (qd[:-1] + qd[1:])).max(),
                 np.abs(np.diff(qd, axis=0) - hk / 2 * (qdd[:-1] + qdd[1:])).max())
    iters = stats.get("iterations", {})
    # Without an iteration recorded the violation is unknown: no bound on it.
    violation = float(iters["inf_pr"][-1]) if iters.get("inf_pr") else float("inf")
    motion = CollocatedMotion(mech=mech, t=t, q=q, qd=qd, qdd=qdd, tau=tau, limit_ratio=np.nan, objective=objective,
                              cost=float(sol["f"]), status=status,
                              success=bool(stats.get("success", False)) and status in CONVERGED and not at_bound,
                              iterations=int(stats.get("iter_count", -1)), violation=violation,
                              max_defect=float(defect), error=np.zeros(m))
    motion.error = _error_estimate(motion)
    motion.limit_ratio = _limit_ratio(motion, p)
    return motion


def _limit_ratio(c: CollocatedMotion, p: Problem) -> float:
    """The largest fraction of an effort or speed limit used at CHECK_POINTS points of every
    interval (ends included): |tau - mid| / half of [lo, hi], |qd| / v; 0 without limits."""
    f = np.linspace(0.0, 1.0, CHECK_POINTS)
    t = (c.t[:-1, None] + np.diff(c.t)[:, None] * f).ravel()
    used = [np.zeros(len(t))]
    if p.lo is not None and p.hi is not None:
        used.append(np.max(np.abs(c.efforts(t) - (p.lo + p.hi) / 2) / ((p.hi - p.lo) / 2), axis=1))
    used.append(np.max(np.abs(c.state(t)[1]) / p.v, axis=1))
    return float(np.max(used))


def _error_estimate(c: CollocatedMotion) -> FloatArray:
    """The stated accuracy of q (m,): see the module; inf where the interpolant meets a
    singularity between nodes (an unconverged solution's)."""
    h = np.diff(c.t)[:, None]
    mid = (c.t[:-1] + c.t[1:]) / 2
    q_m, qd_m, qdd_m = c.state(mid)
    tau_m = c.efforts(mid)
    try:
        f_m = np.array([c.mech.forward_dynamics(a, b, tau=u) for a, b, u in zip(q_m, qd_m, tau_m)])
    except (SingularityError, AssemblyError, ValueError):
        return np.full(c.q.shape[1], np.inf)
    eta_q = 2 * h / 3 * np.abs((c.qd[:-1] + c.qd[1:]) / 2 - qd_m)
    eta_qd = 2 * h / 3 * np.abs(qdd_m - f_m)
    return np.asarray((eta_q + eta_qd * (c.t[-1] - c.t[1:])[:, None]).sum(axis=0))
