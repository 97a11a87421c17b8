"""The results file format, written from plain arrays: the column layout, the checksum, the
atomic replacement of a file, the writers of its three forms (CSV, Parquet, NPZ), and the
errors of a write in words, naming the path asked for (:func:`writing`).

It sits below :mod:`planardyn.result` so that a result can save itself
(``SimulationResult.save``/``to_csv``) in the one format :func:`planardyn.read_results`,
``planardyn plot`` and ``planardyn animate`` read; :mod:`planardyn.results_io` reads it back
and describes the format.
"""

from __future__ import annotations

import contextlib
import csv
import errno
import json
import os
import zlib
from collections.abc import Collection, Iterator
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from . import extras
from ._core import output_columns

FloatArray = NDArray[np.float64]

FORMAT = "planardyn-results"
#: 2: the metadata records ``rows`` and ``checksum`` (version 1 files, without them, are read);
#: 3: a model with actuators adds the motor torques ``tau_motor``.
FORMAT_VERSION = 3
EXTENSIONS = (".csv", ".parquet", ".npz")
#: What a CSV results file's metadata file adds to its name: ``run.csv`` -> ``run.csv.json``.
#: (Before, the metadata were ``# `` lines at the head of the CSV, which spreadsheets do not
#: read; such files are still read.)
METADATA_SUFFIX = ".json"
#: Rows formatted (CSV) or checksummed at a time: bounds the memory a long run's file needs.
CSV_BLOCK = 4096


def plain(v: Any) -> Any:
    """``v`` as JSON takes it: numpy arrays and numbers as lists and Python numbers."""
    if isinstance(v, (np.ndarray, np.generic)):
        return v.tolist()
    return v


#: The axes of a body's pose, in the order of its body coordinates [X, Y, phi].
POSE_AXES = ("X", "Y", "phi")
#: A column's shape per output row, as a result holds it (N rows, m coordinates, n bodies).
SHAPES = {"scalar": "(N,)", "flag": "(N,) bool", "coordinates": "(N, m)", "body_poses": "(N, 3n)"}


@dataclass(frozen=True)
class Column:
    """An output column: ``name`` (the result's field, or the entry of its ``energy``; the
    results file's group), ``shape`` per row (a key of :data:`SHAPES`), ``unit`` (SI; "rad or
    m" by the coordinate's kind, "1" for a pure number), ``doc`` (one line), ``heading`` (its
    columns' headings in a table: ``{coordinate}`` a coordinate's name, ``{axis}`` and
    ``{body}`` a body's pose), and whether it is ``optional`` (None on a result without it)."""

    name: str
    shape: str
    unit: str
    doc: str
    heading: str
    optional: bool = False

    def headings(self, coordinates: list[str], bodies: list[str]) -> list[str]:
        """The headings of its columns in a table, for these coordinates and bodies."""
        if self.shape == "coordinates":
            return [self.heading.format(coordinate=n) for n in coordinates]
        if self.shape == "body_poses":
            return [self.heading.format(axis=a, body=b) for b in bodies for a in POSE_AXES]
        if self.shape in ("scalar", "flag"):
            return [self.heading]
        raise ValueError(f"output column {self.name!r}: unknown shape {self.shape!r} (known: {', '.join(SHAPES)})")

    def values(self, rows: FloatArray) -> NDArray[Any]:
        """Its (N, k) block of a table as the result holds it: (N,) for a scalar, bool for a flag."""
        if self.shape == "flag":
            return rows.reshape(len(rows)).astype(bool)
        return rows.reshape(len(rows)) if self.shape == "scalar" else rows

    def describe(self) -> str:
        """One line: name, shape, what it is and its unit."""
        return f"``{self.name}`` {SHAPES[self.shape]}: {self.doc} ({self.unit})"


#: The motor torques: computed in Python from a run (``Mechanism.motor_torques``), for a model
#: with actuators only, last in a file so that the other columns keep their places.
TAU_MOTOR = Column("tau_motor", "coordinates", "N m",
                   "motor torques of a model with actuators, what its drives measure "
                   "(``Mechanism.motor_torques`` of the rows; tau on a coordinate without one)",
                   "tau_motor_{coordinate}", optional=True)
