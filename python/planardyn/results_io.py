"""Results files (CSV, Parquet, NPZ) and motion tables for inverse dynamics.

A results file holds every array of a :class:`~planardyn.SimulationResult` and, as JSON
metadata, what is needed to reproduce and re-plot it: the model (``Mechanism.to_dict()``),
the solver settings (keyword arguments of ``Mechanism.simulate``), the planardyn version,
the status and counters. The format is chosen by the file name's extension:

``.csv``
    A plain table that a spreadsheet opens: a header row and one row per output time; numbers
    are written with ``repr`` (the shortest string that reads back to the same double, at most
    17 significant digits), so they round-trip exactly. The metadata, as JSON, are in a file
    beside it named after it: ``run.csv.json`` (keep the two together; files written before
    it, with the metadata on leading ``# `` lines of the CSV, are read too).
``.parquet``
    One column per channel (pyarrow), the metadata under the file-level key ``planardyn``.
``.npz``
    One array per quantity (``t``, ``q``, ``x``, ...), the metadata as a 0-d string array
    ``metadata`` (read with ``allow_pickle=False``).

A file is written whole or not at all (a temporary file renamed over the target). Its
metadata records ``rows`` (the number of output times) and ``checksum`` (CRC-32 of the
numbers): a truncated or changed file is refused on reading, with its name and what is
wrong. Whether the run itself completed is its ``status`` (``'success'``, ``'cancelled'``
for an interrupted run written as far as it got, ...).

The table's columns follow :data:`planardyn.results_format.COLUMNS`, listed below: a column of
a result per coordinate has one per coordinate (``<name>`` for q, ``qd_<name>``, ...), a pose
per body has three (``X_<body>``, ``Y_<body>``, ``phi_<body>`` for x, ``Xd_<body>``, ... for
xd), a flag is 0/1; the motor torques only for a model with actuators. Readers split the table
by position (the layout is in the metadata), so a coordinate may be named like another column.

"""

from __future__ import annotations

import os
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ._core import SingularityError
from .arguments import data_error, finite_rates, rates_overflow, samples, times
from .mechanism import Mechanism, attach_metadata
from .result import SimulationResult, column_fields
from .results_format import FORMAT, columns_doc
from .results_read import Damaged, csv_blocks, csv_head, csv_metadata, read

FloatArray = NDArray[np.float64]

__doc__ = f"{__doc__}{columns_doc()}"

#: The settings of ``Mechanism.simulate`` a results file records (None: the library default).
SETTING_NAMES = ("t_end", "method", "rtol", "atol", "dt", "output_dt", "max_steps")


# ------------------------------------------------------------------ metadata


def simulate_settings(mech: Mechanism, **given: Any) -> dict[str, Any]:
    """The settings a run uses: each given value, else the model file's, else None.

    ``mech.simulate(**simulate_settings(mech, rtol=1e-8))`` is the same run as
    ``mech.simulate(rtol=1e-8)``; the dict is what results files record.
    """
    unknown = set(given) - set(SETTING_NAMES)
    if unknown:
        raise TypeError(f"unknown simulate settings: {', '.join(sorted(unknown))}")
    model = mech.simulate_defaults
    return {k: given[k] if given.get(k) is not None else model.get(k) for k in SETTING_NAMES}


# ------------------------------------------------------------------ write / read


def write_results(
    result: SimulationResult,
    path: str | os.PathLike[str],
    *,
    mechanism: Mechanism | None = None,
    settings: dict[str, Any] | None = None,
) -> Path:
    """Write ``result`` to ``path`` (``.csv``, ``.parquet`` or ``.npz``) with its metadata:
    ``result.save(path)``, recording ``mechanism`` and ``settings`` when given (see
    :func:`attach_metadata`). Returns the path.
    """
    if mechanism is not None or settings is not None:
        result = attach_metadata(result, mechanism, settings)
    return result.save(path)


def read_results(path: str | os.PathLike[str]) -> SimulationResult:
    """Read a results file written by planardyn (``.csv``, ``.parquet`` or ``.npz``).

    Gives back the result that was written, every array equal, with ``metadata`` (model,
    settings, version; :func:`planardyn.from_result` rebuilds the model).

    Raises
    ------
    FileNotFoundError
        No such file.
    DataError
        (a ``ValueError``) Not a planardyn results file, or a damaged one: truncated (fewer
        rows than its metadata records), changed (its checksum), metadata missing or of the
        wrong type, a file its format's library cannot read. The message starts with the
        file's name.

    The numbers go straight into the result's arrays a block of rows (or an array) at a
    time: reading needs about the memory of the arrays themselves.
    """
    return read(path)


