"""The wheel stands alone: run by `./dev test` with the python of a fresh venv holding only the
wheel and its dependencies, from a folder outside the repository.

    python wheel_smoke.py README.md

Checks that planardyn is imported from the installed wheel, not a source tree; that the wheel
holds the licence and every shipped model file, each of which loads, and the guide's pages
(`planardyn docs`); that `planardyn --version` prints the installed version; and that every snippet of README.md runs in page order, the
```python blocks in one namespace, the `planardyn` lines of its ```bash blocks as commands (as
tests/test_docs.py runs every page in the repository). Needs nothing but the wheel.
"""

from __future__ import annotations

import importlib.metadata
import re
import shlex
import subprocess
import sys
import warnings
from pathlib import Path

BLOCK = re.compile(r"^```(\w+)\n(.*?)^```", re.S | re.M)
#: Commands the snippets leave out: the demo has its own run and test (it takes seconds).
SKIPPED_COMMANDS = ("planardyn demo",)


def python_blocks(markdown: str) -> list[str]:
    """The ```python blocks of a Markdown text, in order."""
    return [code for kind, code in snippets(markdown) if kind == "python"]


def snippets(markdown: str) -> list[tuple[str, str]]:
    """The code a page asks its reader to run, in page order: ("python", block) for each
    ```python block, ("planardyn", line) for each `planardyn ...` line of a ```bash block
    (its comment cut), the commands in SKIPPED_COMMANDS left out."""
    out = []
    for lang, body in BLOCK.findall(markdown):
        if lang == "python":
            out.append(("python", body))
        elif lang == "bash":
            for line in body.splitlines():
                cmd = line.split("#")[0].strip()
                if cmd.startswith("planardyn ") and not cmd.startswith(SKIPPED_COMMANDS):
                    out.append(("planardyn", cmd))
    return out


def check_installed() -> None:
    import planardyn as pdy

    where = Path(pdy.__file__).resolve()
    assert "site-packages" in where.parts, f"planardyn is imported from {where}, not from an installed wheel"
    files = [str(f) for f in importlib.metadata.distribution("planardyn").files or []]
    assert any(f.endswith("licenses/LICENSE") for f in files), "the wheel holds no LICENSE"
    shipped = sorted(f.removeprefix("planardyn/models/").removesuffix(".yaml") for f in files
                     if f.startswith("planardyn/models/") and f.endswith(".yaml"))
    assert shipped and shipped == sorted(pdy.models.names()), (shipped, pdy.models.names())
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", pdy.PlanardynWarning)  # e.g. the library's redundant double parallelogram
        for name in shipped:
            pdy.load_example(name)
    print(f"wheel: {where.parent}: LICENSE, {len(shipped)} model files, each loads")


def check_guide(readme: Path) -> None:
    """The guide's pages are in the wheel (planardyn/docs/*.md), the repository's, and
    `planardyn docs PAGE` prints them: the address model errors cite."""
    files = [str(f) for f in importlib.metadata.distribution("planardyn").files or []]
    shipped = sorted(f.removeprefix("planardyn/docs/") for f in files if f.startswith("planardyn/docs/"))
    pages = sorted(p.name for p in (readme.parent / "docs").glob("*.md"))
    assert shipped == pages, (shipped, pages)
    command = Path(sys.executable).parent / "planardyn"
    out = subprocess.run([str(command), "docs", "model-format"], capture_output=True, text=True, check=True).stdout
    assert out == (readme.parent / "docs" / "model-format.md").read_text(), out[:200]
    print(f"wheel: the guide's {len(shipped)} pages, planardyn docs prints them")


def check_app() -> None:
    """The browser app is in the wheel (planardyn/app_build/app.html) and `planardyn app` writes
    it with the model: one file holding the engine (its wasm, inlined as base64)."""
    from planardyn.app import APP_FILE

    files = [str(f) for f in importlib.metadata.distribution("planardyn").files or []]
    assert f"planardyn/{APP_FILE}" in files, f"the wheel holds no planardyn/{APP_FILE}"
    command = Path(sys.executable).parent / "planardyn"
    subprocess.run([str(command), "app", "five-bar", "-o", "app.html"], capture_output=True, text=True, check=True)
    page = Path("app.html").read_text()
    # "AGFzbQ" is the base64 of the wasm magic number "\\0asm": the engine is inlined.
    # The page's data is compact JSON (app.page_data): no space after the colon.
    assert '"source":"five-bar.yaml"' in page and "AGFzbQ" in page, page[:200]
    print(f"wheel: planardyn app wrote app.html ({len(page) / 1e6:.1f} MB, the engine inside)")


def check_version() -> None:
    command = Path(sys.executable).parent / "planardyn"
    out = subprocess.run([str(command), "--version"], capture_output=True, text=True, check=True).stdout
    assert out.strip() == f"planardyn {importlib.metadata.version('planardyn')}", out
    print(f"wheel: {out.strip()}")


def run_readme(readme: Path) -> None:
    """Every snippet of the README, in order, in the current folder: the python blocks in one
    namespace, the commands with this venv's `planardyn`."""
    import matplotlib

    matplotlib.use("Agg")
    code = snippets(readme.read_text())
    assert code, f"{readme} has no python block or planardyn command"
    namespace: dict[str, object] = {"__name__": "__main__"}
    command = Path(sys.executable).parent / "planardyn"
    for k, (kind, text) in enumerate(code, 1):
        if kind == "python":
            exec(compile(text, f"{readme.name}, snippet {k}", "exec"), namespace)
        else:
            p = subprocess.run([str(command), *shlex.split(text)[1:]], capture_output=True, text=True)
            assert p.returncode == 0, f"{text!r} exited {p.returncode}: {p.stderr}"
    print(f"wheel: the {len(code)} snippets of {readme.name} ran (python blocks and planardyn commands)")


if __name__ == "__main__":
    check_installed()
    check_version()
    check_guide(Path(sys.argv[1]))
    check_app()
    run_readme(Path(sys.argv[1]))
