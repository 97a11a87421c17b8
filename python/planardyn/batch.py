"""Batch runs: many variants of a mechanism simulated in one call.

A *variant* is a model (a :class:`~planardyn.Mechanism` or a model dict) and, optionally, a
dict of settings that override the call's (``q0``, ``qd0``, ``t_end``, ...). Parameter
sweeps and Monte Carlo samples are model edits made by :func:`sweep` and
:func:`monte_carlo`; a grid of start states is a list of ``(mech, {"q0": q})`` pairs.

By default the whole list goes to Rust in one call and runs on a pool of native threads
with the GIL released (all cores, or ``threads``). Given an ``executor`` (a
``dask.distributed.Client`` or any ``concurrent.futures.Executor``), the list is cut into
chunks and each chunk runs that same native batch on a worker. Either way the results come
back in input order and equal, bit for bit, those of a loop of ``mech.simulate``. A variant
that fails (a start that cannot be assembled, invalid settings, a model dict that is not a
mechanism) gives a :class:`BatchError` in its place; the others are not affected.

:func:`inverse_dynamics` does the same for the drive efforts of a motion: a motion in the
coordinates (``q``, ``qd``, ``qdd`` rows), or an end-effector path solved for the inputs on
each variant first (as :func:`planardyn.robot.solve_motion`, but in Rust), e.g. many
designs of a robot on one task or many tasks of one robot.
"""

from __future__ import annotations

import copy
import math
from collections.abc import Callable, Iterable, Mapping, Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ._core import inverse_batch, simulate_batch
from .arguments import count, error
from .mechanism import Mechanism, from_dict, native_motion
from .result import SimulationResult
from .settings import MAX_THREADS, check_settings

if TYPE_CHECKING:
    from .robot import TaskMotion, TaskPath

__all__ = ["BatchError", "BatchInterrupted", "inverse_dynamics", "monte_carlo", "simulate", "sweep"]

#: A variant: a model, or a model with its own settings.
VariantLike = Mechanism | Mapping[str, Any] | tuple[Mechanism | Mapping[str, Any], Mapping[str, Any]]
#: ``edit(model_dict, value) -> model_dict`` or a dotted path into the model dict.
Edit = str | Callable[[dict[str, Any], Any], dict[str, Any]]

_SETTINGS = ("t_end", "method", "rtol", "atol", "dt", "t_eval", "output_dt", "q0", "qd0", "max_steps")
_ARRAYS = ("t_eval", "q0", "qd0")
_MOTION = ("path", "q", "qd", "qdd", "point", "body", "n", "dt", "q_start", "singular_tol")


@dataclass(frozen=True)
class BatchError:
    """The place of a variant that failed, and why.

    ``type`` is the name of the exception ``Mechanism.simulate`` (or building the model)
    would have raised: ``'AssemblyError'``, ``'SimulationError'``, ``'ModelError'``...
    """

    #: Position of the variant in the list given.
    index: int
    type: str
    message: str
    #: Always False, so that ``[r for r in results if r.success]`` works on a mixed list.
    success: bool = False

    def __str__(self) -> str:
        return f"variant {self.index}: {self.type}: {self.message}"


class BatchInterrupted(KeyboardInterrupt):
    """Ctrl-C during a batch: still a KeyboardInterrupt (loops stop), carrying ``results``,
    one per variant as the call would return them: the finished ones, runs stopped on the
    way (status ``'cancelled'``) and a :class:`BatchError` of type ``'Cancelled'`` for the
    variants not run."""

    def __init__(self, results: list[Any]) -> None:
        done = sum(1 for r in results if not isinstance(r, BatchError) or r.type != "Cancelled")
        super().__init__(f"batch interrupted (Ctrl-C): {done} of {len(results)} variants kept")
        self.results = results


def _settings(common: Mapping[str, Any], own: Mapping[str, Any], mech: Mechanism) -> dict[str, Any]:
    """The settings of one variant, arrays as lists of floats (exact for float64); its
    motions by coordinate index for the native call (``motion``) and by name for the
    result's metadata (``_motion``)."""
    unknown = set(own) - set(_SETTINGS) - {"motion"}
    if unknown:
        raise error("settings", f"unknown simulation settings {sorted(unknown)}; expected some of "
                                f"{', '.join(_SETTINGS)}, motion")
    given = {k: v for k, v in {**common, **own}.items() if v is not None}
    motion = given.pop("motion", None)
    out = check_settings(**given)
    if motion is not None:
        if any(callable(m) for m in dict(motion).values()):
            raise TypeError("a batch's motions are speeds or tables {'t': ..., 'q': ...}; "
                            "a motion function runs only in Mechanism.simulate")
        out["motion"] = native_motion(motion, mech.coordinate_names)
        out["_motion"] = {k: v if np.isscalar(v) else {c: np.asarray(a, float).tolist() for c, a in v.items()}
                          for k, v in motion.items()}
    for k in _ARRAYS:
        if k in out:
            out[k] = np.asarray(out[k], dtype=np.float64).ravel().tolist()
    if "t_end" in out:
        out["t_end"] = float(out["t_end"])
    return out