# ------------------------------------------------------------------ motions and inverse dynamics


def read_motion(path: str | os.PathLike[str], coordinate_names: list[str]) -> dict[str, Any]:
    """Read a prescribed motion: a CSV table, or any planardyn results file.

    The CSV has a header row with ``t`` (s) and one column per coordinate name (rad or m),
    and optionally ``qd_<name>``, ``qdd_<name>``, ``tau_<name>`` (measured efforts, N m or
    N) and ``tau_motor_<name>`` (motor torques, N m) columns; other columns are ignored, and
    so are leading ``#`` comment lines.

    Returns
    -------
    dict with ``t`` (N,), ``q`` (N, m), and ``qd``, ``qdd``, ``tau``: (N, m) arrays where
    every coordinate had such a column (a results file has all three), else None;
    ``tau_motor`` (N, m) likewise (a results file's motor torques, None without actuators);
    ``from_results`` True for a results file (its ``tau`` is joint-side); ``x`` (N, 3n) the
    body coordinates of a results file (the branch it is on) and ``xd`` (N, 3n) its body rates,
    None for a table; and
    per-coordinate lists ``qd_columns``/``qdd_columns`` (a (N,) array or None for each).
    """
    path = Path(path)
    if path.suffix.lower() in (".npz", ".parquet") or (path.suffix.lower() == ".csv" and _is_results_csv(path)):
        res = read_results(path)
        if res.coordinate_names != list(coordinate_names):
            raise data_error(path, f"the results' coordinates ({', '.join(res.coordinate_names)}) are not "
                                   f"the model's ({', '.join(coordinate_names)})")
        groups = {"": res.q, "qd_": res.qd, "qdd_": res.qdd, "tau_": res.tau, "tau_motor_": res.tau_motor}
        _check_finite(path, {f"{p}{n}": a[:, k] for p, a in groups.items() if a is not None
                             for k, n in enumerate(coordinate_names)})
        return {"t": res.t, "q": res.q, "qd": res.qd, "qdd": res.qdd, "tau": res.tau, "tau_motor": res.tau_motor,
                "from_results": True, "x": res.x, "xd": res.xd, "qd_columns": list(res.qd.T),
                "qdd_columns": list(res.qdd.T)}
    if not path.is_file():
        raise FileNotFoundError(f"{path}: no such motion file")
    try:
        with open(path, encoding="utf-8") as f:
            _, header = csv_head(f)
            need = ["t", *coordinate_names]
            missing = [c for c in need if c not in header]
            if missing:
                raise Damaged(f"motion table has no column {', '.join(repr(c) for c in missing)} (it needs t and "
                              f"the coordinates {', '.join(coordinate_names)}; found {', '.join(header)})")
            used = need + [f"{p}_{n}" for p in ("qd", "qdd", "tau", "tau_motor") for n in coordinate_names
                           if f"{p}_{n}" in header]
            cols = [header.index(h) for h in used]
            blocks = list(csv_blocks(f, header, cols))
    except UnicodeDecodeError:
        raise data_error(path, "not text: it holds bytes that are not UTF-8 (not a CSV table?)") from None
    except Damaged as e:
        raise data_error(path, str(e)) from None
    data = np.concatenate(blocks) if blocks else np.empty((0, len(used)))
    col = {h: data[:, k] for k, h in enumerate(used)}
    _check_finite(path, col)
    t = col["t"]
    if len(t) < 2:
        raise data_error(path, f"a motion needs at least 2 rows, found {len(t)}")
    if np.any(np.diff(t) <= 0):
        k = int(np.argmax(np.diff(t) <= 0))
        raise data_error(path, f"column t must increase strictly: data row {k + 2} ({t[k + 1]!r} s) does not "
                               f"come after row {k + 1} ({t[k]!r} s)")
    both = lambda p: np.column_stack([col[f"{p}_{n}"] for n in coordinate_names]) if all(  # noqa: E731
        f"{p}_{n}" in col for n in coordinate_names) else None
    return {"t": t, "q": np.column_stack([col[n] for n in coordinate_names]), "qd": both("qd"), "qdd": both("qdd"),
            "tau": both("tau"), "tau_motor": both("tau_motor"), "from_results": False, "x": None, "xd": None,
            "qd_columns": [col.get(f"qd_{n}") for n in coordinate_names],
            "qdd_columns": [col.get(f"qdd_{n}") for n in coordinate_names]}


