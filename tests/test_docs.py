"""The user guide works as written: every ```python block of README.md and docs/*.md runs
(the blocks of a page in order, in one namespace), and every `planardyn ...` line of their
```bash blocks runs with exit status 0, interleaved in page order, in an empty folder where
`examples/` is the repository's. `planardyn demo` is left to test_demo (it takes seconds).
The site builds with `mkdocs build --strict` when mkdocs is installed.
"""

from __future__ import annotations

import subprocess
import sys
import textwrap

import pytest
from conftest import ROOT
from wheel_smoke import snippets

DOCS = ROOT / "docs"
PAGES = [ROOT / "README.md", *sorted(DOCS.glob("*.md"))]

PRELUDE = textwrap.dedent(
    """
    import shlex, subprocess, sys
    import matplotlib
    matplotlib.use("Agg")

    def _planardyn(line):
        p = subprocess.run([sys.executable, "-m", "planardyn", *shlex.split(line)[1:]],
                           capture_output=True, text=True, timeout=300)
        assert p.returncode == 0, f"{line!r} exited {p.returncode}: {p.stderr}"
        print(p.stdout, end="")
    """
)


def page_script(page) -> tuple[str, int]:
    """The page as one Python script, and the number of blocks and commands in it."""
    code = snippets(page.read_text())
    parts = [PRELUDE] + [text if kind == "python" else f"_planardyn({text!r})" for kind, text in code]
    return "\n".join(parts), len(code)


@pytest.mark.parametrize("page", PAGES, ids=lambda p: p.name)
def test_page_code_runs(page, tmp_path):
    script, n = page_script(page)
    if n == 0:
        pytest.skip(f"{page.name} has no Python block or planardyn command")
    (tmp_path / "examples").symlink_to(ROOT / "examples")
    (tmp_path / "page.py").write_text(script)
    p = subprocess.run([sys.executable, "page.py"], cwd=tmp_path, capture_output=True, text=True, timeout=300,
                       env={**__import__("os").environ, "MPLBACKEND": "Agg"})
    assert p.returncode == 0, f"{page.name}:\n{p.stdout[-3000:]}\n{p.stderr[-3000:]}"


def test_pages_have_the_promised_code():
    # What a new user follows: describe a five-bar, simulate it, view it, plot torques, invert.
    examples, _ = page_script(DOCS / "examples.md")
    for needle in ("pd.load(\"my-five-bar.yaml\")", "mech.simulate(", "animate(mech, res, \"fall.html\")",
                   "plot_efforts(inv", "inverse_result(mech, t, q)"):
        assert needle in examples, needle
    cli, n = page_script(DOCS / "cli.md")
    for cmd in ("check", "simulate", "plot", "animate", "inverse"):
        assert f"_planardyn('planardyn {cmd} " in cli, cmd
    assert n >= 10


def test_mkdocs_build_strict(tmp_path):
    pytest.importorskip("mkdocs")
    p = subprocess.run(
        [sys.executable, "-m", "mkdocs", "build", "--strict", "--site-dir", str(tmp_path / "site")],
        cwd=ROOT, capture_output=True, text=True, timeout=300,
    )
    assert p.returncode == 0, p.stderr[-3000:]
    for page in ("index.html", "cli/index.html", "api/index.html", "examples/index.html", "model-format/index.html"):
        assert (tmp_path / "site" / page).is_file(), page
    assert "planardyn inverse" in (tmp_path / "site" / "cli" / "index.html").read_text()