def _run_chunk(kind: str, items: list[tuple[Mechanism, dict[str, Any]]], threads: int | None,
               finish: Callable[[Any, Mechanism, dict[str, Any]], Any] | None = None) -> list[Any]:
    """One native batch (``kind`` 'simulate' or 'inverse'): a picklable call that runs on a
    worker (or here). Given ``finish``, the native threads apply it to each raw result as they
    finish it (the calling thread only collects them; a failed variant's pair (type, message)
    is kept); else the raw results come back."""
    native = simulate_batch if kind == "simulate" else inverse_batch
    # Keys with a leading underscore stay in Python (the path's label, for the result).
    variants = [(m._native, {k: v for k, v in s.items() if not k.startswith("_")}) for m, s in items]
    if finish is None:
        return native(variants, threads)
    return native(variants, threads, lambda k, raw: raw if isinstance(raw, tuple) else finish(raw, *items[k]))


def _is_dask(executor: Any) -> bool:
    return type(executor).__module__.split(".")[0] == "distributed"


def _prepare(variants: Sequence[VariantLike], own_args: Callable[[Mechanism, Mapping[str, Any]], dict[str, Any]],
             ) -> tuple[list[Any], list[int], list[tuple[Mechanism, dict[str, Any]]]]:
    """Build every variant's model and native arguments; a failure is a BatchError in its place."""
    out: list[Any] = [None] * len(variants)
    todo: list[int] = []
    items: list[tuple[Mechanism, dict[str, Any]]] = []
    for i, v in enumerate(variants):
        model, own = (v if isinstance(v, tuple) else (v, {}))
        try:
            mech = model if isinstance(model, Mechanism) else from_dict(model)
            items.append((mech, own_args(mech, own)))
            todo.append(i)
        except Exception as e:  # noqa: BLE001 - reported in the variant's place
            out[i] = BatchError(i, type(e).__name__, str(e))
    return out, todo, items


def _run(kind: str, variants: Sequence[VariantLike], own_args: Callable[[Mechanism, Mapping[str, Any]], dict[str, Any]],
         finish: Callable[[Any, Mechanism, dict[str, Any]], Any], threads: int | None, executor: Any,
         chunk_size: int | None, progress: Callable[[int, int], Any] | None) -> list[Any]:
    """Cut the prepared variants into chunks, run them here or on the executor, and put each
    raw result (``finish``-ed) or BatchError in its variant's place."""
    if threads is not None:
        threads = count("threads", threads, 1, MAX_THREADS)
    out, todo, items = _prepare(variants, own_args)
    n = len(items)
    if chunk_size is None:
        parts = 16 if executor is not None else (20 if progress is not None else 1)
        chunk_size = max(1, math.ceil(n / parts))
    if chunk_size < 1:
        raise error("chunk_size", f"chunk_size = {chunk_size} must be at least 1")
    starts = range(0, n, chunk_size)
    futures: list[Any] = []
    if executor is None:
        pending = [lambda s=s: _run_chunk(kind, items[s:s + chunk_size], threads, finish) for s in starts]
    else:
        kw = {"pure": False} if _is_dask(executor) else {}
        futures = [executor.submit(_run_chunk, kind, items[s:s + chunk_size], threads, **kw) for s in starts]
        pending = [f.result for f in futures]
    done, stopped = 0, None
    interrupted: KeyboardInterrupt | None = None
    for s, get in zip(starts, pending):
        chunk = items[s:s + chunk_size]
        if stopped is not None:
            for k in range(len(chunk)):
                out[todo[s + k]] = BatchError(todo[s + k], "Cancelled", stopped)
            continue
        try:
            raws = get()
        except KeyboardInterrupt as e:  # the native batch hands back what it has
            interrupted, stopped = e, "not run: interrupted (Ctrl-C)"
            raws = getattr(e, "partial", None) or [("Cancelled", stopped)] * len(chunk)
        except Exception as e:  # noqa: BLE001 - a lost chunk loses only its own variants
            raws = [(type(e).__name__, f"the chunk with this variant failed: {e}")] * len(chunk)
        for k, ((mech, args), raw) in enumerate(zip(chunk, raws)):
            i = todo[s + k]
            if isinstance(raw, tuple):
                out[i] = BatchError(i, *raw)
            else:  # finished here by the native threads, or come back raw from the executor
                out[i] = raw if executor is None else finish(raw, mech, args)
        done += len(chunk)
        if progress is not None and stopped is None:
            stopped = _progress_stop(progress, done, n)
    if stopped is not None:
        for f in futures:
            f.cancel()
    if interrupted is not None:
        raise BatchInterrupted(out) from interrupted
    return out


