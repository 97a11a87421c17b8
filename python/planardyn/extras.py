"""The optional extras of ``pip install 'planardyn[EXTRA]'`` and the error a missing one gives.

Every place that imports an optional package turns the ImportError into :func:`missing`'s,
which names the extra to install (``pip install 'planardyn[plan]'``) and the packages it
brings, so a user never sees a bare ``No module named 'toppra'``. The table is pyproject.toml's
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
}

#: Extra -> the top-level modules of its packages (an ImportError names one when it is missing).
MODULES = {
    "pandas": ("pandas",),
    "parquet": ("pyarrow",),
    "mp4": ("imageio_ffmpeg",),
    "dask": ("dask", "distributed"),
    "plan": ("toppra", "casadi"),
}


class MissingExtra(ImportError):
    """An optional package is not installed; the message names the extra that brings it."""


def missing(extra: str, what: str, cause: ImportError | None = None) -> MissingExtra:
    """The error for ``what`` (a feature, e.g. ``"planardyn plan"``) without ``extra``:
    ``"planardyn plan needs the 'plan' extra: pip install 'planardyn[plan]' (or toppra and
    casadi; No module named 'toppra')"``."""
    packages = " and ".join(EXTRAS[extra])
    found = f"; {cause}" if cause is not None else ""
    return MissingExtra(f"{what} needs the '{extra}' extra: pip install 'planardyn[{extra}]' (or {packages}{found})")


def is_missing(extra: str, error: ImportError) -> bool:
    """Whether ``error`` is the import of one of ``extra``'s packages failing (not another
    module's, whose error must not be hidden behind an install hint)."""
    return (error.name or "").split(".")[0] in MODULES[extra]
