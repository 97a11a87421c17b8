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

f and its Jacobian are planardyn's (Mechanism.forward_dynamics and the exact
forward_dynamics_derivatives), each node one casadi.Callback whose Jacobian is another
Callback. IPOPT (through CasADi) solves the NLP with a limited-memory Hessian. The type II
measure sigma_II's gradient (for the singularity margin) is by central differences of the
kinematics, step SIGMA_STEP; the effector's task coordinates use its exact Jacobian.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import Any, Literal

import numpy as np
from numpy.typing import ArrayLike, NDArray

from .._core import AssemblyError, SingularityError
from ..mechanism import Mechanism
from ..robot import EndEffector
from .planned import PlanError, PlannedMotion, effort_bounds, speed_bounds
from .topp import time_optimal

FloatArray = NDArray[np.float64]

#: Central-difference step (rad or m) of the type II measure's gradient.
SIGMA_STEP = 1e-6


@dataclass
class Workspace:
    """A box the effector's task coordinates X (m, m[, rad]) stay in: lo <= X(q) <= hi at
    every node (inf where unbounded)."""

    effector: EndEffector
    lo: ArrayLike
    hi: ArrayLike


@dataclass
class CollocatedMotion(PlannedMotion):
    """The solution of :func:`collocate` and IPOPT's report on it.

    ``t`` (N + 1,) node times (s); ``q``, ``qd``, ``qdd``, ``tau`` (N + 1, m) there (qdd the
    forward dynamics at the node); ``objective`` "time" or "effort"; ``cost`` its value (s,
    or the integral of sum tau^2, N^2 m^2 s); ``status`` IPOPT's return status, ``success``
    True only when IPOPT converged (``Solve_Succeeded`` or ``Solved_To_Acceptable_Level``),
    ``iterations`` its iteration count, ``violation`` the largest constraint violation of the
    final point as IPOPT measured it, ``max_defect`` the largest trapezoidal defect
    (rad or m, and per s); ``error`` (m,) the stated accuracy of q (rad or m; see the module;
    inf when the motion between nodes meets a singularity).
    """

    objective: str
    cost: float
    status: str
    success: bool
    iterations: int
    violation: float
    max_defect: float
    error: FloatArray

    def _interval(self, t: ArrayLike) -> tuple[Any, FloatArray, FloatArray]:
        tt = np.clip(np.atleast_1d(np.asarray(t, dtype=float)), 0.0, self.t[-1])
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


def _function(ca: Any, name: str, sizes: Sequence[int], n_out: int, value: Callable[..., FloatArray],
              jacobian: Callable[..., Sequence[FloatArray]], keep: list[Any]) -> Any:
    """A casadi.Callback y = value(*args) whose Jacobian is another Callback, jacobian(*args)
    giving dy/d(each arg). ``keep`` holds both alive while the solver uses them."""
    n_in = len(sizes)

    class Jacobian(ca.Callback):
        def __init__(self, jname: str, opts: dict[str, Any]) -> None:
            ca.Callback.__init__(self)
            self.construct(jname, opts)

        def get_n_in(self) -> int:
            return n_in + 1

        def get_n_out(self) -> int:
            return n_in

        def get_sparsity_in(self, i: int) -> Any:
            return ca.Sparsity.dense(sizes[i], 1) if i < n_in else ca.Sparsity(n_out, 1)

        def get_sparsity_out(self, i: int) -> Any:
            return ca.Sparsity.dense(n_out, sizes[i])

        def eval(self, arg: list[Any]) -> list[Any]:
            return [ca.DM(j) for j in jacobian(*(np.asarray(a, dtype=float).ravel() for a in arg[:n_in]))]

    class Function(ca.Callback):
        def __init__(self) -> None:
            ca.Callback.__init__(self)
            self.construct(name, {"enable_fd": False})

        def get_n_in(self) -> int:
            return n_in

        def get_n_out(self) -> int:
            return 1

        def get_sparsity_in(self, i: int) -> Any:
            return ca.Sparsity.dense(sizes[i], 1)

        def get_sparsity_out(self, i: int) -> Any:
            return ca.Sparsity.dense(n_out, 1)

        def eval(self, arg: list[Any]) -> list[Any]:
            return [ca.DM(value(*(np.asarray(a, dtype=float).ravel() for a in arg)))]

        def has_jacobian(self) -> bool:
            return True

        def get_jacobian(self, jname: str, inames: Any, onames: Any, opts: dict[str, Any]) -> Any:
            jac = Jacobian(jname, opts)
            keep.append(jac)
            return jac

    f = Function()
    keep.append(f)
    return f