def _progress_stop(progress: Callable[[int, int], Any], done: int, n: int) -> str | None:
    """Why the batch stops after ``progress(done, n)`` (it returned False, or raised), else None.

    The variants finished are kept; the rest become BatchErrors of type 'Cancelled'."""
    try:
        r = progress(done, n)
    except Exception as e:  # noqa: BLE001 - the results so far are the caller's
        return f"not run: the progress callback raised {e!r} after {done} of {n} variants"
    if r is not None and not r:
        return f"not run: the progress callback returned {r!r} after {done} of {n} variants"
    return None


def simulate(
    variants: Sequence[VariantLike],
    t_end: float | None = None,
    *,
    method: str | None = None,
    rtol: float | None = None,
    atol: float | None = None,
    dt: float | None = None,
    t_eval: ArrayLike | None = None,
    output_dt: float | None = None,
    max_steps: int | None = None,
    motion: Mapping[str, float | Mapping[str, ArrayLike]] | None = None,
    threads: int | None = None,
    executor: Any = None,
    chunk_size: int | None = None,
    progress: Callable[[int, int], Any] | None = None,
) -> list[SimulationResult | BatchError]:
    """Simulate every variant with its model's drives; results in input order.

    Parameters
    ----------
    variants : sequence
        Each a :class:`Mechanism`, a model dict (as :meth:`Mechanism.to_dict` gives), or a
        pair ``(model, settings)`` whose dict overrides the call's settings for that variant
        (keys as the arguments of :meth:`Mechanism.simulate` without callables: ``q0``,
        ``qd0`` (m,) in rad or m and rad/s or m/s, ``t_end``, ``method``...).
    t_end, method, rtol, atol, dt, t_eval, output_dt, max_steps
        As for :meth:`Mechanism.simulate` (None: the model file's value).
    motion : dict, optional
        Coordinates driven by motion, as for :meth:`Mechanism.simulate`: a speed or a table
        ``{"t": ..., "q": ...}`` by coordinate name (not a function: the batch runs without
        Python). A variant's own ``motion`` replaces it.
    threads : int, optional
        Native threads per batch (here, or on each worker), 1 to
        :data:`planardyn.settings.MAX_THREADS` (256); default one per core. Another value is
        a TypeError or ValueError for the call, not for each variant.
    executor : dask.distributed.Client or concurrent.futures.Executor, optional
        Spread chunks of the list over it; default: run here.
    chunk_size : int, optional
        Variants per chunk. Default with an executor: the list in about 16 chunks; without,
        one chunk (or about 20 when ``progress`` is given).
    progress : callable ``progress(done, total)``, optional
        Called after each chunk with the number of variants finished. Returning False (not
        None) or raising stops the batch: the variants finished are kept, the others are
        BatchErrors of type ``'Cancelled'`` whose message says why.

    Returns
    -------
    list of SimulationResult or BatchError
        One entry per variant. A run that stopped early (check ``success``/``status``) is a
        result, as from :meth:`Mechanism.simulate`; a run that could not start, or a model
        that could not be built, is a :class:`BatchError`.
    """
    common: dict[str, Any] = dict(t_end=t_end, method=method, rtol=rtol, atol=atol, dt=dt,
                                  t_eval=t_eval, output_dt=output_dt, max_steps=max_steps)
    check_settings(**common)
    common["motion"] = motion
    return _run("simulate", variants, lambda mech, own: _settings(common, own, mech), _result,
                threads, executor, chunk_size, progress)


def _result(raw: dict[str, Any], mech: Mechanism, settings: dict[str, Any]) -> SimulationResult:
    # The metadata's settings rerun the variant: mech.simulate(**settings), motions by name.
    rerun = {k: v for k, v in settings.items() if k not in ("motion", "_motion")}
    if "_motion" in settings:
        rerun["motion"] = settings["_motion"]
    return mech._result(raw, rerun)


