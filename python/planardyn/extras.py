"""The optional extras of ``pip install 'planardyn-<version>.whl[EXTRA]'`` and the error a
missing one gives.

Every place that imports an optional package turns the ImportError into :func:`missing`'s,
which names the extra and the command that installs its packages (``pip install toppra
casadi``), so a user never sees a bare ``No module named 'toppra'``. The command names the
packages, not ``planardyn[plan]``: planardyn has no release on a package index, so that would
ask the index for another project of the name. The table is pyproject.toml's
``[project.optional-dependencies]`` (a test keeps them equal).
"""

from __future__ import annotations

#: Extra -> the packages it installs (as pip names them).
EXTRAS = {
    "pandas": ("pandas",),
    "parquet": ("pyarrow",),
    "mp4": ("imageio-ffmpeg",),
    "dask": ("dask[distributed]",),
    "plan": ("toppra", "casadi"),
    "cad": ("ezdxf",),
}

#: Extra -> the top-level modules of its packages (an ImportError names one when it is missing).
MODULES = {
    "pandas": ("pandas",),
    "parquet": ("pyarrow",),
    "mp4": ("imageio_ffmpeg",),
    "dask": ("dask", "distributed"),
    "plan": ("toppra", "casadi"),
    "cad": ("ezdxf",),
}


class MissingExtra(ImportError):
    """An optional package is not installed; the message names the extra that brings it."""


def missing(extra: str, what: str, cause: ImportError | None = None) -> MissingExtra:
    """The error for ``what`` (a feature, e.g. ``"planardyn plan"``) without ``extra``:
    ``"planardyn plan needs the 'plan' extra: pip install toppra casadi (or the wheel with
    it, 'planardyn-<version>.whl[plan]'; No module named 'toppra')"``."""
    packages = " ".join(f"'{p}'" if "[" in p else p for p in EXTRAS[extra])
    found = f"; {cause}" if cause is not None else ""
    return MissingExtra(f"{what} needs the '{extra}' extra: pip install {packages} (or the wheel with it, "
                        f"'planardyn-<version>.whl[{extra}]'{found})")


def is_missing(extra: str, error: ImportError) -> bool:
    """Whether ``error`` is the import of one of ``extra``'s packages failing (not another
    module's, whose error must not be hidden behind an install hint)."""
    return (error.name or "").split(".")[0] in MODULES[extra]
