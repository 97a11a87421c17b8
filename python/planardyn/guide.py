"""The user guide's pages as installed with planardyn (``planardyn docs``).

The wheel carries the guide's Markdown (docs/*.md, pyproject.toml's ``include``) in the
package's ``docs/`` folder; in a clone, ``python/planardyn/docs`` is a link to the
repository's ``docs/``. So every reader, wheel or clone, has the pages an error message or a
``--help`` names: ``planardyn docs model-format``.

This module imports nothing of the package: it only locates data files.
"""

from __future__ import annotations

from pathlib import Path

__all__ = ["UnknownPageError", "directory", "page", "pages", "title"]


class UnknownPageError(KeyError):
    """No page has the name asked for; the message lists the pages there are."""

    def __str__(self) -> str:
        return str(self.args[0])


def directory() -> Path:
    """The folder of the installed pages."""
    return Path(__file__).resolve().parent / "docs"


def pages() -> list[str]:
    """Every page's name (its file's stem: ``model-format``), the home page ``index`` first."""
    names = sorted(p.stem for p in directory().glob("*.md"))
    return sorted(names, key=lambda n: n != "index")


def page(name: str) -> Path:
    """The file of page ``name``: ``model-format``, ``model-format.md`` or ``docs/model-format.md``.

    Raises
    ------
    UnknownPageError
        (a ``KeyError``) No such page; the message lists the pages.
    """
    stem = Path(name).name.removesuffix(".md")
    path = directory() / f"{stem}.md"
    if not pages():
        raise UnknownPageError(f"this planardyn has no copy of the guide (no {directory()}): reinstall it from its "
                               "wheel, or read docs/ in the repository")
    if not path.is_file():
        raise UnknownPageError(f"no page of the guide is named {name!r}; the pages are: {', '.join(pages())}")
    return path


def title(name: str) -> str:
    """The page's first heading (``# The model file``), without the ``#``."""
    with open(page(name), encoding="utf-8") as f:
        for line in f:
            if line.startswith("# "):
                return line[2:].strip()
    return name
