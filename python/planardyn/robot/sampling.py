"""How finely a task motion is sampled for sizing: the check that the samples resolve the
path, and the resampling around every sampled peak.

A sizing reads its peaks, RMS values and singularity margins from samples, so the samples
must show the path's shape. The check: the path between two samples is their cubic Hermite
interpolant (from X and Xd at both) to :data:`SAMPLING_TOL` of the path's extent, at the
midpoints (a path given as :class:`TaskPath`) or, for a motion already solved, at every
other sample from its neighbours. A sampling that fails (a circle sampled at its start and
end only looks like a point at rest) is refused with the spacing that would pass, as is one
on which Simpson's rule and the trapezoidal rule give RMS values more than RMS_TOL apart.

Where the samples resolve the path, a peak between two samples lies within a sample of a
sampled local maximum: :func:`peak_windows` picks the samples where a sized quantity comes
within :data:`PEAK_FRACTION` of its largest, and the sizing solves the motion again
:data:`FINE` times finer across the two intervals around each.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from .._core import ArgumentError
from .paths import TaskPath

FloatArray = NDArray[np.float64]

#: The largest error, relative to the path's extent (its largest range over the task
#: coordinates), of the cubic Hermite interpolant between samples: 0.01 %. Every peak between
#: samples then lies next to a sampled local maximum, and the core's continuation from one
#: sample to the next keeps its working mode (on the five-bar's circle of docs/robot.md it
#: loses it at 17 samples, an error of 4.8e-4, and keeps it from 21, 2.0e-4).
SAMPLING_TOL = 1e-4

#: The largest difference, relative to the RMS, between Simpson's and the trapezoidal rule's
#: RMS of a sized quantity (it bounds Simpson's error where both converge): 0.3 %, far below
#: what a motor's continuous rating is known to, and met at a few hundred samples by motions
#: whose motor torques carry Coulomb friction's steep tanh at a speed reversal.
RMS_TOL = 3e-3

#: Sampled local maxima within this fraction of a quantity's largest are resampled (a peak
#: between samples exceeds its samples by far less where the sampling passes the check).
PEAK_FRACTION = 0.9

#: The resampling around a peak: this many intervals across the two sample intervals around it
#: (the peak then within (2 dt / FINE)^2 of a sample's curvature term: 1e-6 relative at most).
FINE = 64


class SizingError(ArgumentError):
    """An argument a sizing cannot use, with what to give instead; ``argument`` names it."""

    def __init__(self, message: str, argument: str | None = None) -> None:
        super().__init__(message)
        self.argument = argument


class SamplingError(SizingError):
    """A sampling too coarse for the path (argument ``dt``); ``dt`` a spacing (s) that
    would pass."""

    def __init__(self, message: str, dt: float) -> None:
        super().__init__(message, "dt")
        self.dt = dt


def _hermite_mid(t0: FloatArray, t1: FloatArray, X0: FloatArray, X1: FloatArray, V0: FloatArray,
                 V1: FloatArray) -> FloatArray:
    """The cubic Hermite interpolant's value at the middle of [t0, t1]."""
    h = (t1 - t0)[:, None]
    return np.asarray((X0 + X1) / 2 + h * (V0 - V1) / 8)


def _relative_error(X: FloatArray, predicted: FloatArray, actual: FloatArray) -> float:
    extent = float(np.ptp(np.vstack([X, actual]), axis=0).max())
    err = float(np.abs(predicted - actual).max())
    return err / extent if extent > 0 else 0.0


def path_error(path: TaskPath, t: FloatArray) -> float:
    """The largest error of the samples' Hermite interpolant at the interval midpoints,
    relative to the path's extent."""
    X, Xd, _ = path.sample(t)
    mid = (t[:-1] + t[1:]) / 2
    return _relative_error(X, _hermite_mid(t[:-1], t[1:], X[:-1], X[1:], Xd[:-1], Xd[1:]), path.sample(mid)[0])


