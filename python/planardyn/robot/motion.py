"""Task-space motion: inverse kinematics along a prescribed end-effector path, input rates and
accelerations from the analogues (not by differencing), then the inverse dynamics.

Stages per sample i of the path (t_i, X_i, Xd_i, Xdd_i):

    q_i    Newton on X(q) = X_i from the predictor q + qd h + qdd h^2 / 2 (same working mode)
    qd_i   J qd = Xd_i
    qdd_i  J qdd = Xdd_i - d2X/dq2 [qd_i, qd_i]      (the acceleration analogues)
    sigma  type I (J) and type II (kinematics) measures; refused below ``singular_tol``

and at the end tau = mech.inverse_dynamics(q, qd, qdd) for all rows at once.
"""

from __future__ import annotations

from dataclasses import dataclass, field, replace
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from .._core import AssemblyError, SingularityError
from .effector import EffectorState, EndEffector
from .paths import TaskPath

if TYPE_CHECKING:
    from ..mechanism import DriveFunction
    from ..result import SimulationResult

FloatArray = NDArray[np.float64]

# A motion is refused where either singularity measure (dimensionless, 0 at the singularity)
# falls below this: there the input rates (type I) or the drive efforts (type II) grow as
# 1/sigma, i.e. about 1000 times their values in a well-conditioned pose.
SINGULAR_TOL = 1e-3
# Default spacing of the samples of a path (s).
DEFAULT_DT = 1e-3
# Between samples, a local minimum of a measure below this level is refined (golden section
# in t), so that a singularity crossed between two samples is not missed.
REFINE_LEVEL = 0.05
# Tolerances of the open-loop check run (Motion.simulate): its integration error must stay far
# below the 1e-6 m to which the efforts are required to reproduce the path.
CHECK_RTOL, CHECK_ATOL = 1e-10, 1e-12
REFINE_ITER = 40
# Largest departure (rad for angles, L for displacements) of a solved q from the second-order
# predictor: beyond it the solution has jumped to another working mode.
JUMP_TOL = 0.05

KIND_TEXT = {
    "I": "type I (serial) singularity: the end effector cannot move in some direction there "
         "(a leg stretched out or folded back), the input rates would be infinite",
    "II": "type II (parallel) singularity: the mechanism gains an uncontrolled motion there and "
          "no drive effort holds it, the efforts would be infinite",
}


@dataclass
class TaskMotion:
    """A task-space motion solved for the inputs, time-major arrays.

    ``t`` (N,) s; ``X``, ``Xd``, ``Xdd`` (N, k) prescribed task coordinates and their rates
    (m, m/s, m/s^2; rad... for psi); ``q``, ``qd``, ``qdd`` (N, m) inputs (rad or m, per s,
    per s^2); ``tau`` (N, m) drive efforts (N m or N; the model's loads included, its drives
    not); ``sigma_I``, ``sigma_II`` (N,) the singularity measures (dimensionless, 0 at the
    singularity); ``condition`` (N,) condition number of the scaled J.
    """

    effector: EndEffector
    label: str
    t: FloatArray
    X: FloatArray
    Xd: FloatArray
    Xdd: FloatArray
    q: FloatArray
    qd: FloatArray
    qdd: FloatArray
    tau: FloatArray
    sigma_I: FloatArray
    sigma_II: FloatArray
    condition: FloatArray
    notes: list[str] = field(default_factory=list)

    @property
    def mech(self) -> Any:
        return self.effector.mech

    def __repr__(self) -> str:
        return (f"TaskMotion({self.label}; {len(self.t)} samples, min sigma_I {self.sigma_I.min():.3g}, "
                f"min sigma_II {self.sigma_II.min():.3g}, peak |tau| {np.abs(self.tau).max(axis=0).round(4).tolist()})")

    def drives(self) -> DriveFunction:
        """The drive efforts as a callable ``f(t, q, qd)`` for :meth:`Mechanism.simulate`: a
        cubic spline of ``tau`` in t (open loop: q and qd are not used)."""
        from scipy.interpolate import CubicSpline

        spline = CubicSpline(self.t, self.tau, axis=0)
        return lambda t, q, qd: spline(t)

    def simulate(self, **options: Any) -> SimulationResult:
        """Forward dynamics under :meth:`drives` from the motion's first state, output at
        ``t`` (open loop: the check that the efforts produce the motion). ``options`` go to
        :meth:`Mechanism.simulate` (default dop853, rtol 1e-10, atol 1e-12)."""
        kw = dict(method="dop853", rtol=CHECK_RTOL, atol=CHECK_ATOL, t_eval=self.t, q0=self.q[0], qd0=self.qd[0],
                  drives=self.drives())
        kw.update(options)
        return self.mech.simulate(self.t[-1], **kw)

    def task_of(self, q: ArrayLike) -> FloatArray:
        """(N, k) task coordinates along coordinates q (N, m), e.g. a simulation's ``res.q``."""
        return np.array([self.effector.state(qi).X for qi in np.atleast_2d(q)])

    def plot(self, fig: Any = None) -> list[Any]:
        """Path (with the robot at the start), inputs, efforts and singularity measures on one
        figure (2 x 2). Returns the artists."""
        from .plots import plot_motion

        return plot_motion(self, fig)

    def _head(self, n: int) -> TaskMotion:
        cut = {k: getattr(self, k)[:n] for k in ("t", "X", "Xd", "Xdd", "q", "qd", "qdd", "tau",
                                                  "sigma_I", "sigma_II", "condition")}
        return replace(self, **cut)


