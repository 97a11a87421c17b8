"""Results files (CSV, Parquet, NPZ) and motion tables for inverse dynamics.

A results file holds every array of a :class:`~planardyn.SimulationResult` and, as JSON
metadata, what is needed to reproduce and re-plot it: the model (``Mechanism.to_dict()``),
the solver settings (keyword arguments of ``Mechanism.simulate``), the planardyn version,
the status and counters. The format is chosen by the file name's extension:

``.csv``
    The metadata as JSON on leading ``# `` comment lines, then a header row and one row per
    output time; numbers are written with ``repr`` (the shortest string that reads back to
    the same double, at most 17 significant digits), so they round-trip exactly.
``.parquet``
    One column per channel (pyarrow), the metadata under the file-level key ``planardyn``.
``.npz``
    One array per quantity (``t``, ``q``, ``x``, ...), the metadata as a 0-d string array
    ``metadata`` (read with ``allow_pickle=False``).

Columns, in order: ``t``; the coordinate names (q); ``qd_<name>``; ``qdd_<name>``;
``tau_<name>``; ``kinetic``, ``potential``, ``work`` (J); ``sigma``; ``residual``;
``partitioned`` (0/1); ``X_<body>``, ``Y_<body>``, ``phi_<body>`` (x) and ``Xd_<body>``,
``Yd_<body>``, ``phid_<body>`` (xd). Readers split the table by position (the layout is in
the metadata), so a coordinate may be named like another column.
"""

from __future__ import annotations

import csv
import io
import json
import os
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ._core import __version__
from .mechanism import Mechanism, attach_metadata, plain
from .result import Energy, SimulationResult

FloatArray = NDArray[np.float64]

FORMAT = "planardyn-results"
FORMAT_VERSION = 1
EXTENSIONS = (".csv", ".parquet", ".npz")
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


def _layout(res: SimulationResult) -> list[tuple[str, list[str]]]:
    """(group, column names) in file order; groups are result fields or energy entries."""
    names, bodies = res.coordinate_names, res.body_names
    body_cols = [f"{c}_{b}" for b in bodies for c in ("X", "Y", "phi")]
    return [
        ("t", ["t"]),
        ("q", list(names)),
        ("qd", [f"qd_{n}" for n in names]),
        ("qdd", [f"qdd_{n}" for n in names]),
        ("tau", [f"tau_{n}" for n in names]),
        ("kinetic", ["kinetic"]),
        ("potential", ["potential"]),
        ("work", ["work"]),
        ("sigma", ["sigma"]),
        ("residual", ["residual"]),
        ("partitioned", ["partitioned"]),
        ("x", body_cols),
        ("xd", [c.replace("_", "d_", 1) for c in body_cols]),
    ]


def _group_arrays(res: SimulationResult) -> dict[str, np.ndarray]:
    e = res.energy
    return {
        "t": res.t, "q": res.q, "qd": res.qd, "qdd": res.qdd, "tau": res.tau,
        "kinetic": e.kinetic, "potential": e.potential, "work": e.work,
        "sigma": res.sigma, "residual": res.residual, "partitioned": res.partitioned,
        "x": res.x, "xd": res.xd,
    }


def _metadata(res: SimulationResult) -> dict[str, Any]:
    meta = {
        "format": FORMAT,
        "format_version": FORMAT_VERSION,
        "kind": "simulation",
        "planardyn_version": __version__,
        "model": None,
        "settings": None,
    }
    meta.update(res.metadata)
    meta.update(
        status=res.status,
        success=res.success,
        message=res.message,
        stats={k: plain(v) for k, v in res.stats.items()},
        coordinate_names=res.coordinate_names,
        coordinate_kinds=res.coordinate_kinds,
        body_names=res.body_names,
        layout=[[g, len(cols)] for g, cols in _layout(res)],
    )
    return meta