#: Every output column, in a results file's order: the core's (``_core.output_columns()``,
#: crates/planardyn/src/simulate/columns.rs), then the motor torques.
COLUMNS = (*(Column(*c) for c in output_columns()), TAU_MOTOR)
#: The columns by name.
COLUMN = {c.name: c for c in COLUMNS}


def columns(names: list[str], bodies: list[str], present: Collection[str] = ()) -> list[tuple[str, list[str]]]:
    """(group, column names) in file order, for coordinates ``names`` and ``bodies``: every
    column of :data:`COLUMNS`, an optional one (the motor torques) only when it is in
    ``present``."""
    return [(c.name, c.headings(names, bodies)) for c in COLUMNS if not c.optional or c.name in present]


def columns_doc(indent: str = "") -> str:
    """The columns of :data:`COLUMNS`, one line each, for the docs (each line after ``indent``)."""
    return "".join(f"{indent}- {c.describe()}\n" for c in COLUMNS)


def metadata_path(path: str | os.PathLike[str]) -> Path:
    """The metadata file beside a CSV results file: ``run.csv`` -> ``run.csv.json``."""
    path = Path(path)
    return path.with_name(path.name + METADATA_SUFFIX)


def table(groups: dict[str, Any], layout: list[tuple[str, int]], n_t: int) -> FloatArray:
    """The groups side by side in layout order: one row per output time, float64."""
    cols = [np.asarray(groups[g], dtype=np.float64).reshape(n_t, k) for g, k in layout]
    return np.hstack(cols) if cols else np.empty((n_t, 0))


def checksum(meta: dict[str, Any], table: FloatArray) -> int:
    """CRC-32 of the metadata (as JSON in its order, without the checksum) and of the
    table's little-endian float64 bytes, row by row (every NaN as one NaN)."""
    crc = checksum_start(meta)
    for start in range(0, len(table), CSV_BLOCK):
        crc = checksum_rows(table[start:start + CSV_BLOCK], crc)
    return crc


def checksum_start(meta: dict[str, Any]) -> int:
    """:func:`checksum` of the metadata alone: the value its rows continue from."""
    text = json.dumps({k: v for k, v in meta.items() if k not in ("checksum", "path")})
    return zlib.crc32(text.encode())


def checksum_rows(block: FloatArray, crc: int) -> int:
    """:func:`checksum` continued over the rows ``block``: a CRC-32 is the same whichever
    blocks its bytes come in, so a reader takes it along as it reads."""
    canonical = np.where(np.isnan(block), np.nan, block).astype("<f8")
    return zlib.crc32(np.ascontiguousarray(canonical).tobytes(), crc)


def pyarrow() -> tuple[Any, Any]:
    """pyarrow and pyarrow.parquet, or an ImportError saying how to get them."""
    try:
        import pyarrow as pa
        import pyarrow.parquet as pq
    except ImportError as e:
        raise extras.missing("parquet", "a Parquet results file", e) from e
    return pa, pq


#: Why a file could not be written, in words, by errno.
WRITE_CAUSES = {
    errno.ENOENT: "its directory does not exist (and could not be made)",
    errno.EACCES: "permission denied",
    errno.EPERM: "permission denied",
    errno.EROFS: "the file system is read-only",
    errno.ENOSPC: "the disk is full",
    errno.EDQUOT: "the disk quota is exceeded",
    errno.EISDIR: "it is a directory",
    errno.ENAMETOOLONG: "the name is too long",
    errno.EFBIG: "the file is larger than the file system allows",
}


class WriteError(OSError):
    """A file that could not be written (an ``OSError`` with the cause's ``errno``): the
    message names the path asked for (not a temporary file) and the cause in words."""

    def __str__(self) -> str:
        return str(self.strerror)


def write_error(path: str | os.PathLike[str], e: OSError) -> WriteError:
    """``e``, raised writing ``path``, as a :class:`WriteError` naming ``path``."""
    path = Path(path)
    if e.errno in (errno.EEXIST, errno.ENOTDIR):  # a part of the directory is a file
        blocking = next((p for p in reversed(path.parents) if p.exists() and not p.is_dir()), path.parent)
        cause = f"{blocking} is a file, not a directory"
    elif e.errno == errno.ENOENT and path.parent.is_dir():  # /proc, /sys: no new files there
        cause = f"{path.parent} does not take new files"
    else:
        cause = WRITE_CAUSES.get(e.errno or 0, e.strerror or str(e))
    return WriteError(e.errno, f"cannot write {path}: {cause}")