def _sample_times(duration: float, n: int | None, dt: float | None) -> FloatArray:
    if n is None:
        n = int(np.ceil(duration / (dt or DEFAULT_DT))) + 1
    if n < 2:
        raise ValueError(f"a motion needs at least 2 samples, got n = {n}")
    return np.linspace(0.0, duration, n)


def _where(ee: EndEffector, X: FloatArray) -> str:
    pos = f"({X[0]:.4f}, {X[1]:.4f}) m"
    return pos if ee.dim == 2 else f"{pos}, psi = {X[2]:.4f} rad"


def singularity_message(ee: EndEffector, kind: str, t: float, X: FloatArray, q: FloatArray,
                        sigma: float, tol: float) -> str:
    """The message of a refused motion: which kind, where (end effector, inputs) and when."""
    return (f"the prescribed motion reaches a {KIND_TEXT[kind]}; at t = {t:.4f} s, end effector "
            f"{ee.point} at {_where(ee, X)}, q = {np.array2string(q, precision=4)}: sigma_{kind} = "
            f"{sigma:.2e} < {tol:g}. Keep the path away from it (robot.singularity_map shows where "
            f"they are); the motion up to there is the error's .partial")


class _Solver:
    """Solves one sample after another, keeping the last state as the warm start."""

    def __init__(self, ee: EndEffector, tol: float) -> None:
        self.ee, self.tol = ee, tol

    def rates(self, st: EffectorState, Xd: FloatArray, Xdd: FloatArray) -> tuple[FloatArray, FloatArray]:
        qd = np.linalg.solve(st.J, Xd)
        qdd = np.linalg.solve(st.J, Xdd - self.ee.convective(st.kin, qd))
        return qd, qdd

    def step(self, X: FloatArray, q: FloatArray, qd: FloatArray, qdd: FloatArray, h: float) -> EffectorState:
        """Solve X from the state (q, qd, qdd) h seconds before; AssemblyError on a jump."""
        pred = q + qd * h + 0.5 * qdd * h * h
        st = self.ee.solve(X, pred)
        jump = np.max(np.abs(st.q - pred) / self.ee._input_scale)
        if jump > JUMP_TOL:
            raise AssemblyError(f"the inputs jumped by {jump:.3g} from the predictor: another working mode")
        return st


