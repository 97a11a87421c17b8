"""What the wheel check of `./dev test` relies on (the check itself, building the wheel and
installing it into a fresh venv, is `./dev wheel`; tests/wheel_smoke.py runs there).

Expected values: the extras and licence are those of pyproject.toml; README.md's python
blocks are counted by hand.
"""

from __future__ import annotations

import pytest
from conftest import ROOT
from wheel_smoke import python_blocks

README = (ROOT / "README.md").read_text()
tomllib = pytest.importorskip("tomllib")  # Python 3.11+


def test_python_blocks_are_found_in_order():
    text = "a\n```python\nx = 1\n```\n```bash\nls\n```\n```python\ny = 2\n```\n"
    assert python_blocks(text) == ["x = 1\n", "y = 2\n"]


def test_readme_python_needs_no_repository_file():
    # Run from an installed wheel in an empty folder: models by name, not by repository path.
    blocks = python_blocks(README)
    assert len(blocks) == 1
    assert "examples/" not in blocks[0] and 'pd.load_example("five-bar")' in blocks[0]


def test_extras_and_licence():
    meta = tomllib.loads((ROOT / "pyproject.toml").read_text())["project"]
    extras = meta["optional-dependencies"]
    assert extras["parquet"] == ["pyarrow>=14"] and extras["mp4"] == ["imageio-ffmpeg>=0.4"]
    assert extras["dask"] == ["dask[distributed]>=2023.1"]
    assert extras["all"] == ["planardyn[pandas,parquet,mp4,dask]"]
    assert set(extras) == {"pandas", "parquet", "mp4", "dask", "all"}
    assert meta["license"] == {"text": "MIT"}
    assert (ROOT / "LICENSE").read_text().startswith("MIT License\n")