def _or_nan(shapes: Sequence[tuple[int, ...]]) -> Callable[[Callable[..., Any]], Callable[..., Any]]:
    """Evaluations where the kinematics fail (a singularity, out of reach) give NaN to IPOPT,
    which then shortens its step; they never reach the result (checked there)."""

    def wrap(fn: Callable[..., Any]) -> Callable[..., Any]:
        def safe(*args: FloatArray) -> Any:
            try:
                return fn(*args)
            except (SingularityError, AssemblyError):
                nan = [np.full(s, np.nan) for s in shapes]
                return nan[0] if len(nan) == 1 else nan

        return safe

    return wrap


def _sigma(mech: Mechanism, q: FloatArray) -> float:
    return float(mech.kinematics(q)["sigma_min"])


def _warm_start(mech: Mechanism, q_start: FloatArray, q_end: FloatArray, lo: FloatArray | None, hi: FloatArray | None,
                speed: FloatArray, duration: float | None, n: int, previous: PlannedMotion | None) -> tuple[Any, ...]:
    """(T, q, qd, tau) at n + 1 nodes: a previous motion, or the straight joint path timed by
    TOPP within the limits, stretched to ``duration`` when one is given (efforts by inverse
    dynamics of the stretched motion); without limits, or for a model TOPP refuses (dampers),
    the straight path in ``duration`` with the cubic timing s = 3 r^2 - 2 r^3, r = t / T (the
    minimum-effort timing of a double integrator)."""
    if previous is None:
        effort = None if lo is None or hi is None else np.stack([lo, hi], axis=1)
        try:
            if effort is None and not np.isfinite(speed).any():
                raise PlanError("no limits to time the warm start with")
            previous = time_optimal(mech, [q_start, q_end], effort, None if not np.isfinite(speed).any() else speed,
                                    n_grid=max(2 * n, 50))
        except PlanError as exc:
            if duration is None:
                raise PlanError(f"warm start: {exc}; give a first guess duration= (s) or warm_start=") from exc
            r = np.linspace(0.0, 1.0, n + 1)[:, None]
            dq = q_end - q_start
            q = q_start + dq * (3 * r**2 - 2 * r**3)
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
        A type II singularity margin: sigma_II(q_k) >= sigma_min at every node.
    workspace : Workspace, optional
        A box for the effector's task coordinates at every node.
    n_intervals : int
        N, the collocation intervals (>= 2).
    warm_start : PlannedMotion, optional
        A motion to start from (e.g. a previous solution), stretched to ``duration``;
        default the straight joint path timed by :func:`time_optimal` within the limits.
    tol, max_iter
        IPOPT's tolerance and iteration limit.

    Returns
    -------
    CollocatedMotion
        With IPOPT's status; ``success`` is False when IPOPT did not converge.

    Raises
    ------
    PlanError
        Bad arguments, or ends that break the margin or the workspace.
    """
    import casadi as ca

    m = mech.dof
    q0, q1 = (np.asarray(v, dtype=float) for v in (q_start, q_end))
    if q0.shape != (m,) or q1.shape != (m,) or not (np.all(np.isfinite(q0)) and np.all(np.isfinite(q1))):
        raise PlanError(f"q_start, q_end: expected ({m},) finite coordinates, got shapes {q0.shape}, {q1.shape}")
    if objective not in ("time", "effort"):
        raise PlanError(f"objective: 'time' or 'effort', got {objective!r}")
    if objective == "effort" and (duration is None or not np.isfinite(duration) or duration <= 0):
        raise PlanError(f"objective 'effort' needs a positive duration (s), got {duration}")
    if objective == "time" and effort is None and speed is None:
        raise PlanError("objective 'time' needs effort or speed limits")
    if n_intervals < 2:
        raise PlanError(f"n_intervals: need at least 2, got {n_intervals}")
    if duration is not None and not (np.isfinite(duration) and duration > 0):
        raise PlanError(f"duration: a positive time (s), got {duration}")
    try:
        mech.forward_dynamics_derivatives(q0, np.zeros(m), tau=np.zeros(m))
    except ValueError as exc:
        raise PlanError(f"collocation needs the exact derivatives of forward dynamics: {exc}") from exc
    n = n_intervals
    lo, hi = effort_bounds(m, effort) if effort is not None else (None, None)
    v = speed_bounds(m, speed)
    for name, qe in (("q_start", q0), ("q_end", q1)):
        if sigma_min is not None and _sigma(mech, qe) < sigma_min:
            raise PlanError(f"{name}: sigma_II {_sigma(mech, qe):.3g} is below the margin {sigma_min}; move it or lower "
                            "sigma_min")
        if workspace is not None:
            X = workspace.effector.state(qe).X
            if np.any(X < np.asarray(workspace.lo, dtype=float)) or np.any(X > np.asarray(workspace.hi, dtype=float)):
                raise PlanError(f"{name}: the effector at {np.round(X, 6).tolist()} is outside the workspace box")

    T0, q_w, qd_w, tau_w = _warm_start(mech, q0, q1, lo, hi, v, duration, n, warm_start)

    keep: list[Any] = []
    fd = _function(
        ca, "forward_dynamics", [m, m, m], m,
        _or_nan([(m,)])(lambda q, qd, tau: mech.forward_dynamics(q, qd, tau=tau)),
        _or_nan([(m, m)] * 3)(lambda q, qd, tau: [(d := mech.forward_dynamics_derivatives(q, qd, tau=tau))["dq"],
                                                     d["dqd"], d["dtau"]]),
        keep)

    w = ca.MX.sym("w", 3 * m * (n + 1) + 1)
    Q = ca.reshape(w[0:m * (n + 1)], m, n + 1)
    QD = ca.reshape(w[m * (n + 1):2 * m * (n + 1)], m, n + 1)
    U = ca.reshape(w[2 * m * (n + 1):3 * m * (n + 1)], m, n + 1)
    T = w[-1]
    h = T / n
    F = [fd(Q[:, k], QD[:, k], U[:, k]) for k in range(n + 1)]
    g = []
    for k in range(n):
        g.append(Q[:, k + 1] - Q[:, k] - h / 2 * (QD[:, k] + QD[:, k + 1]))
        g.append(QD[:, k + 1] - QD[:, k] - h / 2 * (F[k] + F[k + 1]))
    lbg, ubg = [0.0] * (2 * m * n), [0.0] * (2 * m * n)
    if sigma_min is not None:
        def sigma_grad(q: FloatArray) -> list[FloatArray]:
            e = SIGMA_STEP * np.eye(m)
            return [np.array([[(_sigma(mech, q + ei) - _sigma(mech, q - ei)) / (2 * SIGMA_STEP) for ei in e]])]

        sig = _function(ca, "sigma_II", [m], 1, _or_nan([(1,)])(lambda q: np.array([_sigma(mech, q)])),
                        _or_nan([(1, m)])(sigma_grad), keep)
        g += [sig(Q[:, k]) for k in range(1, n)]
        lbg += [sigma_min] * (n - 1)
        ubg += [np.inf] * (n - 1)
    if workspace is not None:
        ee = workspace.effector
        k_x = len(ee.names)
        box_lo = np.broadcast_to(np.asarray(workspace.lo, dtype=float), (k_x,))
        box_hi = np.broadcast_to(np.asarray(workspace.hi, dtype=float), (k_x,))
        task = _function(ca, "task", [m], k_x, _or_nan([(k_x,)])(lambda q: ee.state(q).X),
                         _or_nan([(k_x, m)])(lambda q: [ee.state(q).J]), keep)
        g += [task(Q[:, k]) for k in range(1, n)]
        lbg += list(box_lo) * (n - 1)
        ubg += list(box_hi) * (n - 1)

    if objective == "time":
        J = T
    else:
        Ua, Ub = U[:, :-1], U[:, 1:]
        J = h / 3 * ca.sum1(ca.sum2(Ua**2 + Ua * Ub + Ub**2))

    inf = np.inf
    lbq, ubq = np.full((n + 1, m), -inf), np.full((n + 1, m), inf)
    lbq[0] = ubq[0] = q0
    lbq[-1] = ubq[-1] = q1
    lbqd, ubqd = np.tile(-v, (n + 1, 1)), np.tile(v, (n + 1, 1))
    lbqd[[0, -1]] = ubqd[[0, -1]] = 0.0
    lbu = np.tile(lo if lo is not None else np.full(m, -inf), (n + 1, 1))
    ubu = np.tile(hi if hi is not None else np.full(m, inf), (n + 1, 1))
    lbT, ubT = (T0, T0) if objective == "effort" else (1e-3 * T0, 1e3 * T0)
    # Columns of the casadi matrices are the nodes: (n + 1, m) row-major is their column-major.
    lbx = np.concatenate([lbq.ravel(), lbqd.ravel(), lbu.ravel(), [lbT]])
    ubx = np.concatenate([ubq.ravel(), ubqd.ravel(), ubu.ravel(), [ubT]])
    x0 = np.concatenate([q_w.ravel(), qd_w.ravel(), np.clip(tau_w, lbu, ubu).ravel(), [T0]])

    opts: dict[str, Any] = {"ipopt.hessian_approximation": "limited-memory", "ipopt.tol": tol, "ipopt.max_iter": max_iter,
            "ipopt.print_level": 0, "print_time": False, "ipopt.sb": "yes",
            "ipopt.bound_relax_factor": 0.0}
    nlp: dict[str, Any] = {"x": w, "f": J, "g": ca.vertcat(*g)}
    solver = ca.nlpsol("collocation", "ipopt", nlp, opts)
    sol = solver(x0=x0, lbx=lbx, ubx=ubx, lbg=lbg, ubg=ubg)
    stats = solver.stats()
    status = str(stats.get("return_status", "unknown"))
    xs = np.asarray(sol["x"], dtype=float).ravel()
    if not np.all(np.isfinite(xs)):
        raise PlanError(f"IPOPT ended ({status}) at a point where the dynamics are undefined; start nearer (warm_start=) "
                        "or add a singularity margin (sigma_min=)")
    nm = m * (n + 1)
    q, qd, tau = xs[:nm].reshape(n + 1, m), xs[nm:2 * nm].reshape(n + 1, m), xs[2 * nm:3 * nm].reshape(n + 1, m)
    t = np.linspace(0.0, xs[-1], n + 1)
    try:
        qdd = np.array([mech.forward_dynamics(a, b, tau=c) for a, b, c in zip(q, qd, tau)])
    except (SingularityError, AssemblyError) as exc:
        raise PlanError(f"IPOPT ended ({status}) at a singular configuration: {exc}; add a margin (sigma_min=)") from exc
    hk = t[1] - t[0]
    defect = max(np.abs(np.diff(q, axis=0) - hk / 2 * (qd[:-1] + qd[1:])).max(),
                 np.abs(np.diff(qd, axis=0) - hk / 2 * (qdd[:-1] + qdd[1:])).max())
    iters = stats.get("iterations", {})
    violation = float(iters["inf_pr"][-1]) if iters.get("inf_pr") else float("nan")
    motion = CollocatedMotion(mech=mech, t=t, q=q, qd=qd, qdd=qdd, tau=tau, objective=objective,
                              cost=float(sol["f"]), status=status,
                              success=bool(stats.get("success", False)) and status in ("Solve_Succeeded",
                                                                                       "Solved_To_Acceptable_Level"),
                              iterations=int(stats.get("iter_count", -1)), violation=violation,
                              max_defect=float(defect), error=np.zeros(m))
    motion.error = _error_estimate(motion)
    return motion


def _error_estimate(c: CollocatedMotion) -> FloatArray:
    """The stated accuracy of q (m,): see the module; inf where the interpolant meets a
    singularity between nodes (an unconverged solution's)."""
    h = np.diff(c.t)[:, None]
    mid = (c.t[:-1] + c.t[1:]) / 2
    q_m, qd_m, qdd_m = c.state(mid)
    tau_m = c.efforts(mid)
    try:
        f_m = np.array([c.mech.forward_dynamics(a, b, tau=u) for a, b, u in zip(q_m, qd_m, tau_m)])
    except (SingularityError, AssemblyError):
        return np.full(c.q.shape[1], np.inf)
    eta_q = 2 * h / 3 * np.abs((c.qd[:-1] + c.qd[1:]) / 2 - qd_m)
    eta_qd = 2 * h / 3 * np.abs(qdd_m - f_m)
    return np.asarray((eta_q + eta_qd * (c.t[-1] - c.t[1:])[:, None]).sum(axis=0))
