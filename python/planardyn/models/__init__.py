"""The model files shipped with planardyn, found by name in the installed package.

    >>> from planardyn import models
    >>> models.names()[:3]
    ['3-rrr', 'andrews-squeezer', 'five-bar']
    >>> models.path("five-bar")            # a pathlib.Path to five-bar.yaml
    >>> models.resolve("my-linkage.yaml")  # a file as given; a shipped model by name if no such file

The files of the mechanism library (``planardyn.library``) are named ``library/<name>``.
``planardyn.load_example(name)`` loads one into a :class:`~planardyn.Mechanism`.

This module imports nothing of the package: it only locates data files.
"""

from __future__ import annotations

import os
from importlib import resources
from pathlib import Path

__all__ = ["UnknownModelError", "directory", "names", "path", "resolve"]

#: The extension of every shipped model file.
SUFFIX = ".yaml"
#: The sub-folder holding the mechanism library's files.
LIBRARY = "library"


class UnknownModelError(KeyError):
    """No shipped model has the name asked for; the message lists the names there are."""

    def __str__(self) -> str:
        # KeyError's own str() quotes its argument, which is a sentence here.
        return str(self.args[0])


def directory() -> Path:
    """The folder of the shipped model files (the library's are in its ``library/``)."""
    root = resources.files(__name__)
    # A package installed from a wheel or in editable mode lives on the file system; only a
    # zip import gives another Traversable, and planardyn (an extension module) cannot be one.
    if not isinstance(root, Path):
        raise RuntimeError(f"planardyn.models is not on the file system ({root!r}): reinstall planardyn from its wheel")
    return root


def names() -> list[str]:
    """Every shipped model's name, sorted: file stems, ``library/<stem>`` for the library's."""
    root = directory()
    top = sorted(p.stem for p in root.glob(f"*{SUFFIX}"))
    library = sorted(f"{LIBRARY}/{p.stem}" for p in (root / LIBRARY).glob(f"*{SUFFIX}"))
    return top + library


def path(name: str) -> Path:
    """The file of the shipped model ``name`` (``"five-bar"``; ``".yaml"`` may be given).

    Raises
    ------
    UnknownModelError
        (a ``KeyError``) No shipped model has that name; the message lists the names there are.
    """
    stem = name.removesuffix(SUFFIX)
    if stem in names():
        return directory() / f"{stem}{SUFFIX}"
    raise UnknownModelError(f"no shipped model is named {name!r}; the shipped models are: {', '.join(names())}")


def resolve(name_or_file: str | os.PathLike[str]) -> Path:
    """A model argument as the command line takes it: an existing file, or else the shipped
    model of that name (``five-bar``). A name with a suffix (``.json``...) is taken as a file,
    for the loader to report if missing.

    Raises
    ------
    UnknownModelError
        (a ``KeyError``) Neither a file nor a shipped model; the message lists the shipped ones.
    """
    given = Path(name_or_file)
    if given.exists() or given.suffix not in ("", SUFFIX):
        return given
    try:
        return path(os.fspath(given))
    except UnknownModelError as e:
        raise UnknownModelError(f"{given}: no such model file, and {e}") from None
