"""The rules the public functions check their arguments by, one per kind of parameter.

A value that breaks its rule raises :class:`~planardyn.ArgumentError` (a ``PlanardynError``
and a ``ValueError``) whose message names the argument, says what it is and what it must be,
and whose attribute ``argument`` is its name; something that is not a number or an array of
numbers at all raises ``TypeError``. NaN, infinities, zero and negative values are refused
before they reach a computation, where they would come out as NaN results or a library's
error (``ZeroDivisionError``, LAPACK's "SVD did not converge", scipy's ``padlen``).

The rules are few on purpose: every time or frequency is :func:`positive`, every limit
:func:`positive` or None, every count :func:`count`, every array :func:`array`.
"""

from __future__ import annotations

import math
import operator
from collections.abc import Sequence
from typing import Any

import numpy as np
from numpy.typing import NDArray

from ._core import ArgumentError, DataError

FloatArray = NDArray[np.float64]


def error(name: str | None, message: str) -> ArgumentError:
    """An ``ArgumentError`` with ``message`` for argument ``name`` (its attribute ``argument``)."""
    e = ArgumentError(message)
    e.argument = name
    return e


def data_error(path: Any, message: str) -> DataError:
    """A ``DataError`` with ``message``, prefixed by the file's name ``path`` (None: data
    given as arrays), its attribute ``path``."""
    e = DataError(message if path is None else f"{path}: {message}")
    e.path = None if path is None else str(path)
    return e


def _float(name: str, value: Any) -> float:
    """``value`` as a float (NaN for one too large for a float), TypeError for a non-number."""
    if isinstance(value, bool) or isinstance(value, (str, bytes)) or not (
        isinstance(value, (int, float)) or hasattr(value, "__float__")
    ):
        raise TypeError(f"{name} = {value!r} must be a number, not {type(value).__name__}")
    try:
        return float(value)
    except OverflowError:  # an int beyond the float range
        return math.inf
    except (TypeError, ValueError):
        raise TypeError(f"{name} = {value!r} must be a number, not {type(value).__name__}") from None


def number(name: str, value: Any, unit: str = "") -> float:
    """A finite number (any sign)."""
    x = _float(name, value)
    if not math.isfinite(x):
        raise error(name, f"{name} = {value!r} must be a finite number{_unit(unit)}")
    return x


def positive(name: str, value: Any, unit: str = "") -> float:
    """A finite number > 0 (a time, a frequency, a length, a limit)."""
    x = _float(name, value)
    if not (math.isfinite(x) and x > 0.0):
        raise error(name, f"{name} = {value!r} must be a finite number > 0{_unit(unit)}")
    return x


def count(name: str, value: Any, low: int = 1, high: int = 10**9) -> int:
    """An integer from ``low`` to ``high`` (a number of samples, harmonics, evaluations)."""
    if isinstance(value, bool):
        raise TypeError(f"{name} = {value!r} must be an integer, not bool")
    try:
        n = operator.index(value)
    except TypeError:
        raise TypeError(f"{name} = {value!r} must be an integer, not {type(value).__name__}") from None
    if not low <= n <= high:
        raise error(name, f"{name} = {n} must be an integer from {low} to {high}")
    return n


def index(name: str, value: Any, n: int, what: str) -> int:
    """An index into ``n`` things (``what`` names them), from 0 to n - 1."""
    if n == 0:
        raise error(name, f"{name} = {value!r}: there are no {what}")
    return count(name, value, 0, n - 1)


def choice(name: str, value: Any, choices: Sequence[str]) -> str:
    """One of ``choices``."""
    if value not in choices:
        raise error(name, f"{name} = {value!r} must be one of {', '.join(repr(c) for c in choices)}")
    return str(value)