def _check_finite(path: Path, columns: dict[str, FloatArray]) -> None:
    """Refuse a motion with a NaN or an infinity, naming the first data row that has one
    (from 1) and its column."""
    rows = {h: np.flatnonzero(~np.isfinite(c)) for h, c in columns.items()}
    bad = [(int(r[0]), h) for h, r in rows.items() if len(r)]
    if bad:
        i, h = min(bad)
        raise data_error(path, f"data row {i + 1} has {columns[h][i]} in column {h!r}: give finite numbers "
                               "(remove the row, or fill it in)")


def _is_results_csv(path: Path) -> bool:
    """Whether a CSV file is a planardyn results file: its metadata file beside it, or its
    head (files written before the metadata file was)."""
    try:
        with open(path, encoding="utf-8") as f:
            meta = csv_metadata(path, csv_head(f)[0])
    except (OSError, UnicodeDecodeError, Damaged):
        return False
    return isinstance(meta, dict) and meta.get("format") == FORMAT


def motion_derivatives(
    t: ArrayLike, q: ArrayLike, qd_columns: list[Any] | None = None, qdd_columns: list[Any] | None = None
) -> tuple[FloatArray, FloatArray]:
    """Rates and accelerations of a sampled motion from cubic splines (scipy's CubicSpline,
    not-a-knot ends).

    For each coordinate k: ``qd`` is ``qd_columns[k]`` when given, else the spline of q
    differentiated once; ``qdd`` is ``qdd_columns[k]`` when given, else the derivative of
    the spline of the given rates, else the spline of q differentiated twice. Shapes: t
    (N,) s, q (N, m); returns two (N, m) arrays (rad/s or m/s, rad/s^2 or m/s^2).
    """
    from scipy.interpolate import CubicSpline

    t = times("t", t)
    q = samples("q", q, len(t), what="rad or m")
    m = q.shape[1]
    finite_rates(q, t)
    qd_columns = qd_columns or [None] * m
    qdd_columns = qdd_columns or [None] * m
    qd, qdd = np.empty_like(q), np.empty_like(q)
    for k in range(m):
        try:
            sq = CubicSpline(t, q[:, k])
            if qd_columns[k] is not None:
                qd[:, k] = qd_columns[k]
                second = CubicSpline(t, qd[:, k])(t, 1)
            else:
                qd[:, k] = sq(t, 1)
                second = sq(t, 2)
        except ValueError:  # scipy's refusal of its own overflow
            raise rates_overflow(q, t) from None
        qdd[:, k] = qdd_columns[k] if qdd_columns[k] is not None else second
    finite_rates(q, t, qd, qdd)
    return qd, qdd