def _result(meta: dict[str, Any], groups: dict[str, np.ndarray], path: Path) -> SimulationResult:
    """Rebuild a result from its metadata and its arrays by group (2-D where the result has it)."""
    n_b = len(meta["body_names"])
    n_t = len(groups["t"])
    as2 = lambda a, k: np.ascontiguousarray(np.asarray(a, dtype=np.float64).reshape(n_t, k))  # noqa: E731
    m = len(meta["coordinate_names"])
    x = as2(groups["x"], 3 * n_b)
    own = {"format", "format_version", "status", "success", "message", "stats", "coordinate_names",
           "coordinate_kinds", "body_names", "layout"}
    return SimulationResult(
        t=np.ascontiguousarray(np.asarray(groups["t"], dtype=np.float64).reshape(n_t)),
        q=as2(groups["q"], m),
        qd=as2(groups["qd"], m),
        qdd=as2(groups["qdd"], m),
        tau=as2(groups["tau"], m),
        x=x,
        xd=as2(groups["xd"], 3 * n_b),
        poses=x.reshape(n_t, n_b, 3),
        energy=Energy.from_arrays(
            *(np.asarray(groups[k], dtype=np.float64).reshape(n_t) for k in ("kinetic", "potential", "work"))
        ),
        sigma=np.asarray(groups["sigma"], dtype=np.float64).reshape(n_t),
        residual=np.asarray(groups["residual"], dtype=np.float64).reshape(n_t),
        partitioned=np.asarray(groups["partitioned"]).reshape(n_t).astype(bool),
        success=bool(meta["success"]),
        status=str(meta["status"]),
        message=str(meta["message"]),
        stats=dict(meta.get("stats") or {}),
        coordinate_names=list(meta["coordinate_names"]),
        coordinate_kinds=list(meta["coordinate_kinds"]),
        body_names=list(meta["body_names"]),
        metadata={k: v for k, v in meta.items() if k not in own} | {"path": str(path)},
    )


def _split(meta: dict[str, Any], table: np.ndarray, path: Path) -> dict[str, np.ndarray]:
    groups, col = {}, 0
    for g, k in meta["layout"]:
        groups[g] = table[:, col : col + k]
        col += k
    if col != table.shape[1]:
        raise ValueError(f"{path}: {table.shape[1]} columns, the metadata's layout says {col}")
    return groups


def _check_meta(meta: Any, path: Path) -> dict[str, Any]:
    if not isinstance(meta, dict) or meta.get("format") != FORMAT:
        raise ValueError(f"{path}: not a planardyn results file (no '{FORMAT}' metadata)")
    if meta.get("format_version", 0) > FORMAT_VERSION:
        raise ValueError(
            f"{path}: results format version {meta['format_version']} is newer than this "
            f"planardyn reads ({FORMAT_VERSION}): upgrade planardyn"
        )
    return meta


# ------------------------------------------------------------------ write / read


def write_results(
    result: SimulationResult,
    path: str | os.PathLike[str],
    *,
    mechanism: Mechanism | None = None,
    settings: dict[str, Any] | None = None,
) -> Path:
    """Write ``result`` to ``path`` (``.csv``, ``.parquet`` or ``.npz``) with its metadata.

    ``mechanism`` and ``settings`` are recorded when given (see :func:`attach_metadata`).
    Parquet needs pyarrow. Returns the path.
    """
    path = Path(path)
    ext = path.suffix.lower()
    if ext not in EXTENSIONS:
        raise ValueError(f"{path}: unknown results format {ext!r} (use {', '.join(EXTENSIONS)})")
    if mechanism is not None or settings is not None:
        result = attach_metadata(result, mechanism, settings)
    meta = _metadata(result)
    meta.pop("path", None)
    groups = _group_arrays(result)
    n_t = len(result.t)
    if ext == ".npz":
        # Any: numpy's signature would also take a group for its allow_pickle flag.
        arrays: dict[str, Any] = {g: np.asarray(a) for g, a in groups.items()}
        with open(path, "wb") as f:
            np.savez_compressed(f, metadata=np.array(json.dumps(meta)), **arrays)
        return path
    names = [c for _, cols in _layout(result) for c in cols]
    columns = [
        np.asarray(groups[g], dtype=np.float64).reshape(n_t, len(cols))[:, k]
        for g, cols in _layout(result)
        for k in range(len(cols))
    ]
    if ext == ".parquet":
        pa, pq = _pyarrow()
        pa_columns = [pa.array(c.astype(bool) if n == "partitioned" else c) for n, c in zip(names, columns)]
        table = pa.Table.from_arrays(pa_columns, names=names).replace_schema_metadata(
            {"planardyn": json.dumps(meta)}
        )
        pq.write_table(table, path)
        return path
    with open(path, "w", newline="") as f:
        for line in json.dumps(meta, indent=1).splitlines():
            f.write(f"# {line}\n")
        w = csv.writer(f)
        w.writerow(names)
        for row in zip(*(c.tolist() for c in columns)):
            w.writerow([repr(v) for v in row])
    return path