def samples_error(t: FloatArray, X: FloatArray, Xd: FloatArray) -> float:
    """The same from samples alone: every other sample predicted from its two neighbours."""
    return _relative_error(X, _hermite_mid(t[:-2:2], t[2::2], X[:-2:2], X[2::2], Xd[:-2:2], Xd[2::2]), X[1:-1:2])


def check_path(path: TaskPath, t: FloatArray) -> None:
    """Refuse samples t (N,) (s) of the path that do not resolve it (SamplingError)."""
    err = path_error(path, t)
    if err <= SAMPLING_TOL:
        return
    n = len(t)
    while path_error(path, np.linspace(0.0, path.duration, n)) > SAMPLING_TOL and n < 2**30:
        n = 2 * n - 1
    dt = path.duration / (n - 1)
    raise SamplingError(f"dt: {len(t)} samples {t[1] - t[0]:.3g} s apart do not resolve the path ({path.label}): "
                        f"between them it leaves their interpolant by {100 * err:.3g} % of its extent (at most "
                        f"{100 * SAMPLING_TOL:g} %); sample it every {dt:.3g} s or closer", dt)


def check_samples(t: FloatArray, X: FloatArray, Xd: FloatArray) -> None:
    """Refuse a solved motion whose samples do not resolve it (SamplingError)."""
    if len(t) < 3:
        raise SamplingError(f"dt: a motion of {len(t)} samples shows nothing between them; solve it with more "
                            "samples (dt= or n=)", float(t[-1] - t[0]) / 4)
    err = samples_error(t, X, Xd)
    if err > SAMPLING_TOL:
        dt = float(np.diff(t).max()) * (SAMPLING_TOL / err) ** 0.25 / 2
        raise SamplingError(f"dt: the motion's {len(t)} samples do not resolve it: a sample lies "
                            f"{100 * err:.3g} % of the path's extent off its neighbours' interpolant (at most "
                            f"{100 * SAMPLING_TOL:g} %); solve it with samples every {dt:.3g} s or closer", dt)


def check_rms(t: FloatArray, values: FloatArray) -> None:
    """Refuse samples too coarse for the RMS of the quantities (N, K): Simpson's rule and the
    trapezoidal rule on them differ by more than RMS_TOL of the RMS."""
    from scipy.integrate import simpson, trapezoid

    if len(t) < 3:
        return
    y2 = values**2
    s, tr = simpson(y2, x=t, axis=0), trapezoid(y2, x=t, axis=0)
    with np.errstate(divide="ignore", invalid="ignore"):
        err = np.where(s > 0, np.abs(np.sqrt(np.maximum(s, 0)) - np.sqrt(tr)) / np.sqrt(np.maximum(s, 0)), 0.0)
    worst = float(np.max(err))
    if worst > RMS_TOL:
        dt = float(np.diff(t).max()) * np.sqrt(RMS_TOL / worst) / 2
        raise SamplingError(f"dt: samples {float(np.diff(t).max()):.3g} s apart do not resolve the RMS values: Simpson's "
                            f"and the trapezoidal rule differ by {100 * worst:.3g} % (at most {100 * RMS_TOL:g} %); "
                            f"sample every {dt:.3g} s or closer", dt)


def peak_windows(values: list[FloatArray]) -> list[int]:
    """The samples (indices) next to which a peak may lie: the local maxima of each
    quantity (N,) within PEAK_FRACTION of its largest."""
    keep: set[int] = set()
    for y in values:
        top = float(np.max(y))
        if not np.isfinite(top) or top <= 0:
            continue
        left = np.concatenate([[-np.inf], y[:-1]])
        right = np.concatenate([y[1:], [-np.inf]])
        keep.update(np.flatnonzero((y >= left) & (y >= right) & (y >= PEAK_FRACTION * top)).tolist())
    return sorted(keep)