def inverse_result(
    mech: Mechanism,
    t: ArrayLike,
    q: ArrayLike,
    qd: ArrayLike | None = None,
    qdd: ArrayLike | None = None,
    x: ArrayLike | None = None,
    xd: ArrayLike | None = None,
) -> SimulationResult:
    """Drive efforts for a prescribed motion, as a result (``metadata['kind'] = 'inverse'``).

    The rows follow the branch of ``x`` as :meth:`Mechanism.inverse_dynamics` does: every
    row's own body coordinates when ``x`` is (N, 3n), else continuation from row to row,
    refused (``SingularityError`` with ``row`` and ``t``) where q alone cannot tell the branch.

    Parameters
    ----------
    t : (N,) array_like
        Times (s), strictly increasing.
    q : (N, m) array_like
        Coordinates (rad or m) along the motion.
    qd, qdd : (N, m) array_like, optional
        Rates and accelerations; those not given come from cubic splines
        (:func:`motion_derivatives`).
    x : (3n,) or (N, 3n) array_like, optional
        Body coordinates (m, m, rad per body) at the first row, or at every row (a results
        file's ``x``).
    xd : array_like of x's shape, optional
        Body rates of x's rows (a results file's ``xd``), used instead of those solved from
        qd (:meth:`Mechanism.inverse_dynamics`); then also the result's ``xd``.

    Returns
    -------
    SimulationResult
        ``tau`` (N, m): the drive efforts (N m or N) that produce the motion together with
        the model's loads (springs, dampers, gravity; the model's own drives are not
        counted), joint-side; ``tau_motor`` their motor torques where the model has
        actuators; ``x``, ``xd``, ``sigma``, ``residual`` from the kinematics at each row;
        kinetic and potential energy; ``work`` the work of tau (J, trapezoidal rule);
        ``metadata["branch"]`` says which branch the rows were computed on.
    """
    t = times("t", t)
    m = mech.dof
    q = samples("q", q, len(t), m, "rad or m")
    if qd is None or qdd is None:
        sd, sdd = motion_derivatives(t, q)
        qd = sd if qd is None else qd
        qdd = sdd if qdd is None else qdd
    qd = samples("qd", qd, len(t), m, "rad/s or m/s")
    qdd = samples("qdd", qdd, len(t), m, "rad/s^2 or m/s^2")
    given = None if x is None else np.asarray(x, dtype=np.float64)
    given_xd = None if xd is None else np.asarray(xd, dtype=np.float64)
    try:
        tau = np.asarray(mech.inverse_dynamics(q, qd, qdd, given, given_xd), dtype=np.float64).reshape(q.shape)
    except SingularityError as e:
        row = getattr(e, "row", None)
        if row is not None:
            e.t = float(t[row])  # type: ignore[attr-defined]
            e.args = (f"at t = {t[row]:.6g} s: {e}",)
        raise
    n_t, n_b = len(t), mech.n_bodies
    x, xd = np.empty((n_t, 3 * n_b)), np.empty((n_t, 3 * n_b))
    sigma, residual, kinetic, potential = (np.empty(n_t) for _ in range(4))
    for i in range(n_t):
        # Each row from its own body coordinates when given, else from the row before.
        if given is not None and given.ndim == 2:
            start = given[i]
        else:
            start = given if i == 0 else x[i - 1]
        k = mech.kinematics(q[i], qd[i], x_start=start)
        x[i], xd[i] = k["x"], k["xd"] if given_xd is None else given_xd.reshape(n_t, -1)[i]
        sigma[i], residual[i] = k["sigma_min"], k["residual"]
        kinetic[i], potential[i] = mech.energy(q[i], qd[i], x_start=x[i])
    power = np.sum(tau * qd, axis=1)
    work = np.concatenate([[0.0], np.cumsum(0.5 * (power[1:] + power[:-1]) * np.diff(t))])
    columns: dict[str, Any] = {"t": t, "q": q, "qd": qd, "qdd": qdd, "tau": tau, "x": x, "xd": xd}
    columns |= {"kinetic": kinetic, "potential": potential, "work": work, "sigma": sigma, "residual": residual,
                "partitioned": np.zeros(n_t, dtype=bool)}
    columns["tau_motor"], note = mech._result_motor_torques(columns)
    res = SimulationResult(
        **column_fields(columns, mech.body_names),
        success=True, status="success", message="inverse dynamics of a prescribed motion" + note,
        stats={"rows": n_t, "max_residual": float(residual.max()), "min_sigma": float(sigma.min()),
               "max_abs_tau": [float(v) for v in np.abs(tau).max(axis=0)]},
        coordinate_names=list(mech.coordinate_names),
        coordinate_kinds=list(mech.coordinate_kinds),
        body_names=list(mech.body_names),
    )
    if given is not None and given.ndim == 2:
        branch = "each row's body coordinates"
    elif given is not None:
        branch = "continued from the first row's body coordinates"
    else:
        branch = "the drawn branch, continued row to row"
    return attach_metadata(res, mech, None, kind="inverse", branch=branch)


def inverse_from_file(mech: Mechanism, path: str | os.PathLike[str]) -> SimulationResult:
    """:func:`inverse_result` of the motion in a file (see :func:`read_motion`)."""
    m = read_motion(path, mech.coordinate_names)
    qd, qdd = motion_derivatives(m["t"], m["q"], m["qd_columns"], m["qdd_columns"])
    try:
        res = inverse_result(mech, m["t"], m["q"], qd, qdd, x=m["x"], xd=m["xd"])
    except SingularityError as e:
        e.args = (f"{path}: {e}",)
        raise
    return attach_metadata(res, None, None, motion=str(path))