def read_results(path: str | os.PathLike[str]) -> SimulationResult:
    """Read a results file written by planardyn (``.csv``, ``.parquet`` or ``.npz``).

    Gives back the result that was written, every array equal, with ``metadata`` (model,
    settings, version; :func:`planardyn.from_result` rebuilds the model).

    Raises
    ------
    FileNotFoundError
        No such file.
    ValueError
        Not a planardyn results file, or a damaged one.
    """
    path = Path(path)
    ext = path.suffix.lower()
    if not path.is_file():
        raise FileNotFoundError(f"{path}: no such results file")
    if ext == ".npz":
        with np.load(path, allow_pickle=False) as z:
            if "metadata" not in z.files:
                raise ValueError(f"{path}: not a planardyn results file (no 'metadata' array)")
            meta = _check_meta(json.loads(str(z["metadata"])), path)
            groups = {g: z[g] for g, _ in meta["layout"]}
        return _result(meta, groups, path)
    if ext == ".parquet":
        pa, pq = _pyarrow()
        table = pq.read_table(path)
        raw = (table.schema.metadata or {}).get(b"planardyn")
        meta = _check_meta(json.loads(raw) if raw else None, path)
        cols = [table.column(i).to_numpy().astype(np.float64) for i in range(table.num_columns)]
        data = np.column_stack(cols) if cols else np.empty((0, 0))
        return _result(meta, _split(meta, data.reshape(table.num_rows, len(cols)), path), path)
    if ext == ".csv":
        found, _, rows = _read_csv(path)
        meta = _check_meta(found, path)
        width = sum(k for _, k in meta["layout"])
        try:
            data = np.array([[float(v) for v in r] for r in rows], dtype=np.float64).reshape(len(rows), width)
        except ValueError as e:
            raise ValueError(f"{path}: a row is not {width} numbers ({e})") from None
        return _result(meta, _split(meta, data, path), path)
    raise ValueError(f"{path}: unknown results format {ext!r} (use {', '.join(EXTENSIONS)})")


def _read_csv(path: Path) -> tuple[dict[str, Any] | None, list[str], list[list[str]]]:
    """The JSON of the leading '# ' lines (None if there are none), the header, the data rows."""
    text = path.read_text()
    comment: list[str] = []
    lines = text.splitlines(keepends=True)
    k = 0
    while k < len(lines) and lines[k].startswith("#"):
        comment.append(lines[k][2:] if lines[k].startswith("# ") else lines[k][1:])
        k += 1
    body = lines[k:]
    rows = [r for r in csv.reader(io.StringIO("".join(body))) if r]
    meta = None
    if comment:
        try:
            meta = json.loads("".join(comment))
        except json.JSONDecodeError:
            meta = None
    return meta, [h.strip() for h in rows[0]] if rows else [], rows[1:]


def _pyarrow() -> tuple[Any, Any]:
    try:
        import pyarrow as pa
        import pyarrow.parquet as pq
    except ImportError as e:  # pragma: no cover - depends on the environment
        raise ImportError("Parquet results files need pyarrow: pip install pyarrow") from e
    return pa, pq


# ------------------------------------------------------------------ motions and inverse dynamics