@contextlib.contextmanager
def writing(path: str | os.PathLike[str], make_directory: bool = True) -> Iterator[Path]:
    """Around the writing of ``path``: its directory made first (``make_directory``), and any
    ``OSError`` raised inside turned into a :class:`WriteError` naming ``path``."""
    path = Path(path)
    try:
        if make_directory:
            path.parent.mkdir(parents=True, exist_ok=True)
        yield path
    except (WriteError, BrokenPipeError):  # a closed stdout is not the file's failure
        raise
    except OSError as e:
        raise write_error(path, e) from None


def check_writable(path: str | os.PathLike[str]) -> Path:
    """Refuse, before a long computation, a file that cannot be written: its directory made
    and a file created and removed there; a failure is a :class:`WriteError` naming ``path``."""
    path = Path(path)
    with writing(path):
        if path.is_dir():
            raise IsADirectoryError(errno.EISDIR, "is a directory")
        probe = path.with_name(f".{path.name}.{os.getpid()}.probe")
        probe.open("w").close()
        probe.unlink()
    return path


@contextlib.contextmanager
def replacing(path: Path) -> Iterator[Path]:
    """A temporary file next to ``path`` that replaces it (one rename) when the block ends
    without an error, and is removed when it fails: ``path`` is never half written. An
    ``OSError`` is a :class:`WriteError` naming ``path`` (the temporary file is ours)."""
    tmp = path.with_name(f".{path.name}.{os.getpid()}.part")
    with writing(path, make_directory=False):
        try:
            yield tmp
            with open(tmp, "rb+") as f:
                os.fsync(f.fileno())
            os.replace(tmp, path)
        except BaseException:
            tmp.unlink(missing_ok=True)
            raise


def write(path: str | os.PathLike[str], meta: dict[str, Any], groups: dict[str, Any],
          layout: list[tuple[str, list[str]]], ext: str | None = None) -> Path:
    """Write a results file: ``meta`` (JSON-plain metadata, without ``rows`` and
    ``checksum``, which are added), the arrays ``groups`` in ``layout`` order. The form is
    ``ext`` or the name's extension. The file is written whole or not at all; a CSV's metadata
    go to :func:`metadata_path` beside it (a plain table a spreadsheet opens, and its JSON),
    written after the table: the checksum the JSON records refuses a table it was not
    written with."""
    path = Path(path)
    ext = (ext or path.suffix).lower()
    if ext not in EXTENSIONS:
        raise ValueError(f"{path}: unknown results format {ext!r} (use {', '.join(EXTENSIONS)})")
    n_t = len(groups["t"])
    tab = table(groups, [(g, len(c)) for g, c in layout], n_t)
    meta = {**meta, "rows": n_t}
    meta["checksum"] = checksum(meta, tab)
    names = [c for _, cols in layout for c in cols]
    with replacing(path) as tmp:
        if ext == ".npz":
            # Any: numpy's signature would also take a group for its allow_pickle flag.
            arrays: dict[str, Any] = {g: np.asarray(a) for g, a in groups.items()}
            with open(tmp, "wb") as f:
                np.savez_compressed(f, metadata=np.array(json.dumps(meta)), **arrays)
        elif ext == ".parquet":
            pa, pq = pyarrow()
            flags = [COLUMN[g].shape == "flag" for g, cols in layout for _ in cols]
            pa_columns = [pa.array(tab[:, k].astype(bool) if flag else tab[:, k]) for k, flag in enumerate(flags)]
            pq.write_table(pa.Table.from_arrays(pa_columns, names=names).replace_schema_metadata(
                {"planardyn": json.dumps(meta)}), tmp)
        else:
            with open(tmp, "w", newline="") as f:
                w = csv.writer(f)
                w.writerow(names)
                for start in range(0, n_t, CSV_BLOCK):
                    w.writerows([repr(v) for v in row] for row in tab[start:start + CSV_BLOCK].tolist())
    if ext == ".csv":
        with replacing(metadata_path(path)) as tmp, open(tmp, "w", encoding="utf-8") as f:
            f.write(json.dumps(meta, indent=1) + "\n")
    return path