def array(name: str, value: Any, ndim: int | tuple[int, ...] | None = None,
          shape: tuple[int | None, ...] | None = None, what: str = "",
          columns: Sequence[str] | None = None) -> FloatArray:
    """A float64 array of finite values, of ``ndim`` dimensions (or one of them) and of
    ``shape`` (None: any length on that axis). A NaN or an infinity is located by its index,
    and in a 2-D array by its row and its column's name from ``columns``."""
    try:
        a = np.asarray(value, dtype=np.float64)
    except (TypeError, ValueError):
        raise TypeError(f"{name} must be an array of numbers{_unit(what)}, "
                        f"got {type(value).__name__}") from None
    dims = (ndim,) if isinstance(ndim, int) else ndim
    wrong = (dims is not None and a.ndim not in dims) or (shape is not None and (
        a.ndim != len(shape) or any(s is not None and s != k for s, k in zip(shape, a.shape))))
    if wrong:
        want = (", ".join("N" if s is None else str(s) for s in shape) + ("," if len(shape) == 1 else "")
                if shape is not None else " or ".join(f"{d}-D" for d in (dims or ())))
        raise error(name, f"{name} must have shape ({want}){_unit(what)}, got shape {a.shape}")
    bad = np.argwhere(~np.isfinite(a))
    if len(bad):
        at = tuple(int(i) for i in bad[0])
        where = f"{name}[{', '.join(map(str, at))}]" if at else name
        fix = ""
        if columns is not None and a.ndim == 2 and at[1] < len(columns):
            where += f" (row {at[0]}, column {columns[at[1]]!r})"
            fix = ": remove the row or give its value"
        raise error(name, f"{where} = {a[tuple(bad[0])]} is not a finite number{fix}")
    return a


def times(name: str, value: Any, least: int = 2, why: str = "") -> FloatArray:
    """Sample times (s): a 1-D array of at least ``least`` finite values (``why`` says why
    that many), strictly increasing."""
    t = array(name, value, ndim=1, what="times in s")
    if len(t) < least:
        raise error(name, f"{name} has {len(t)} times: give at least {least}{_unit(why)}")
    steps = np.diff(t)
    if np.any(steps <= 0):
        k = int(np.argmax(steps <= 0))
        raise error(name, f"{name} must increase strictly: {name}[{k + 1}] = {t[k + 1]!r} does not come after "
                          f"{name}[{k}] = {t[k]!r}")
    return t


def samples(name: str, value: Any, n: int, m: int | None = None, what: str = "",
            columns: Sequence[str] | None = None) -> FloatArray:
    """Rows of a motion: (n, m) finite values (m None: any number of columns), or (n,) for
    one column; ``columns`` names them in messages."""
    a = array(name, value, ndim=(1, 2), what=what, columns=columns)
    if a.ndim == 1 and m in (1, None):
        a = a[:, None]
    if a.shape[0] != n or (m is not None and a.shape[1] != m):
        raise error(name, f"{name} must have shape ({n}, {'m' if m is None else m}) (a row per time, a column "
                          f"per coordinate), got shape {a.shape}")
    return a


def finite_rates(q: FloatArray, t: FloatArray, *rates: FloatArray) -> None:
    """Refuse a sampled motion q(t) (N, m) whose slopes between samples, or ``rates``
    differentiated from it, overflow, naming q and t: samples too large or too close for
    floating point (before a spline is fitted, which would raise its own error)."""
    with np.errstate(all="ignore"):
        slopes = np.diff(q, axis=0) / np.diff(t).reshape((-1,) + (1,) * (q.ndim - 1))
    if not all(np.isfinite(r).all() for r in (slopes, *rates)):
        raise rates_overflow(q, t)


def rates_overflow(q: FloatArray, t: FloatArray) -> ArgumentError:
    """The error of a sampled motion q(t) whose rates overflow (a spline's refusal too)."""
    return error("q", f"the rates of q (largest |q| {np.abs(q).max():.3g}) over t (steps from "
                      f"{np.diff(t).min():.3g} s, times to {np.abs(t).max():.3g} s) overflow: give q and t in SI "
                      "units of a physical size")


def limits(name: str, value: Any, m: int, unit: str = "") -> FloatArray | None:
    """A limit given as one number or one per drive (m), as an (m,) array of finite values
    > 0; None stays None."""
    if value is None:
        return None
    a = np.asarray(array(name, value, ndim=(0, 1), what=unit))
    if a.ndim == 1 and a.shape != (m,):
        raise error(name, f"{name} must be one number or {m} (one per drive){_unit(unit)}, got {a.size}")
    out = np.broadcast_to(a, (m,)).copy()
    if not np.all(out > 0):
        k = int(np.argmin(out > 0))
        raise error(name, f"{name}[{k}] = {out[k]} must be > 0{_unit(unit)}: give a positive limit, or None for none")
    return out


def _unit(unit: str) -> str:
    return f" ({unit})" if unit else ""