def read_motion(path: str | os.PathLike[str], coordinate_names: list[str]) -> dict[str, Any]:
    """Read a prescribed motion: a CSV table, or any planardyn results file.

    The CSV has a header row with ``t`` (s) and one column per coordinate name (rad or m),
    and optionally ``qd_<name>`` and ``qdd_<name>`` columns; other columns are ignored, and
    so are leading ``#`` comment lines.

    Returns
    -------
    dict with ``t`` (N,), ``q`` (N, m), and ``qd``, ``qdd``: (N, m) arrays where every
    coordinate had such a column (a results file has both), else None; ``x`` (N, 3n) the
    body coordinates of a results file (the branch it is on), None for a table; and
    per-coordinate lists ``qd_columns``/``qdd_columns`` (a (N,) array or None for each).
    """
    path = Path(path)
    if path.suffix.lower() in (".npz", ".parquet") or (
        path.suffix.lower() == ".csv" and path.is_file() and path.read_text()[:1] == "#"
        and ((_read_csv(path)[0] or {}).get("format") == FORMAT)
    ):
        res = read_results(path)
        if res.coordinate_names != list(coordinate_names):
            raise ValueError(
                f"{path}: the results' coordinates ({', '.join(res.coordinate_names)}) are not "
                f"the model's ({', '.join(coordinate_names)})"
            )
        return {"t": res.t, "q": res.q, "qd": res.qd, "qdd": res.qdd, "x": res.x,
                "qd_columns": list(res.qd.T), "qdd_columns": list(res.qdd.T)}
    if not path.is_file():
        raise FileNotFoundError(f"{path}: no such motion file")
    _, header, rows = _read_csv(path)
    need = ["t", *coordinate_names]
    missing = [c for c in need if c not in header]
    if missing:
        raise ValueError(
            f"{path}: motion table has no column {', '.join(repr(c) for c in missing)} "
            f"(it needs t and the coordinates {', '.join(coordinate_names)}; found {', '.join(header)})"
        )
    col = {h: i for i, h in enumerate(header)}
    used = need + [f"{p}_{n}" for p in ("qd", "qdd") for n in coordinate_names if f"{p}_{n}" in col]
    data = np.empty((len(rows), len(header)))
    for i, r in enumerate(rows):
        for h in used:
            try:
                data[i, col[h]] = float(r[col[h]])
            except (ValueError, IndexError):
                raise ValueError(f"{path}: row {i + 1} of the data has no number in column {h!r}") from None
        if not all(np.isfinite(data[i, col[h]]) for h in used):
            raise ValueError(f"{path}: row {i + 1} of the data has a non-finite value")
    get = lambda h: data[:, col[h]] if h in col else None  # noqa: E731 - an optional column
    t = data[:, col["t"]]
    if len(t) < 2:
        raise ValueError(f"{path}: a motion needs at least 2 rows, found {len(t)}")
    if np.any(np.diff(t) <= 0):
        raise ValueError(f"{path}: column t must increase strictly")
    q = np.column_stack([data[:, col[n]] for n in coordinate_names])
    qd_cols = [get(f"qd_{n}") for n in coordinate_names]
    qdd_cols = [get(f"qdd_{n}") for n in coordinate_names]
    both = lambda cols: None if any(c is None for c in cols) else np.column_stack(cols)  # noqa: E731
    return {"t": t, "q": q, "qd": both(qd_cols), "qdd": both(qdd_cols), "x": None,
            "qd_columns": qd_cols, "qdd_columns": qdd_cols}


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

    t = np.asarray(t, dtype=np.float64)
    q = np.asarray(q, dtype=np.float64)
    m = q.shape[1]
    qd_columns = qd_columns or [None] * m
    qdd_columns = qdd_columns or [None] * m
    qd, qdd = np.empty_like(q), np.empty_like(q)
    for k in range(m):
        sq = CubicSpline(t, q[:, k])
        if qd_columns[k] is not None:
            qd[:, k] = qd_columns[k]
            second = CubicSpline(t, qd[:, k])(t, 1)
        else:
            qd[:, k] = sq(t, 1)
            second = sq(t, 2)
        qdd[:, k] = qdd_columns[k] if qdd_columns[k] is not None else second
    return qd, qdd