def inverse_dynamics(
    variants: Sequence[VariantLike],
    path: TaskPath | None = None,
    *,
    q: ArrayLike | None = None,
    qd: ArrayLike | None = None,
    qdd: ArrayLike | None = None,
    point: str = "P",
    body: str | None = None,
    n: int | None = None,
    dt: float | None = None,
    q_start: ArrayLike | None = None,
    singular_tol: float | None = None,
    threads: int | None = None,
    executor: Any = None,
    chunk_size: int | None = None,
    progress: Callable[[int, int], Any] | None = None,
) -> list[TaskMotion | NDArray[np.float64] | BatchError]:
    """Drive efforts of a motion for every variant; results in input order.

    Parameters
    ----------
    variants : sequence
        As for :func:`simulate`; a pair's dict overrides this call's motion arguments for
        that variant (keys ``path``, ``q``, ``qd``, ``qdd``, ``point``, ``body``, ``n``,
        ``dt``, ``q_start``, ``singular_tol``).
    path : planardyn.robot.TaskPath, optional
        An end-effector motion: on each variant it is sampled (``n`` samples or spacing
        ``dt`` s, default 1 ms), solved for the inputs from ``q_start`` (rad or m; default
        the drawing) on that working mode, then for the efforts, as
        :func:`planardyn.robot.solve_motion` does.
    q, qd, qdd : (N, m) array_like, optional
        Instead of a path, a motion in the coordinates (rad or m, per s, per s^2); the
        efforts as :meth:`Mechanism.inverse_dynamics` gives them, bit for bit.
    point, body : str
        The end-effector point (and its body, for a pose of an m = 3 robot).
    singular_tol : float
        Refuse a path where sigma_I or sigma_II falls below this (dimensionless; default
        :data:`planardyn.robot.SINGULAR_TOL`).
    threads, executor, chunk_size, progress
        As for :func:`simulate`.

    Returns
    -------
    list of TaskMotion, ndarray or BatchError
        Per variant: a :class:`~planardyn.robot.TaskMotion` for a path (its ``tau``, ``q``,
        ``sigma_I``...), the (N, m) efforts (N m or N) for coordinate rows, or a
        :class:`BatchError`: ``SingularityError`` where the path meets a singularity of that
        design, ``AssemblyError`` where it leaves its reach, ``ModelError``...
    """
    common = dict(path=path, q=q, qd=qd, qdd=qdd, point=point, body=body, n=n, dt=dt, q_start=q_start,
                  singular_tol=singular_tol)
    return _run("inverse", variants, lambda mech, own: _motion(mech, common, own), _efforts,
                threads, executor, chunk_size, progress)


def _motion(mech: Mechanism, common: Mapping[str, Any], own: Mapping[str, Any]) -> dict[str, Any]:
    """The native motion dict of one variant: coordinate rows, or the path sampled."""
    from .robot.motion import _sample_times
    from .robot.tolerances import SINGULAR_TOL

    unknown = set(own) - set(_MOTION)
    if unknown:
        raise error("motion", f"unknown motion arguments {sorted(unknown)}; expected some of {', '.join(_MOTION)}")
    a = {k: v for k, v in {**common, **own}.items() if v is not None}
    flat = lambda x: np.asarray(x, dtype=np.float64).ravel().tolist()  # noqa: E731 - exact for float64
    if "path" not in a:
        if not {"q", "qd", "qdd"} <= set(a):
            raise error("path", "inverse_dynamics needs a path, or q, qd and qdd (N, m) rows")
        return {k: flat(a[k]) for k in ("q", "qd", "qdd")}
    path = a["path"].with_dim(mech.dof)
    t = _sample_times(path.duration, a.get("n"), a.get("dt"))
    X, Xd, Xdd = path.sample(t)
    motion = {"t": t.tolist(), "X": flat(X), "Xd": flat(Xd), "Xdd": flat(Xdd), "point": a["point"],
              "body": a.get("body"), "singular_tol": float(a.get("singular_tol", SINGULAR_TOL)),
              "_label": path.label}
    if "q_start" in a:
        motion["q_start"] = flat(a["q_start"])
    return motion


def _efforts(raw: dict[str, Any], mech: Mechanism, motion: dict[str, Any]) -> TaskMotion | NDArray[np.float64]:
    if "t" not in motion:
        return raw["tau"]
    from .robot import EndEffector, TaskMotion

    ee = EndEffector(mech, motion["point"], motion["body"])
    k = mech.dof
    X, Xd, Xdd = (np.asarray(motion[key]).reshape(-1, k) for key in ("X", "Xd", "Xdd"))
    return TaskMotion(ee, motion["_label"], np.asarray(motion["t"]), X, Xd, Xdd, raw["q"], raw["qd"], raw["qdd"],
                      raw["tau"], raw["sigma_I"], raw["sigma_II"], raw["condition"], tau_motor=raw["tau_motor"])


