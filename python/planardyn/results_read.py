"""Reading a results file back (:func:`planardyn.read_results`) in memory bounded by the
arrays it holds: the numbers go straight into the result's arrays, one block of rows (CSV,
Parquet) or one array (NPZ) at a time, and the checksum is taken along the way, so a read
needs the result's arrays and one block, not a copy of the whole table per step.

Every damage is refused by :class:`~planardyn.DataError` naming the file and what is wrong:
not a results file, metadata missing or of the wrong type, fewer or more rows than the
metadata records (a cut copy), a row that is not numbers, a checksum that does not match.
"""

from __future__ import annotations

import csv
import itertools
import json
import os
import zipfile
import zlib
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import IO, Any

import numpy as np
from numpy.typing import NDArray

from .arguments import data_error
from .result import ChangePoint, SimulationResult, column_fields
from .results_format import (
    COLUMN,
    COLUMNS,
    CSV_BLOCK,
    EXTENSIONS,
    FORMAT,
    FORMAT_VERSION,
    checksum_rows,
    checksum_start,
    metadata_path,
)
from .results_format import columns as _columns
from .results_format import pyarrow as _pyarrow

FloatArray = NDArray[np.float64]

#: Metadata a results file cannot be read without (the others may be absent or None).
REQUIRED_FIELDS = ("coordinate_names", "coordinate_kinds", "body_names", "status", "success", "message", "layout")
#: Fewest bytes a CSV data row of w columns takes: a digit and a comma per number. A
#: metadata ``rows`` beyond what the file's size can hold is damage, refused before any
#: array is allocated for it.
CSV_MIN_BYTES_PER_NUMBER = 2


class Damaged(Exception):
    """What is wrong with a results file (the reader adds the file's name)."""


def read(path: str | os.PathLike[str]) -> SimulationResult:
    """The result a results file holds (see :func:`planardyn.read_results`)."""
    path = Path(path)
    ext = path.suffix.lower()
    if ext not in EXTENSIONS:
        raise data_error(path, f"unknown results format {ext!r} (use {', '.join(EXTENSIONS)})")
    if not path.is_file():
        raise FileNotFoundError(f"{path}: no such results file")
    readers: dict[str, Callable[[Path], tuple[dict[str, Any], dict[str, FloatArray]]]] = {
        ".npz": _read_npz, ".parquet": _read_parquet, ".csv": _read_csv}
    try:
        meta, groups = readers[ext](path)
        return _result(meta, groups, path)
    except Damaged as e:
        raise data_error(path, str(e)) from None
    except MemoryError:
        raise data_error(path, "damaged: it declares arrays larger than memory") from None
    except _library_errors() as e:
        raise data_error(path, f"damaged or not a {ext} results file ({type(e).__name__}: {e})") from None


# ------------------------------------------------------------------ metadata


def _is_str_list(v: Any) -> bool:
    return isinstance(v, list) and all(isinstance(s, str) for s in v)