def solve_motion(
    effector: EndEffector,
    path: TaskPath,
    *,
    n: int | None = None,
    dt: float | None = None,
    q_start: ArrayLike | None = None,
    singular_tol: float = SINGULAR_TOL,
) -> TaskMotion:
    """Inverse kinematics and inverse dynamics of a prescribed end-effector motion.

    Parameters
    ----------
    effector : EndEffector
        What follows the path (a point for m = 2, a pose for m = 3).
    path : TaskPath
        From :func:`line`, :func:`point_to_point`, :func:`circle` or :func:`table`.
    n, dt : int, float
        Number of samples, or their spacing (s; default 1 ms).
    q_start : (m,) array_like, optional
        A configuration on the wanted working mode (default the drawing); the path's first
        point is reached from it by continuation in task space.
    singular_tol : float
        Refuse the motion where sigma_I or sigma_II falls below this (dimensionless).

    Raises
    ------
    SingularityError
        The path reaches a type I or type II singularity; the message says which, when and
        where; attributes ``kind`` (``'I'``/``'II'``), ``t``, ``X``, ``sigma`` and ``partial``
        (the :class:`TaskMotion` before it).
    AssemblyError
        A point of the path is out of reach on this working mode (``partial`` attached).
    """
    ee = effector
    path = path.with_dim(ee.dim)
    t = _sample_times(path.duration, n, dt)
    X, Xd, Xdd = path.sample(t)
    N, m = len(t), ee.mech.dof
    q, qd, qdd = (np.zeros((N, m)) for _ in range(3))
    sI, sII, cond = (np.zeros(N) for _ in range(3))
    solver = _Solver(ee, singular_tol)
    partial = lambda i: _finish(ee, path, t, X, Xd, Xdd, q, qd, qdd, sI, sII, cond, i)  # noqa: E731

    for i in range(N):
        try:
            st = ee.inverse(X[0], q_start) if i == 0 else solver.step(X[i], q[i - 1], qd[i - 1], qdd[i - 1], t[i] - t[i - 1])
        except (AssemblyError, SingularityError) as exc:
            _fail_between(ee, solver, t, X, Xd, Xdd, q, qd, qdd, i, singular_tol, exc, partial)
        q[i] = st.q
        qd[i], qdd[i] = solver.rates(st, Xd[i], Xdd[i])
        sI[i], sII[i], cond[i] = st.sigma_I, st.sigma_II, ee.condition(st.J)
        kind = _below(sI[i], sII[i], singular_tol)
        if kind:
            _raise(ee, kind, t[i], X[i], q[i], min(sI[i], sII[i]), singular_tol, partial(i))
        if i >= 2:
            _refine(ee, solver, t, X, q, qd, qdd, (sI, sII), i - 1, singular_tol, partial)
    return partial(N)


def _below(s_I: float, s_II: float, tol: float) -> str | None:
    if min(s_I, s_II) >= tol:
        return None
    return "I" if s_I <= s_II else "II"


def _raise(ee: EndEffector, kind: str, t: float, X: FloatArray, q: FloatArray, sigma: float, tol: float,
           partial: TaskMotion) -> None:
    exc = SingularityError(singularity_message(ee, kind, t, X, q, sigma, tol))
    exc.kind, exc.t, exc.X, exc.sigma, exc.partial = kind, t, X, sigma, partial
    raise exc


def _refine(ee: EndEffector, solver: _Solver, t: FloatArray, X: FloatArray, q: FloatArray, qd: FloatArray,
            qdd: FloatArray, sigmas: tuple[FloatArray, FloatArray], j: int, tol: float, partial: Any) -> None:
    """If a measure has a local minimum at sample j below REFINE_LEVEL, find the minimum in
    (t_j-1, t_j+1) by golden section and refuse the motion if it is below tol there."""
    for kind, s in zip(("I", "II"), sigmas):
        if not (s[j] < REFINE_LEVEL and s[j] <= s[j - 1] and s[j] <= s[j + 1]):
            continue
        path_X = _interp_path(t, X, j)
        a, b = t[j - 1], t[j + 1]
        g = (np.sqrt(5) - 1) / 2

        def measure(tt: float) -> tuple[float, EffectorState]:
            st = solver.step(path_X(tt), q[j], qd[j], qdd[j], tt - t[j])
            return (st.sigma_I if kind == "I" else st.sigma_II), st

        try:
            c, d = b - g * (b - a), a + g * (b - a)
            fc, fd = measure(c)[0], measure(d)[0]
            for _ in range(REFINE_ITER):
                if fc < fd:
                    b, d, fd = d, c, fc
                    c = b - g * (b - a)
                    fc = measure(c)[0]
                else:
                    a, c, fc = c, d, fd
                    d = a + g * (b - a)
                    fd = measure(d)[0]
                if min(fc, fd) < tol:
                    break
            tm = c if fc < fd else d
            sigma, st = measure(tm)
        except (AssemblyError, SingularityError):
            sigma, tm, st = 0.0, t[j], None
        if sigma < tol:
            qm = q[j] if st is None else st.q
            _raise(ee, kind, tm, path_X(tm), qm, sigma, tol, partial(j if tm > t[j] else j - 1))


