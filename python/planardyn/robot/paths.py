"""Prescribed end-effector motions X(t) with exact derivatives: point-to-point and lines with a
time profile, circles, and time tables (cubic splines).

A path gives, at times t (N,) in [0, duration] (s), the task coordinates X (N, k) and their
first and second time derivatives (m/s, m/s^2; rad/s, rad/s^2 for psi). k = 2 for a point
(the orientation psi, when given, is appended for m = 3 robots; a path without one keeps
psi = 0, the drawn orientation of the end-effector body).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import Literal

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ..arguments import array, choice, error, number, positive, times

FloatArray = NDArray[np.float64]
Profile = Literal["quintic", "trapezoid", "constant"]
Sampler = Callable[[FloatArray], tuple[FloatArray, FloatArray, FloatArray]]

# Trapezoidal velocity profile: the fraction of the duration spent accelerating (and again
# decelerating); 1/3 is the usual "thirds" move (accelerate, cruise, decelerate).
TRAPEZOID_ACCEL_FRACTION = 1.0 / 3.0


def time_law(kind: Profile, tau: FloatArray) -> tuple[FloatArray, FloatArray, FloatArray]:
    """Normalised time law s(tau), ds/dtau, d2s/dtau2 for tau in [0, 1], s from 0 to 1.

    ``'quintic'``: 10 tau^3 - 15 tau^4 + 6 tau^5, at rest (zero speed and acceleration) at both
    ends. ``'trapezoid'``: constant acceleration, cruise, constant deceleration (speed
    continuous, acceleration steps). ``'constant'``: s = tau (constant speed).
    """
    tau = np.clip(array("tau", tau, ndim=(0, 1), what="normalised times"), 0.0, 1.0)
    if kind == "quintic":
        s = tau**3 * (10 - 15 * tau + 6 * tau**2)
        sd = 30 * tau**2 * (1 - tau) ** 2
        sdd = 60 * tau * (1 - tau) * (1 - 2 * tau)
    elif kind == "trapezoid":
        a = TRAPEZOID_ACCEL_FRACTION
        v = 1.0 / (1.0 - a)  # cruise speed so that s(1) = 1
        acc = v / a
        up, down = tau < a, tau > 1 - a
        s = np.where(up, 0.5 * acc * tau**2, np.where(down, 1 - 0.5 * acc * (1 - tau) ** 2, v * (tau - a / 2)))
        sd = np.where(up, acc * tau, np.where(down, acc * (1 - tau), v))
        sdd = np.where(up, acc, np.where(down, -acc, 0.0))
    elif kind == "constant":
        s, sd, sdd = tau, np.ones_like(tau), np.zeros_like(tau)
    else:
        raise error("profile", f"profile must be 'quintic', 'trapezoid' or 'constant', got {kind!r}")
    return s, sd, sdd


@dataclass(frozen=True)
class TaskPath:
    """A prescribed end-effector motion over [0, duration] (s).

    ``sample(t)`` gives X, Xd, Xdd, each (N, k). ``label`` describes it in reports.
    """

    duration: float
    dim: int
    label: str
    _sample: Sampler

    def sample(self, t: ArrayLike) -> tuple[FloatArray, FloatArray, FloatArray]:
        """X, Xd, Xdd (N, k) at times t (N,) (s) within [0, duration]."""
        t = np.atleast_1d(array("t", t, ndim=(0, 1), what="times in s"))
        if np.any((t < 0.0) | (t > self.duration)):
            k = int(np.argmax((t < 0.0) | (t > self.duration)))
            raise error("t", f"t[{k}] = {t[k]!r} s is outside the path's [0, {self.duration:g}] s")
        out = self._sample(t)
        if not all(np.isfinite(a).all() for a in out):
            raise error("path", f"{self.label}: its speed or acceleration overflows (not finite): give a longer "
                                "duration or a smaller path")
        return out

    def with_dim(self, k: int) -> TaskPath:
        """The same path with k task coordinates: psi = 0 (drawn orientation) appended for
        k = 3 when it has none; k = 2 of a path with psi is an error."""
        if k == self.dim:
            return self
        if k == 3 and self.dim == 2:
            def sample3(t: FloatArray) -> tuple[FloatArray, FloatArray, FloatArray]:
                z = np.zeros((len(t), 1))
                return tuple(np.hstack([a, z]) for a in self._sample(t))  # type: ignore[return-value]

            return TaskPath(self.duration, 3, self.label, sample3)
        raise error("path", f"the path has {self.dim} task coordinates, the end effector {k}: give a path of {k}")


def _check_duration(duration: float) -> float:
    return positive("duration", duration, "s")


def _angles(angle: float | tuple[float, float] | None) -> tuple[float, float] | None:
    if angle is None:
        return None
    a = array("angle", angle, ndim=(0, 1), what="psi, or (psi0, psi1), rad")
    if a.size not in (1, 2):
        raise error("angle", f"angle must be psi or (psi0, psi1) (rad), got {a.size} values")
    a0, a1 = np.broadcast_to(a, (2,))
    return float(a0), float(a1)


def _with_angle(
    pos: tuple[FloatArray, FloatArray, FloatArray], angles: tuple[float, float] | None, s: tuple[FloatArray, ...]
) -> tuple[FloatArray, FloatArray, FloatArray]:
    if angles is None:
        return pos
    a0, a1 = angles
    d = a1 - a0
    cols = (a0 + d * s[0], d * s[1], d * s[2])
    X, Xd, Xdd = (np.column_stack([p, c]) for p, c in zip(pos, cols))
    return X, Xd, Xdd


def line(
    start: ArrayLike,
    end: ArrayLike,
    duration: float,
    profile: Profile = "quintic",
    angle: float | tuple[float, float] | None = None,
) -> TaskPath:
    """Straight line from ``start`` to ``end`` ((2,), m) in ``duration`` s with a time profile
    (``'quintic'`` and ``'trapezoid'`` are rest-to-rest: a point-to-point move).

    ``angle``: for a pose, psi (rad from the drawn orientation), constant or (psi0, psi1)
    interpolated with the same profile.
    """
    T = _check_duration(duration)
    choice("profile", profile, ("quintic", "trapezoid", "constant"))
    p0, p1 = (array(n, p, shape=(2,), what="a point (x, y), m") for n, p in (("start", start), ("end", end)))
    d = p1 - p0
    angles = _angles(angle)

    def sample(t: FloatArray) -> tuple[FloatArray, FloatArray, FloatArray]:
        s, sd, sdd = time_law(profile, t / T)
        law = (s, sd / T, sdd / T**2)
        pos = (p0 + np.outer(law[0], d), np.outer(law[1], d), np.outer(law[2], d))
        return _with_angle(pos, angles, law)

    return TaskPath(T, 2 if angles is None else 3, f"line {p0.round(4).tolist()} -> {p1.round(4).tolist()} in {T:g} s ({profile})", sample)


def point_to_point(
    start: ArrayLike,
    end: ArrayLike,
    duration: float,
    profile: Literal["quintic", "trapezoid"] = "quintic",
    angle: float | tuple[float, float] | None = None,
) -> TaskPath:
    """Rest-to-rest move along a straight line (see :func:`line`)."""
    if profile not in ("quintic", "trapezoid"):
        raise error("profile", f"a point-to-point move starts and ends at rest: use 'quintic' or 'trapezoid', "
                               f"got {profile!r}")
    return line(start, end, duration, profile, angle)


def circle(
    center: ArrayLike,
    radius: float,
    duration: float,
    start_angle: float = -np.pi / 2,
    turns: float = 1.0,
    profile: Profile = "quintic",
    angle: float | tuple[float, float] | None = None,
) -> TaskPath:
    """Circle of ``radius`` (m) about ``center`` ((2,), m), counter-clockwise for turns > 0,
    starting at polar angle ``start_angle`` (rad, default the lowest point); the polar angle
    follows the time profile (``'quintic'``: from rest to rest; ``'constant'``: uniform speed).
    """
    T = _check_duration(duration)
    choice("profile", profile, ("quintic", "trapezoid", "constant"))
    c = array("center", center, shape=(2,), what="a point (x, y), m")
    r = positive("radius", radius, "m")
    sweep = 2 * np.pi * number("turns", turns)
    start_angle = number("start_angle", start_angle, "rad")
    angles = _angles(angle)

    def sample(t: FloatArray) -> tuple[FloatArray, FloatArray, FloatArray]:
        s, sd, sdd = time_law(profile, t / T)
        law = (s, sd / T, sdd / T**2)
        th, thd, thdd = start_angle + sweep * law[0], sweep * law[1], sweep * law[2]
        e_r = np.column_stack([np.cos(th), np.sin(th)])
        e_t = np.column_stack([-np.sin(th), np.cos(th)])
        pos = (c + r * e_r, r * thd[:, None] * e_t, r * (thdd[:, None] * e_t - (thd**2)[:, None] * e_r))
        return _with_angle(pos, angles, law)

    return TaskPath(T, 2 if angles is None else 3, f"circle r = {r:g} m about {c.round(4).tolist()} in {T:g} s ({profile})", sample)


#: Relative mismatch between the derivative functions of :func:`from_functions` and central
#: differences of the position function (step 1e-4 of the duration: error ~1e-8 relative for
#: a smooth motion) beyond which they are refused as not each other's derivatives.
DERIVATIVE_CHECK_RTOL = 1e-4


def from_functions(
    X: Callable[[FloatArray], ArrayLike],
    Xd: Callable[[FloatArray], ArrayLike],
    Xdd: Callable[[FloatArray], ArrayLike],
    duration: float,
    label: str = "functions of time",
) -> TaskPath:
    """A path given as functions of time: the pose and its first two derivatives, exact.

    Each function takes t, an (N,) array of times in [0, duration] (s), and returns (N, k)
    (k = 2 for a point, 3 with psi in rad). This is the route for a motion known as a formula:
    no interpolation error, and the ends move as the formula says.

    The derivatives are checked against central differences of X at a few times inside
    (:data:`DERIVATIVE_CHECK_RTOL`), so a wrong sign or a forgotten chain-rule factor is an
    error here rather than wrong efforts later.
    """
    duration = _check_duration(duration)

    def sample(t: FloatArray) -> tuple[FloatArray, FloatArray, FloatArray]:
        out = tuple(np.asarray(f(t), dtype=float) for f in (X, Xd, Xdd))
        for name, a in zip(("X", "Xd", "Xdd"), out):
            if a.shape not in ((len(t), 2), (len(t), 3)):
                raise error(name, f"{name}(t) must return shape (N, 2) or (N, 3) for t of shape (N,); "
                                  f"got {a.shape} for N = {len(t)}")
            if not np.isfinite(a).all():
                raise error(name, f"{name}(t) returned a NaN or an infinity")
        return out  # type: ignore[return-value]

    t = duration * np.array([0.1, 0.37, 0.5, 0.73, 0.9])
    h = 1e-4 * duration
    (x0, v0, a0), (xp, vp, _), (xm, vm, _) = sample(t), sample(t + h), sample(t - h)
    for name, got, want in (("Xd", v0, (xp - xm) / (2 * h)), ("Xdd", a0, (vp - vm) / (2 * h))):
        scale = np.abs(want).max() + np.abs(x0).max() / duration ** (1 if name == "Xd" else 2)
        err = np.abs(got - want).max()
        if err > DERIVATIVE_CHECK_RTOL * scale:
            raise error(name, f"{name}(t) is not the time derivative of the path: at 0.1 to 0.9 of the duration it "
                              f"differs from a central difference (step {h:.3g} s, 1e-4 of the duration) by "
                              f"{err:.3g} (scale {scale:.3g}); check signs and chain-rule factors")
    return TaskPath(duration, x0.shape[1], label, sample)


#: The end conditions of :func:`table` (scipy's CubicSpline names).
BC_TYPES = ("not-a-knot", "clamped", "natural", "periodic")


def table(t: ArrayLike, X: ArrayLike, bc_type: str = "not-a-knot") -> TaskPath:
    """A time table of task coordinates, interpolated by a cubic spline in t.

    Parameters
    ----------
    t : (K,) array_like
        Times (s), increasing, from 0.
    X : (K, 2) or (K, 3) array_like
        Positions (m), with psi (rad) as a third column for a pose.
    bc_type : str
        scipy's CubicSpline end conditions. The default ``'not-a-knot'`` assumes nothing at
        the ends (the velocity and acceleration there follow from the table), so a motion
        that does not start or end at rest keeps its speed; ``'clamped'`` makes it start and
        end at rest (zero velocity), right only for a table that does.
    """
    from scipy.interpolate import CubicSpline

    t = times("t", t)
    X = array("X", X, ndim=2, what="positions (m), with psi (rad) as a third column for a pose")
    if X.shape[0] != t.shape[0] or X.shape[1] not in (2, 3):
        raise error("X", f"table needs X (K, 2 or 3) for t (K,) = ({len(t)},); got {X.shape}")
    if t[0] != 0.0:
        raise error("t", f"table times start at 0 s, got t[0] = {t[0]!r}")
    choice("bc_type", bc_type, BC_TYPES)
    if bc_type == "periodic" and not np.array_equal(X[0], X[-1]):
        raise error("bc_type", "bc_type = 'periodic' needs a table whose last row X[-1] is its first X[0]")
    with np.errstate(all="ignore"):  # the slopes and the spline's coefficients must be finite
        finite = bool(np.isfinite(np.diff(X, axis=0) / np.diff(t)[:, None]).all())
        spline = CubicSpline(t, X, bc_type=bc_type) if finite else None
    if spline is None or not all(np.isfinite(c).all() for c in (spline.c, spline(t[-1], 1), spline(t[-1], 2))):
        raise error("X", "X: the table's spline overflows (its positions too far apart, or its times too close, for "
                         "floating point): give positions in metres and times in seconds of a drawable motion")
    d1, d2 = spline.derivative(1), spline.derivative(2)

    def sample(tt: FloatArray) -> tuple[FloatArray, FloatArray, FloatArray]:
        return spline(tt), d1(tt), d2(tt)

    return TaskPath(float(t[-1]), X.shape[1], f"table of {len(t)} points over {t[-1]:g} s", sample)