# ---------------------------------------------------------------------- making variants


def _set(model: dict[str, Any], path: str, value: Any) -> dict[str, Any]:
    """Set a dotted path (``bodies.crank.mass``, ``points.A.0``, ``coordinates.theta1.q0``)
    in a copy of the model dict. A list is indexed by number or by its items' ``name``."""
    model = copy.deepcopy(model)
    *head, last = path.split(".")
    node: Any = model
    for key in [*head, last]:
        parent, node = node, _child(node, key, path)
    if isinstance(parent, list):
        parent[_index(parent, last, path)] = _plain(value)
    else:
        parent[last] = _plain(value)
    return model


def _index(node: list[Any], key: str, path: str) -> int:
    if key.lstrip("-").isdigit():
        return int(key)
    for k, item in enumerate(node):
        if isinstance(item, Mapping) and item.get("name") == key:
            return k
    raise KeyError(f"{path}: no item named {key!r}")


def _child(node: Any, key: str, path: str) -> Any:
    if isinstance(node, list):
        return node[_index(node, key, path)]
    if isinstance(node, Mapping):
        # A missing leaf (an optional field such as q0) is created by _set.
        return node.get(key)
    raise KeyError(f"{path}: {key!r} is inside a value, not a mapping or list")


def _plain(value: Any) -> Any:
    if isinstance(value, (np.ndarray, np.generic)):
        return value.tolist()
    return value


def _edited(base: Mechanism | Mapping[str, Any], edit: Edit, value: Any) -> dict[str, Any]:
    model = base.to_dict() if isinstance(base, Mechanism) else copy.deepcopy(dict(base))
    return _set(model, edit, value) if isinstance(edit, str) else edit(model, value)


def sweep(base: Mechanism | Mapping[str, Any], edit: Edit, values: Iterable[Any], *,
          build: bool = True) -> list[Mechanism] | list[dict[str, Any]]:
    """Variants of a model, one per value.

    Parameters
    ----------
    base : Mechanism or model dict
    edit : str or callable
        A dotted path into the model dict, e.g. ``"bodies.crank.mass"`` (kg) or
        ``"points.B.0"`` (m), lists indexed by number or item name
        (``"coordinates.theta1.q0"``); or ``edit(model_dict, value) -> model_dict``, given
        a fresh copy it may change.
    values : sequence
        The values (in the units of the field).
    build : bool
        True: validated Mechanisms (a value that makes no mechanism raises ``ModelError``).
        False: the model dicts, which :func:`simulate` builds and reports on one by one.
    """
    models = [_edited(base, edit, v) for v in values]
    return [from_dict(m) for m in models] if build else models


def monte_carlo(base: Mechanism | Mapping[str, Any],
                distributions: Mapping[str, tuple[float, float] | Callable[[np.random.Generator, int], ArrayLike]],
                n: int, seed: int | None = None, *, build: bool = True,
                ) -> tuple[list[Mechanism] | list[dict[str, Any]], dict[str, NDArray[np.float64]]]:
    """n random variants of a model and the values drawn.

    Parameters
    ----------
    distributions : mapping
        For each dotted path (as in :func:`sweep`), ``(low, high)`` for a uniform draw, or
        ``f(rng, n) -> (n,)`` values (e.g. ``lambda rng, n: rng.normal(1.2, 0.05, n)``).
        Paths are drawn in the order given, each all n values at once, from
        ``numpy.random.default_rng(seed)``: the same seed gives the same variants.
    n : int
        Number of variants.
    build : bool
        As for :func:`sweep`.

    Returns
    -------
    (variants, values)
        The n variants, and for each path the (n,) values used.
    """
    rng = np.random.default_rng(seed)
    values: dict[str, NDArray[np.float64]] = {}
    for path, dist in distributions.items():
        drawn = rng.uniform(dist[0], dist[1], n) if isinstance(dist, tuple) else dist(rng, n)
        values[path] = np.asarray(drawn, dtype=np.float64).reshape(n)
    model = base.to_dict() if isinstance(base, Mechanism) else dict(base)
    models = []
    for k in range(n):
        m = model
        for path, vals in values.items():
            m = _set(m, path, float(vals[k]))
        models.append(m)
    return ([from_dict(m) for m in models] if build else models), values
