"""Task-space motion: inverse kinematics along a prescribed end-effector path, input rates and
accelerations from the analogues (not by differencing), then the inverse dynamics.

Stages per sample i of the path (t_i, X_i, Xd_i, Xdd_i), computed by the core
(``planardyn::dynamics::task``) on one branch, each sample continuing from the last:

    q_i    Newton on X(q) = X_i from the predictor q + qd h + qdd h^2 / 2 (same working mode)
    qd_i   J qd = Xd_i
    qdd_i  J qdd = Xdd_i - d2X/dq2 [qd_i, qd_i]      (the acceleration analogues)
    sigma  type I (J) and type II (kinematics) measures; refused below ``singular_tol``
    tau_i  inverse dynamics at (q_i, qd_i, qdd_i)
"""

from __future__ import annotations

from dataclasses import dataclass, field, replace
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from .._core import AssemblyError, SingularityError
from ..arguments import count, error, positive
from ..notebook import Summarized, peak_rows
from .effector import EndEffector
from .paths import TaskPath
from .tolerances import SINGULAR_TOL

if TYPE_CHECKING:
    from ..mechanism import DriveFunction
    from ..result import SimulationResult

FloatArray = NDArray[np.float64]

# Default spacing of the samples of a path (s).
DEFAULT_DT = 1e-3
#: Most samples of a task motion: 1e7 rows of q, qd, qdd, tau and the poses take gigabytes.
MAX_SAMPLES = 10**7
# Tolerances of the open-loop check run (TaskMotion.simulate): its integration error must stay
# far below the 1e-6 m to which the efforts are required to reproduce the path.
CHECK_RTOL, CHECK_ATOL = 1e-10, 1e-12


@dataclass
class TaskMotion(Summarized):
    """A task-space motion solved for the inputs, time-major arrays.

    ``t`` (N,) s; ``X``, ``Xd``, ``Xdd`` (N, k) prescribed task coordinates and their rates
    (m, m/s, m/s^2; rad... for psi); ``q``, ``qd``, ``qdd`` (N, m) inputs (rad or m, per s,
    per s^2); ``tau`` (N, m) drive efforts (N m or N; the model's loads included, its drives
    not); ``sigma_I``, ``sigma_II`` (N,) the singularity measures (dimensionless, 0 at the
    singularity); ``condition`` (N,) condition number of the scaled J; ``tau_motor`` (N, m) the
    motor torques (N m) the efforts need (``Mechanism.motor_torques``; tau itself on a
    coordinate without a motor).
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
    tau_motor: FloatArray | None = None

    @property
    def mech(self) -> Any:
        return self.effector.mech

    def __repr__(self) -> str:
        return (f"TaskMotion({self.label}; {len(self.t)} samples, min sigma_I {self.sigma_I.min():.3g}, "
                f"min sigma_II {self.sigma_II.min():.3g}, peak |tau| {np.abs(self.tau).max(axis=0).round(4).tolist()})")

    def _summary_rows(self) -> list[tuple[str, str]]:
        return [("model", self.mech.name), ("path", f"{self.label} of {self.effector.point}"),
                ("samples", f"{len(self.t)}, t = {self.t[0]:.6g} .. {self.t[-1]:.6g} s"),
                *peak_rows(self.mech, self.tau, self.qd),
                ("min sigma_I, sigma_II", f"{self.sigma_I.min():.3g}, {self.sigma_II.min():.3g}"),
                *[("note", n) for n in self.notes]]

    def drives(self) -> DriveFunction:
        """The drive efforts as a callable ``f(t, q, qd)`` for :meth:`Mechanism.simulate`: a
        cubic spline of ``tau_motor`` (the drives' efforts: a motor's torque, else tau) in t
        (open loop: q and qd are not used)."""
        from scipy.interpolate import CubicSpline

        spline = CubicSpline(self.t, self.tau if self.tau_motor is None else self.tau_motor, axis=0)
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

    def _head(self, n: int) -> TaskMotion:
        cut = {k: getattr(self, k)[:n] for k in ("t", "X", "Xd", "Xdd", "q", "qd", "qdd", "tau",
                                                  "sigma_I", "sigma_II", "condition")}
        if self.tau_motor is not None:
            cut["tau_motor"] = self.tau_motor[:n]
        return replace(self, **cut)


def _sample_times(duration: float, n: int | None, dt: float | None) -> FloatArray:
    """``n`` sample times over [0, duration] (s), or as many as a spacing ``dt`` (s) gives."""
    if n is not None:
        return np.linspace(0.0, duration, count("n", n, 2, MAX_SAMPLES))
    step = DEFAULT_DT if dt is None else positive("dt", dt, "s")
    if duration / step >= MAX_SAMPLES:
        raise error("dt", f"dt = {step:g} s cuts the {duration:g} s motion into more than {MAX_SAMPLES} samples: "
                          "give a larger dt")
    return np.linspace(0.0, duration, max(int(np.ceil(duration / step)) + 1, 2))


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

    def motion(rows: dict[str, FloatArray]) -> TaskMotion:
        k = len(rows["sigma_I"])
        return TaskMotion(ee, path.label, t[:k].copy(), X[:k].copy(), Xd[:k].copy(), Xdd[:k].copy(), rows["q"],
                          rows["qd"], rows["qdd"], rows["tau"], rows["sigma_I"], rows["sigma_II"], rows["condition"],
                          tau_motor=rows["tau_motor"])

    try:
        rows = ee._core.motion(t, X, Xd, Xdd, q_start, singular_tol)
    except (AssemblyError, SingularityError) as exc:
        part = getattr(exc, "partial_rows", None)
        if part is not None:
            setattr(exc, "partial", motion(part))  # noqa: B010 - set on the native exception
        if hasattr(exc, "X"):
            setattr(exc, "X", np.asarray(getattr(exc, "X")))  # noqa: B010, B009
        raise
    return motion(rows)