def check_meta(meta: Any) -> dict[str, Any]:
    """The metadata if it is a planardyn results file's, field by field, else Damaged."""
    if not isinstance(meta, dict) or meta.get("format") != FORMAT:
        raise Damaged(f"not a planardyn results file (no '{FORMAT}' metadata)")
    version = meta.get("format_version")
    if not isinstance(version, int) or isinstance(version, bool) or version < 1:
        raise Damaged(f"metadata field 'format_version' is {version!r}, not a version number")
    if version > FORMAT_VERSION:
        raise Damaged(f"results format version {version} is newer than this planardyn reads "
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
        raise Damaged(f"metadata has no field{'s' * (len(missing) > 1)} {', '.join(repr(k) for k in missing)}")
    for name, ok, what in fields:
        if not ok(meta.get(name)):
            raise Damaged(f"metadata field {name!r} is {_short(meta.get(name))}, not {what}")
    if len(meta["coordinate_kinds"]) != len(meta["coordinate_names"]):
        raise Damaged("metadata fields 'coordinate_names' and 'coordinate_kinds' differ in length")
    layout = [[g, len(c)] for g, c in _layout(meta)]
    if meta["layout"] != layout:
        raise Damaged(f"metadata field 'layout' is {_short(meta['layout'])}, not the layout of its "
                      f"coordinates and bodies {layout}")
    return meta


def _layout(meta: dict[str, Any]) -> list[tuple[str, list[str]]]:
    """The columns of a file with this metadata: with an optional one (the motor torques) when
    its layout names it."""
    layout = meta["layout"] if isinstance(meta["layout"], list) else []
    present = [c.name for c in COLUMNS if c.optional and any(isinstance(e, list) and e[:1] == [c.name] for e in layout)]
    return _columns(meta["coordinate_names"], meta["body_names"], present)


def _short(v: Any) -> str:
    text = repr(v)
    return text if len(text) <= 60 else text[:57] + "..."


def _json(text: Any) -> Any:
    try:
        return json.loads(text)
    except (ValueError, TypeError) as e:
        raise Damaged(f"metadata is not JSON ({e})") from None


def _check_header(meta: dict[str, Any], header: list[str]) -> None:
    names = [c for _, cols in _layout(meta) for c in cols]
    if header != names:
        wrong = next((k for k, (h, n) in enumerate(zip(header, names)) if h != n), min(len(header), len(names)))
        raise Damaged(f"{len(header)} columns where its metadata says {len(names)}: column {wrong + 1} is "
                      f"{header[wrong] if wrong < len(header) else 'missing'!r}, expected "
                      f"{names[wrong] if wrong < len(names) else 'none'!r}")


def _rows_message(found: int, rows: int) -> str:
    return f"truncated or damaged: {found} rows where its metadata records {rows} (an interrupted copy or write?)"


def _check_sum(meta: dict[str, Any], crc: int) -> None:
    if meta.get("checksum") is not None and crc != meta["checksum"]:
        raise Damaged("damaged: its contents do not match the checksum its metadata records "
                      "(changed after it was written?)")


# ------------------------------------------------------------------ the arrays, block by block


class _Arrays:
    """The result's arrays (one per group of the layout, (rows, k) each) filled by blocks of
    the file's rows (rows, w) in order, the checksum taken along."""

    def __init__(self, meta: dict[str, Any], rows: int) -> None:
        self.meta, self.rows, self.filled, self.extra = meta, rows, 0, 0
        self.layout = [(g, int(k)) for g, k in meta["layout"]]
        self.groups = {g: np.empty((rows, k)) for g, k in self.layout}
        self.crc = checksum_start(meta)

    def add(self, block: FloatArray) -> None:
        n = len(block)
        if self.extra or self.filled + n > self.rows:  # only counted, for the message
            self.extra += n
            return
        col = 0
        for g, k in self.layout:
            self.groups[g][self.filled:self.filled + n] = block[:, col:col + k]
            col += k
        self.crc = checksum_rows(block, self.crc)
        self.filled += n

    def done(self) -> dict[str, FloatArray]:
        if self.filled + self.extra != self.rows:
            raise Damaged(_rows_message(self.filled + self.extra, self.rows))
        _check_sum(self.meta, self.crc)
        return self.groups


def _result(meta: dict[str, Any], groups: dict[str, FloatArray], path: Path) -> SimulationResult:
    """Rebuild a result from its checked metadata and its arrays ((rows, k) per group)."""
    own = {"format", "format_version", "status", "success", "message", "stats", "coordinate_names",
           "coordinate_kinds", "body_names", "layout", "rows", "checksum", "events",
           "change_points"}
    m = len(meta["coordinate_names"])
    events = meta.get("events") or {}
    per_event = lambda key, shape: [np.asarray(v, dtype=float).reshape(shape) for v in events.get(key, [])]  # noqa: E731
    return SimulationResult(
        **column_fields({g: COLUMN[g].values(a) for g, a in groups.items()}, meta["body_names"]),
        success=meta["success"], status=meta["status"], message=meta["message"],
        stats=dict(meta.get("stats") or {}),
        coordinate_names=list(meta["coordinate_names"]),
        coordinate_kinds=list(meta["coordinate_kinds"]),
        body_names=list(meta["body_names"]),
        change_points=[ChangePoint.from_dict(c) for c in meta.get("change_points") or []],
        metadata={k: v for k, v in meta.items() if k not in own} | {"path": str(path)},
        t_events=per_event("t", (-1,)), q_events=per_event("q", (-1, m)), qd_events=per_event("qd", (-1, m)),
    )


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


# ------------------------------------------------------------------ NPZ: one array at a time


def _read_npz(path: Path) -> tuple[dict[str, Any], dict[str, FloatArray]]:
    if not zipfile.is_zipfile(path):
        raise Damaged("not an .npz archive (damaged, or another kind of file)")
    with np.load(path, allow_pickle=False) as z:
        if "metadata" not in z.files:
            raise Damaged("not a planardyn results file (no 'metadata' array)")
        raw = _member(z, "metadata")
        if raw.shape != () or raw.dtype.kind != "U":
            raise Damaged(f"array 'metadata' is {raw.dtype} of shape {raw.shape}, not one JSON string")
        meta = check_meta(_json(str(raw)))
        layout = [(g, int(k)) for g, k in meta["layout"]]
        missing = [g for g, _ in layout if g not in z.files]
        if missing:
            raise Damaged(f"no array {', '.join(repr(g) for g in missing)}")
        groups: dict[str, FloatArray] = {}
        n_t = None
        for g, k in layout:  # decompressed one at a time, each converted in place of the last
            a = _member(z, g)
            if a.dtype.kind not in "fiub":
                raise Damaged(f"array {g!r} holds {a.dtype}, not numbers")
            n_t = a.size if n_t is None else n_t
            if a.size != n_t * k:
                raise Damaged(f"array {g!r} has {a.size} values where {n_t} rows of {k} need {n_t * k}")
            groups[g] = np.ascontiguousarray(a, dtype=np.float64).reshape(n_t, k)
            del a
    rows = meta.get("rows")
    if rows is not None and n_t != rows:
        raise Damaged(_rows_message(n_t or 0, rows))
    return meta, _checked(meta, groups, layout, n_t or 0)


def _checked(meta: dict[str, Any], groups: dict[str, FloatArray], layout: list[tuple[str, int]],
             n_t: int) -> dict[str, FloatArray]:
    """The arrays, once their checksum, taken over their rows in file order CSV_BLOCK rows
    at a time, is the metadata's."""
    crc = checksum_start(meta)
    for start in range(0, n_t, CSV_BLOCK):
        crc = checksum_rows(np.hstack([groups[g][start:start + CSV_BLOCK] for g, _ in layout]), crc)
    _check_sum(meta, crc)
    return groups


def _member(z: Any, name: str) -> NDArray[Any]:
    """Array ``name`` of an open .npz; numpy's refusals as Damaged."""
    try:
        return np.asarray(z[name])
    except ValueError as e:
        if "allow_pickle" in str(e):
            raise Damaged(f"array {name!r} holds Python objects, not numbers") from None
        raise Damaged(f"array {name!r} is damaged ({e})") from None


# ------------------------------------------------------------------ Parquet: one column at a time


def _read_parquet(path: Path) -> tuple[dict[str, Any], dict[str, FloatArray]]:
    pa, pq = _pyarrow()
    f = pq.ParquetFile(path)
    raw = (f.schema_arrow.metadata or {}).get(b"planardyn")
    meta = check_meta(_json(raw) if raw else None)
    names = f.schema_arrow.names
    _check_header(meta, names)
    n_t = f.metadata.num_rows
    if meta.get("rows") is not None and n_t != meta["rows"]:
        raise Damaged(_rows_message(n_t, meta["rows"]))
    layout = [(g, int(k)) for g, k in meta["layout"]]
    groups = {g: np.empty((n_t, k)) for g, k in layout}
    col = iter(names)
    for g, k in layout:  # a column decompressed at a time, straight into its array
        for j in range(k):
            start = 0
            name = next(col)
            for chunk in f.read(columns=[name]).column(0).chunks:
                groups[g][start:start + len(chunk), j] = _floats(pa, chunk, name)
                start += len(chunk)
    return meta, _checked(meta, groups, layout, n_t)


def _floats(pa: Any, chunk: Any, name: str) -> FloatArray:
    """A Parquet column's chunk as float64 values, a view of its buffer (pyarrow's own
    ``to_numpy`` imports pandas, 30 MB and a second, for every read)."""
    if chunk.null_count:
        raise Damaged(f"column {name!r} has {chunk.null_count} missing values")
    values = chunk.cast(pa.float64())
    return np.frombuffer(values.buffers()[1], dtype="<f8", count=len(values), offset=values.offset * 8)


# ------------------------------------------------------------------ CSV: blocks of lines


def csv_head(f: IO[str]) -> tuple[dict[str, Any] | None, list[str]]:
    """From an open CSV file: the JSON of its leading '#' lines (None if there are none or
    it is not JSON) and its header (the first line after them that is not blank), leaving
    ``f`` at the first data line."""
    comment: list[str] = []
    line = f.readline()
    while line.startswith("#"):
        comment.append(line[2:] if line.startswith("# ") else line[1:])
        line = f.readline()
    while line and not line.strip():
        line = f.readline()
    header = [h.strip() for h in next(csv.reader([line]), [])] if line else []
    meta = None
    if comment:
        try:
            meta = json.loads("".join(comment))
        except json.JSONDecodeError:
            meta = None
    return meta, header


def csv_blocks(f: IO[str], header: list[str], usecols: list[int] | None = None) -> Iterator[FloatArray]:
    """The data lines of an open CSV file after its ``header``, CSV_BLOCK at a time, as
    (n, len(header)) floats, or (n, len(usecols)) of the columns ``usecols`` only (a motion
    table's other columns may hold anything); blank lines are skipped. A line that is not
    that many numbers is Damaged, named by its row (from 1) and column."""
    row = 1
    lines = (ln for ln in f if ln.strip())
    while block := list(itertools.islice(lines, CSV_BLOCK)):
        try:
            values = np.loadtxt(block, delimiter=",", dtype=np.float64, ndmin=2, comments=None, usecols=usecols)
            if values.shape[1] != (len(header) if usecols is None else len(usecols)):
                raise ValueError("a column is missing")
        except ValueError:  # numpy says which row only in words: locate it line by line
            values = _parse_lines(block, header, usecols, row)
        yield values
        row += len(block)


def _parse_lines(block: list[str], header: list[str], usecols: list[int] | None, first: int) -> FloatArray:
    """A block parsed line by line (csv quoting allowed), Damaged naming the first bad row."""
    width = len(header)
    cols = list(range(width)) if usecols is None else usecols
    out = np.empty((len(block), len(cols)))
    for i, r in enumerate(csv.reader(block)):
        if usecols is None and len(r) != width:
            raise Damaged(f"data row {first + i} is not {width} numbers ({len(r)} fields): truncated or damaged")
        for j, k in enumerate(cols):
            try:
                out[i, j] = float(r[k])
            except (ValueError, IndexError):
                found = repr(r[k]) if k < len(r) else "nothing"
                raise Damaged(f"data row {first + i} has no number in column {header[k]!r} (found {found})") from None
    return out


def csv_metadata(path: Path, head: Any) -> Any:
    """A CSV results file's metadata: its JSON file beside it (``run.csv.json``), else the
    ``# `` lines at its head (``head``, from :func:`csv_head`: files written before the JSON
    file was), else None."""
    beside = metadata_path(path)
    if not beside.is_file():
        return head
    try:
        return json.loads(beside.read_text(encoding="utf-8"))
    except (ValueError, UnicodeDecodeError) as e:
        raise Damaged(f"its metadata file {beside.name} is not JSON ({e})") from None


def _read_csv(path: Path) -> tuple[dict[str, Any], dict[str, FloatArray]]:
    try:
        with open(path, encoding="utf-8") as f:
            head, header = csv_head(f)
            found = csv_metadata(path, head)
            if found is None:
                raise Damaged(f"not a planardyn results file: no metadata file {metadata_path(path).name} "
                              "beside it (copy it with the table) and none at its head")
            meta = check_meta(found)
            _check_header(meta, header)
            width = len(header)
            rows = meta.get("rows")
            if rows is None:  # a version 1 file: count its rows first
                rows = sum(1 for ln in f if ln.strip())
                f.seek(0)
                csv_head(f)
            if rows * width * CSV_MIN_BYTES_PER_NUMBER > os.path.getsize(path):
                raise Damaged(f"truncated or damaged: its metadata records {rows} rows of {width} numbers, "
                              "more than the file can hold (an interrupted copy or write?)")
            arrays = _Arrays(meta, rows)
            for block in csv_blocks(f, header):
                arrays.add(block)
            return meta, arrays.done()
    except UnicodeDecodeError:
        raise Damaged("not text: it holds bytes that are not UTF-8 (damaged, or not a CSV file)") from None
