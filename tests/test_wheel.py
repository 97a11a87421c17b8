"""What the wheel check of `./dev test` relies on (the check itself, building the wheel and
installing it into a fresh venv, is `./dev wheel`; tests/wheel_smoke.py runs there).

Expected values: the extras and licence are those of pyproject.toml; README.md's python
blocks are counted by hand.
"""

from __future__ import annotations

import pytest
from conftest import ROOT
from wheel_smoke import python_blocks, snippets

README = (ROOT / "README.md").read_text()
tomllib = pytest.importorskip("tomllib")  # Python 3.11+


def test_snippets_are_found_in_page_order():
    text = ("a\n```python\nx = 1\n```\n```bash\nls\nplanardyn check five-bar   # a comment\n"
            "planardyn demo --out d\n```\n```python\ny = 2\n```\n")
    assert snippets(text) == [("python", "x = 1\n"), ("planardyn", "planardyn check five-bar"), ("python", "y = 2\n")]
    assert python_blocks(text) == ["x = 1\n", "y = 2\n"]


def test_readme_snippets_need_no_repository_file():
    # Run from an installed wheel in an empty folder: models by name, not by repository path.
    code = snippets(README)
    assert [kind for kind, _ in code] == ["python"] + ["planardyn"] * 10
    for _, text in code:
        assert "examples/" not in text, text
    assert 'pdy.load_example("five-bar")' in code[0][1]
    assert code[1][1] == "planardyn check five-bar"


def test_extras_and_licence():
    meta = tomllib.loads((ROOT / "pyproject.toml").read_text())["project"]
    extras = meta["optional-dependencies"]
    assert extras["parquet"] == ["pyarrow>=14"] and extras["mp4"] == ["imageio-ffmpeg>=0.4"]
    assert extras["dask"] == ["dask[distributed]>=2023.1"]
    assert extras["plan"] == ["toppra>=0.6.10", "casadi>=3.6"]
    assert extras["cad"] == ["ezdxf>=1.1"]
    assert extras["all"] == ["planardyn[pandas,parquet,mp4,dask,plan,cad]"]
    assert set(extras) == {"pandas", "parquet", "mp4", "dask", "plan", "cad", "all"}
    assert meta["license"] == {"text": "MIT"}
    assert (ROOT / "LICENSE").read_text().startswith("MIT License\n")


def test_the_app_is_included_in_the_wheel():
    # maturin's walk of python/planardyn skips the git-ignored built app: an include rule
    # names it, at the path planardyn.app reads (tests/wheel_smoke.py checks the wheel itself).
    from planardyn.app import APP_FILE

    include = tomllib.loads((ROOT / "pyproject.toml").read_text())["tool"]["maturin"]["include"]
    assert {"path": f"python/planardyn/{APP_FILE.rsplit('/', 1)[0]}/*.html", "format": "wheel"} in include
    assert APP_FILE.endswith(".html")