def inverse_result(
    mech: Mechanism,
    t: ArrayLike,
    q: ArrayLike,
    qd: ArrayLike | None = None,
    qdd: ArrayLike | None = None,
    x_start: ArrayLike | None = None,
) -> SimulationResult:
    """Drive efforts for a prescribed motion, as a result (``metadata['kind'] = 'inverse'``).

    The rows follow one branch: the first is reached from ``x_start`` (else the drawing),
    every next one by continuation from the previous row's body coordinates.

    Parameters
    ----------
    t : (N,) array_like
        Times (s), strictly increasing.
    q : (N, m) array_like
        Coordinates (rad or m) along the motion.
    qd, qdd : (N, m) array_like, optional
        Rates and accelerations; those not given come from cubic splines
        (:func:`motion_derivatives`).
    x_start : (3n,) array_like, optional
        Body coordinates (m, m, rad per body) on the wanted branch at the first row, e.g. a
        results file's ``x[0]``.

    Returns
    -------
    SimulationResult
        ``tau`` (N, m): the drive efforts (N m or N) that produce the motion together with
        the model's loads (springs, dampers, gravity; the model's own drives are not
        counted); ``x``, ``xd``, ``sigma``, ``residual`` from the kinematics at each row;
        kinetic and potential energy; ``work`` the work of tau (J, trapezoidal rule).
    """
    t = np.ascontiguousarray(t, dtype=np.float64)
    q = np.ascontiguousarray(q, dtype=np.float64)
    if q.ndim == 1:
        q = q[:, None]
    if qd is None or qdd is None:
        sd, sdd = motion_derivatives(t, q)
        qd = sd if qd is None else qd
        qdd = sdd if qdd is None else qdd
    qd = np.ascontiguousarray(qd, dtype=np.float64).reshape(q.shape)
    qdd = np.ascontiguousarray(qdd, dtype=np.float64).reshape(q.shape)
    tau = np.asarray(mech.inverse_dynamics(q, qd, qdd, x_start), dtype=np.float64).reshape(q.shape)
    n_t, n_b = len(t), mech.n_bodies
    x, xd = np.empty((n_t, 3 * n_b)), np.empty((n_t, 3 * n_b))
    sigma, residual, kinetic, potential = (np.empty(n_t) for _ in range(4))
    for i in range(n_t):
        k = mech.kinematics(q[i], qd[i], x_start=x_start if i == 0 else x[i - 1])
        x[i], xd[i] = k["x"], k["xd"]
        sigma[i], residual[i] = k["sigma_min"], k["residual"]
        kinetic[i], potential[i] = mech.energy(q[i], qd[i], x_start=x[i])
    power = np.sum(tau * qd, axis=1)
    work = np.concatenate([[0.0], np.cumsum(0.5 * (power[1:] + power[:-1]) * np.diff(t))])
    res = SimulationResult(
        t=t, q=q, qd=qd, qdd=qdd, tau=tau, x=x, xd=xd, poses=x.reshape(n_t, n_b, 3),
        energy=Energy.from_arrays(kinetic, potential, work),
        sigma=sigma, residual=residual, partitioned=np.zeros(n_t, dtype=bool),
        success=True, status="success", message="inverse dynamics of a prescribed motion",
        stats={"rows": n_t, "max_residual": float(residual.max()), "min_sigma": float(sigma.min()),
               "max_abs_tau": [float(v) for v in np.abs(tau).max(axis=0)]},
        coordinate_names=list(mech.coordinate_names),
        coordinate_kinds=list(mech.coordinate_kinds),
        body_names=list(mech.body_names),
    )
    return attach_metadata(res, mech, None, kind="inverse")


def inverse_from_file(mech: Mechanism, path: str | os.PathLike[str]) -> SimulationResult:
    """:func:`inverse_result` of the motion in a file (see :func:`read_motion`)."""
    m = read_motion(path, mech.coordinate_names)
    qd, qdd = motion_derivatives(m["t"], m["q"], m["qd_columns"], m["qdd_columns"])
    x = m["x"]
    res = inverse_result(mech, m["t"], m["q"], qd, qdd, x_start=None if x is None else x[0])
    return attach_metadata(res, None, None, motion=str(path))