def _interp_path(t: FloatArray, X: FloatArray, j: int):  # noqa: ANN202
    """X(t) near sample j: the quadratic through samples j-1, j, j+1 (exact enough for the
    location of a singularity; the refused motion is not integrated from it)."""
    ts, Xs = t[j - 1 : j + 2], X[j - 1 : j + 2]
    coef = np.polyfit(ts - t[j], Xs, 2)
    return lambda tt: np.array([np.polyval(coef[:, k], tt - t[j]) for k in range(X.shape[1])])


def _fail_between(ee: EndEffector, solver: _Solver, t: FloatArray, X: FloatArray, Xd: FloatArray,
                  Xdd: FloatArray, q: FloatArray, qd: FloatArray, qdd: FloatArray, i: int, tol: float,
                  exc: Exception, partial: Any) -> None:
    """Sample i could not be solved: find by bisection how far past t_i-1 the path can be
    followed; at that edge one of the measures is near zero (the singularity that stops it),
    or the target is simply out of reach."""
    if i == 0:
        err = AssemblyError(f"the path's first point {_where(ee, X[0])} cannot be reached from the drawing: {exc}")
        err.partial = partial(0)
        raise err from exc
    lo, hi, best = t[i - 1], t[i], None
    path_X = _interp_path(t, X, i - 1) if i >= 2 else (lambda tt: X[i - 1] + (tt - t[i - 1]) / (t[i] - t[i - 1]) * (X[i] - X[i - 1]))
    for _ in range(30):
        mid = 0.5 * (lo + hi)
        try:
            best = (mid, solver.step(path_X(mid), q[i - 1], qd[i - 1], qdd[i - 1], mid - t[i - 1]))
            lo = mid
        except (AssemblyError, SingularityError):
            hi = mid
    if best is not None:
        tm, st = best
        kind = "I" if st.sigma_I <= st.sigma_II else "II"
        sigma = min(st.sigma_I, st.sigma_II)
        if sigma < REFINE_LEVEL:
            _raise(ee, kind, tm, st.X, st.q, sigma, tol if sigma < tol else REFINE_LEVEL, partial(i))
    err = AssemblyError(f"the path leaves the reach of the working mode at t = {t[i]:.4f} s, end effector at "
                        f"{_where(ee, X[i])}: {exc}; the motion up to there is the error's .partial")
    err.partial = partial(i)
    raise err from exc


def _finish(ee: EndEffector, path: TaskPath, t: FloatArray, X: FloatArray, Xd: FloatArray, Xdd: FloatArray,
            q: FloatArray, qd: FloatArray, qdd: FloatArray, sI: FloatArray, sII: FloatArray, cond: FloatArray,
            n: int) -> TaskMotion:
    tau = ee.mech.inverse_dynamics(q[:n], qd[:n], qdd[:n]) if n else np.zeros((0, q.shape[1]))
    return TaskMotion(ee, path.label, t[:n].copy(), X[:n].copy(), Xd[:n].copy(), Xdd[:n].copy(), q[:n].copy(),
                      qd[:n].copy(), qdd[:n].copy(), tau, sI[:n].copy(), sII[:n].copy(), cond[:n].copy())
