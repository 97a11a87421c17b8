"""The wheel stands alone: run by `./dev test` with the python of a fresh venv holding only the
wheel and its dependencies, from a folder outside the repository.

    python wheel_smoke.py README.md

Checks that planardyn is imported from the installed wheel, not a source tree; that the wheel
holds the licence and every shipped model file, each of which loads; that `planardyn --version`
prints the installed version; and that every ```python block of README.md runs, in order, in
one namespace (as tests/test_docs.py runs them in the repository). Needs nothing but the wheel.
"""

from __future__ import annotations

import importlib.metadata
import re
import subprocess
import sys
import warnings
from pathlib import Path

BLOCK = re.compile(r"^```(\w+)\n(.*?)^```", re.S | re.M)


def python_blocks(markdown: str) -> list[str]:
    """The ```python blocks of a Markdown text, in order."""
    return [body for lang, body in BLOCK.findall(markdown) if lang == "python"]


def check_installed() -> None:
    import planardyn as pd

    where = Path(pd.__file__).resolve()
    assert "site-packages" in where.parts, f"planardyn is imported from {where}, not from an installed wheel"
    files = [str(f) for f in importlib.metadata.distribution("planardyn").files or []]
    assert any(f.endswith("licenses/LICENSE") for f in files), "the wheel holds no LICENSE"
    shipped = sorted(f.removeprefix("planardyn/models/").removesuffix(".yaml") for f in files
                     if f.startswith("planardyn/models/") and f.endswith(".yaml"))
    assert shipped and shipped == sorted(pd.models.names()), (shipped, pd.models.names())
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", pd.PlanardynWarning)  # e.g. the library's redundant double parallelogram
        for name in shipped:
            pd.load_example(name)
    print(f"wheel: {where.parent}: LICENSE, {len(shipped)} model files, each loads")


def check_version() -> None:
    command = Path(sys.executable).parent / "planardyn"
    out = subprocess.run([str(command), "--version"], capture_output=True, text=True, check=True).stdout
    assert out.strip() == f"planardyn {importlib.metadata.version('planardyn')}", out
    print(f"wheel: {out.strip()}")


def run_readme(readme: Path) -> None:
    import matplotlib

    matplotlib.use("Agg")
    blocks = python_blocks(readme.read_text())
    assert blocks, f"{readme} has no python block"
    namespace: dict[str, object] = {"__name__": "__main__"}
    for k, body in enumerate(blocks, 1):
        exec(compile(body, f"{readme.name}, python block {k}", "exec"), namespace)
    print(f"wheel: the {len(blocks)} python block(s) of {readme.name} ran")


if __name__ == "__main__":
    check_installed()
    check_version()
    run_readme(Path(sys.argv[1]))
