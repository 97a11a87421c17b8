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

A file is written whole or not at all (a temporary file renamed over the target). Its
metadata records ``rows`` (the number of output times) and ``checksum`` (CRC-32 of the
numbers): a truncated or changed file is refused on reading, with its name and what is
wrong. Whether the run itself completed is its ``status`` (``'success'``, ``'cancelled'``
for an interrupted run written as far as it got, ...).

Columns, in order: ``t``; the coordinate names (q); ``qd_<name>``; ``qdd_<name>``;
``tau_<name>``; ``kinetic``, ``potential``, ``work`` (J); ``sigma``; ``residual``;
``partitioned`` (0/1); ``X_<body>``, ``Y_<body>``, ``phi_<body>`` (x) and ``Xd_<body>``,
``Yd_<body>``, ``phid_<body>`` (xd); for a model with actuators, ``tau_motor_<name>`` (the
motor torques, N m: ``Mechanism.motor_torques`` of the rows, what identification reads).
Readers split the table by position (the layout is in the metadata), so a coordinate may be
named like another column.
"""

from __future__ import annotations

import csv
import io
import json
import os
import zipfile
import zlib
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ._core import SingularityError
from .mechanism import Mechanism, attach_metadata
from .result import ChangePoint, Energy, SimulationResult
from .results_format import EXTENSIONS, FORMAT, FORMAT_VERSION
from .results_format import checksum as _checksum
from .results_format import columns as _columns
from .results_format import pyarrow as _pyarrow
from .results_format import table as _table

FloatArray = NDArray[np.float64]

#: The settings of ``Mechanism.simulate`` a results file records (None: the library default).
SETTING_NAMES = ("t_end", "method", "rtol", "atol", "dt", "output_dt", "max_steps")
#: Metadata a results file cannot be read without (the others may be absent or None).
REQUIRED_FIELDS = ("coordinate_names", "coordinate_kinds", "body_names", "status", "success", "message", "layout")


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


def _result(meta: dict[str, Any], table: FloatArray, path: Path) -> SimulationResult:
    """Rebuild a result from its checked metadata and its (rows, columns) table."""
    groups, col = {}, 0
    for g, k in meta["layout"]:
        groups[g] = np.ascontiguousarray(table[:, col : col + k])
        col += k
    n_t, n_b = len(table), len(meta["body_names"])
    flat = lambda g: np.ascontiguousarray(groups[g].reshape(n_t))  # noqa: E731
    own = {"format", "format_version", "status", "success", "message", "stats", "coordinate_names",
           "coordinate_kinds", "body_names", "layout", "rows", "checksum", "events",
           "change_points"}
    m = len(meta["coordinate_names"])
    events = meta.get("events") or {}
    per_event = lambda key, shape: [np.asarray(v, dtype=float).reshape(shape) for v in events.get(key, [])]  # noqa: E731
    return SimulationResult(
        t=flat("t"), q=groups["q"], qd=groups["qd"], qdd=groups["qdd"], tau=groups["tau"],
        x=groups["x"], xd=groups["xd"], poses=groups["x"].reshape(n_t, n_b, 3),
        energy=Energy.from_arrays(flat("kinetic"), flat("potential"), flat("work")),
        sigma=flat("sigma"), residual=flat("residual"), partitioned=flat("partitioned").astype(bool),
        success=meta["success"], status=meta["status"], message=meta["message"],
        stats=dict(meta.get("stats") or {}),
        coordinate_names=list(meta["coordinate_names"]),
        coordinate_kinds=list(meta["coordinate_kinds"]),
        body_names=list(meta["body_names"]),
        change_points=[ChangePoint.from_dict(c) for c in meta.get("change_points") or []],
        metadata={k: v for k, v in meta.items() if k not in own} | {"path": str(path)},
        t_events=per_event("t", (-1,)), q_events=per_event("q", (-1, m)), qd_events=per_event("qd", (-1, m)),
        tau_motor=groups.get("tau_motor"),
    )


class _Damaged(Exception):
    """What is wrong with a results file (the reader adds the file's name)."""


def _is_str_list(v: Any) -> bool:
    return isinstance(v, list) and all(isinstance(s, str) for s in v)


def _check_meta(meta: Any) -> dict[str, Any]:
    """The metadata if it is a planardyn results file's, field by field, else _Damaged."""
    if not isinstance(meta, dict) or meta.get("format") != FORMAT:
        raise _Damaged(f"not a planardyn results file (no '{FORMAT}' metadata)")
    version = meta.get("format_version")
    if not isinstance(version, int) or isinstance(version, bool) or version < 1:
        raise _Damaged(f"metadata field 'format_version' is {version!r}, not a version number")
    if version > FORMAT_VERSION:
        raise _Damaged(f"results format version {version} is newer than this planardyn reads "
                       f"({FORMAT_VERSION}): upgrade planardyn")
    fields: list[tuple[str, Callable[[Any], bool], str]] = [
        ("coordinate_names", _is_str_list, "a list of names"),
        ("coordinate_kinds", lambda v: isinstance(v, list) and all(k in ("angle", "displacement") for k in v),
         "a list of 'angle'/'displacement'"),
        ("body_names", _is_str_list, "a list of names"),
        ("status", lambda v: isinstance(v, str), "a string"),
        ("success", lambda v: isinstance(v, bool), "true or false"),
        ("message", lambda v: isinstance(v, str), "a string"),
        ("stats", lambda v: v is None or isinstance(v, dict), "a mapping"),
        ("model", lambda v: v is None or isinstance(v, dict), "a model mapping"),
        ("settings", lambda v: v is None or isinstance(v, dict), "a mapping"),
        ("rows", lambda v: v is None or isinstance(v, int) and not isinstance(v, bool) and v >= 0,
         "a number of rows"),
        ("checksum", lambda v: v is None or isinstance(v, int) and not isinstance(v, bool), "a CRC-32"),
    ]
    # From version 2 the integrity fields are required: a damaged key must not switch the check off.
    required = REQUIRED_FIELDS + (("rows", "checksum") if version >= 2 else ())
    missing = [k for k in required if k not in meta]
    if missing:
        raise _Damaged(f"metadata has no field{'s' * (len(missing) > 1)} {', '.join(repr(k) for k in missing)}")
    for name, ok, what in fields:
        if not ok(meta.get(name)):
            raise _Damaged(f"metadata field {name!r} is {_short(meta.get(name))}, not {what}")
    if len(meta["coordinate_kinds"]) != len(meta["coordinate_names"]):
        raise _Damaged("metadata fields 'coordinate_names' and 'coordinate_kinds' differ in length")
    layout = [[g, len(c)] for g, c in _layout(meta)]
    if meta["layout"] != layout:
        raise _Damaged(f"metadata field 'layout' is {_short(meta['layout'])}, not the layout of its "
                       f"coordinates and bodies {layout}")
    return meta


def _layout(meta: dict[str, Any]) -> list[tuple[str, list[str]]]:
    """The columns of a file with this metadata: with the motor torques when its layout names them."""
    motor = isinstance(meta["layout"], list) and ["tau_motor", len(meta["coordinate_names"])] in meta["layout"]
    return _columns(meta["coordinate_names"], meta["body_names"], motor)


def _short(v: Any) -> str:
    text = repr(v)
    return text if len(text) <= 60 else text[:57] + "..."


def _check_table(meta: dict[str, Any], table: FloatArray) -> FloatArray:
    """The table if it has the rows and the checksum the metadata records, else _Damaged."""
    rows = meta.get("rows")
    if rows is not None and len(table) != rows:
        raise _Damaged(f"truncated or damaged: {len(table)} rows where its metadata records {rows} "
                       "(an interrupted copy or write?)")
    if meta.get("checksum") is not None and _checksum(meta, table) != meta["checksum"]:
        raise _Damaged("damaged: its contents do not match the checksum its metadata records "
                       "(changed after it was written?)")
    return table


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
    ValueError
        Not a planardyn results file, or a damaged one: truncated (fewer rows than its
        metadata records), changed (its checksum), metadata missing or of the wrong type,
        a file its format's library cannot read. The message starts with the file's name.
    """
    path = Path(path)
    ext = path.suffix.lower()
    if ext not in EXTENSIONS:
        raise ValueError(f"{path}: unknown results format {ext!r} (use {', '.join(EXTENSIONS)})")
    if not path.is_file():
        raise FileNotFoundError(f"{path}: no such results file")
    readers = {".npz": _read_npz, ".parquet": _read_parquet, ".csv": _read_csv_table}
    try:
        meta, table = readers[ext](path)
        return _result(meta, _check_table(meta, table), path)
    except _Damaged as e:
        raise ValueError(f"{path}: {e}") from None
    except MemoryError:
        raise ValueError(f"{path}: damaged: it declares arrays larger than memory") from None
    except _library_errors() as e:
        raise ValueError(f"{path}: damaged or not a {ext} results file ({type(e).__name__}: {e})") from None


def _library_errors() -> tuple[type[BaseException], ...]:
    """What numpy, zipfile, zlib, json and pyarrow raise on a damaged file (zipfile: a
    NotImplementedError for flags or a compression it does not know, a RuntimeError for an
    encrypted member)."""
    errors: tuple[type[BaseException], ...] = (OSError, EOFError, zipfile.BadZipFile, zlib.error, ValueError,
                                               NotImplementedError, RuntimeError)
    try:
        import pyarrow as pa
    except ImportError:  # pragma: no cover - depends on the environment
        return errors
    return (*errors, pa.lib.ArrowException)


def _read_npz(path: Path) -> tuple[dict[str, Any], FloatArray]:
    if not zipfile.is_zipfile(path):
        raise _Damaged("not an .npz archive (damaged, or another kind of file)")
    with np.load(path, allow_pickle=False) as z:
        if "metadata" not in z.files:
            raise _Damaged("not a planardyn results file (no 'metadata' array)")
        raw = _member(z, "metadata")
        if raw.shape != () or raw.dtype.kind != "U":
            raise _Damaged(f"array 'metadata' is {raw.dtype} of shape {raw.shape}, not one JSON string")
        meta = _check_meta(_json(str(raw)))
        layout = [(g, k) for g, k in meta["layout"]]
        missing = [g for g, _ in layout if g not in z.files]
        if missing:
            raise _Damaged(f"no array {', '.join(repr(g) for g in missing)}")
        groups = {g: _member(z, g) for g, _ in layout}
    n_t = groups["t"].size
    for g, k in layout:
        a = groups[g]
        if a.dtype.kind not in "fiub":
            raise _Damaged(f"array {g!r} holds {a.dtype}, not numbers")
        if a.size != n_t * k:
            raise _Damaged(f"array {g!r} has {a.size} values where {n_t} rows of {k} need {n_t * k}")
    return meta, _table(groups, layout, n_t)


def _member(z: Any, name: str) -> np.ndarray:
    """Array ``name`` of an open .npz; numpy's refusals as _Damaged."""
    try:
        return z[name]
    except ValueError as e:
        if "allow_pickle" in str(e):
            raise _Damaged(f"array {name!r} holds Python objects, not numbers") from None
        raise _Damaged(f"array {name!r} is damaged ({e})") from None


def _read_parquet(path: Path) -> tuple[dict[str, Any], FloatArray]:
    pa, pq = _pyarrow()
    table = pq.read_table(path)
    raw = (table.schema.metadata or {}).get(b"planardyn")
    meta = _check_meta(_json(raw) if raw else None)
    width = sum(k for _, k in meta["layout"])
    _check_header(meta, table.column_names)
    cols = [table.column(i).to_numpy().astype(np.float64) for i in range(table.num_columns)]
    return meta, np.column_stack(cols).reshape(table.num_rows, width) if cols else np.empty((table.num_rows, 0))


def _read_csv_table(path: Path) -> tuple[dict[str, Any], FloatArray]:
    found, header, rows = _read_csv(path)
    meta = _check_meta(found)
    _check_header(meta, header)
    width = len(header)
    data = np.empty((len(rows), width))
    for i, r in enumerate(rows):
        try:
            if len(r) != width:
                raise ValueError(f"{len(r)} fields")
            data[i] = [float(v) for v in r]
        except ValueError as e:
            raise _Damaged(f"data row {i + 1} is not {width} numbers ({e}): truncated or damaged") from None
    return meta, data


def _check_header(meta: dict[str, Any], header: list[str]) -> None:
    names = [c for _, cols in _layout(meta) for c in cols]
    if header != names:
        wrong = next((k for k, (h, n) in enumerate(zip(header, names)) if h != n), min(len(header), len(names)))
        raise _Damaged(f"{len(header)} columns where its metadata says {len(names)}: column {wrong + 1} is "
                       f"{header[wrong] if wrong < len(header) else 'missing'!r}, expected "
                       f"{names[wrong] if wrong < len(names) else 'none'!r}")


def _json(text: Any) -> Any:
    try:
        return json.loads(text)
    except (ValueError, TypeError) as e:
        raise _Damaged(f"metadata is not JSON ({e})") from None


def _read_csv(path: Path) -> tuple[dict[str, Any] | None, list[str], list[list[str]]]:
    """The JSON of the leading '# ' lines (None if there are none or it is not JSON), the
    header, the data rows."""
    try:
        text = path.read_text(encoding="utf-8")
    except UnicodeDecodeError as e:
        raise _Damaged(f"not text: byte {e.start} is not UTF-8 (damaged, or not a CSV file)") from None
    comment: list[str] = []
    lines = text.splitlines(keepends=True)
    k = 0
    while k < len(lines) and lines[k].startswith("#"):
        comment.append(lines[k][2:] if lines[k].startswith("# ") else lines[k][1:])
        k += 1
    body = lines[k:]
    try:
        rows = [r for r in csv.reader(io.StringIO("".join(body))) if r]
    except csv.Error as e:
        raise _Damaged(f"not a CSV table ({e})") from None
    meta = None
    if comment:
        try:
            meta = json.loads("".join(comment))
        except json.JSONDecodeError:
            meta = None
    return meta, [h.strip() for h in rows[0]] if rows else [], rows[1:]


def _read_named_csv(path: Path) -> tuple[dict[str, Any] | None, list[str], list[list[str]]]:
    """:func:`_read_csv`, its errors as ValueErrors that name the file."""
    try:
        return _read_csv(path)
    except _Damaged as e:
        raise ValueError(f"{path}: {e}") from None


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
    if path.suffix.lower() in (".npz", ".parquet") or (
        path.suffix.lower() == ".csv" and path.is_file() and path.open("rb").read(1) == b"#"
        and ((_read_named_csv(path)[0] or {}).get("format") == FORMAT)
    ):
        res = read_results(path)
        if res.coordinate_names != list(coordinate_names):
            raise ValueError(
                f"{path}: the results' coordinates ({', '.join(res.coordinate_names)}) are not "
                f"the model's ({', '.join(coordinate_names)})"
            )
        return {"t": res.t, "q": res.q, "qd": res.qd, "qdd": res.qdd, "tau": res.tau, "tau_motor": res.tau_motor,
                "from_results": True, "x": res.x, "xd": res.xd, "qd_columns": list(res.qd.T),
                "qdd_columns": list(res.qdd.T)}
    if not path.is_file():
        raise FileNotFoundError(f"{path}: no such motion file")
    _, header, rows = _read_named_csv(path)
    need = ["t", *coordinate_names]
    missing = [c for c in need if c not in header]
    if missing:
        raise ValueError(
            f"{path}: motion table has no column {', '.join(repr(c) for c in missing)} "
            f"(it needs t and the coordinates {', '.join(coordinate_names)}; found {', '.join(header)})"
        )
    col = {h: i for i, h in enumerate(header)}
    used = need + [f"{p}_{n}" for p in ("qd", "qdd", "tau", "tau_motor") for n in coordinate_names
                   if f"{p}_{n}" in col]
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
    tau = both([get(f"tau_{n}") for n in coordinate_names])
    tau_motor = both([get(f"tau_motor_{n}") for n in coordinate_names])
    return {"t": t, "q": q, "qd": both(qd_cols), "qdd": both(qdd_cols), "tau": tau, "tau_motor": tau_motor,
            "from_results": False, "x": None, "xd": None, "qd_columns": qd_cols, "qdd_columns": qdd_cols}


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
        tau_motor=mech._result_motor_torques({"q": q, "qd": qd, "qdd": qdd, "tau": tau, "x": x, "xd": xd}),
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

