"""The shipped model files as package data: planardyn.models, planardyn.load_example, and the
repository's examples/models link to them.

Expected values: the file names are those in the package's models/ folder (listed here by
hand); the coordinate names and the mobility of five-bar are those of its file.
"""

from __future__ import annotations

import ast
import os
import subprocess
import sys
from pathlib import Path

import planardyn as pd
import pytest
from planardyn import demo, models

ROOT = Path(__file__).resolve().parents[1]

SHIPPED = ["3-rrr", "andrews-squeezer", "five-bar", "five-bar-compliant", "five-bar-free-fall", "five-bar-robot",
           "four-bar-gravity", "gear-train", "geared-five-bar", "hydraulic-boom", "scotch-yoke", "slider-crank"]
LIBRARY = ["library/3-prr", "library/3-rpr", "library/3-rrr", "library/biglide", "library/double-parallelogram",
           "library/five-bar-5r", "library/four-bar", "library/slider-crank", "library/slider-crank-slider-driven",
           "library/stephenson-six-bar", "library/watt-six-bar"]


def test_names_lists_every_shipped_file_sorted():
    assert models.names() == SHIPPED + LIBRARY


@pytest.mark.parametrize("name", SHIPPED + LIBRARY)
def test_path_is_the_file_in_the_package(name):
    path = models.path(name)
    assert path.is_file()
    assert path == Path(pd.__file__).parent / "models" / f"{name}.yaml"


def test_path_accepts_the_file_name():
    assert models.path("five-bar.yaml") == models.path("five-bar")


@pytest.mark.parametrize("name", ["five-barr", "", "library", "models/five-bar", "../README"])
def test_unknown_name_lists_the_known_ones(name):
    with pytest.raises(KeyError) as info:
        models.path(name)
    message = str(info.value)
    assert message.startswith(f"no shipped model is named {name!r}")
    for known in SHIPPED + LIBRARY:
        assert known in message


def test_load_example_loads_the_shipped_file():
    mech = pd.load_example("five-bar")
    assert mech.coordinate_names == pd.load(models.path("five-bar")).coordinate_names
    assert mech.coordinate_names == ["theta1", "theta2"]


def test_load_example_unknown_name():
    with pytest.raises(models.UnknownModelError, match="five-bar-free-fall"):
        pd.load_example("six-bar")


def test_examples_models_is_the_package_folder():
    """The repository's examples/models is a relative link to the package data, stored by git."""
    link = ROOT / "examples" / "models"
    assert link.is_symlink()
    assert os.readlink(link) == "../python/planardyn/models"
    assert link.resolve() == models.directory().resolve()
    listed = subprocess.run(["git", "ls-files", "-s", "examples/models"], cwd=ROOT, capture_output=True, text=True)
    if listed.returncode != 0 or not listed.stdout:
        pytest.skip("not a git checkout")
    assert listed.stdout.startswith("120000 "), listed.stdout  # git's mode of a symbolic link


def test_models_imports_nothing_of_the_package():
    """planardyn.models is a bottom-layer utility: no import of the package, at any level."""
    tree = ast.parse(Path(models.__file__).read_text())
    imported = [node.module or "" for node in ast.walk(tree) if isinstance(node, ast.ImportFrom) and
                (node.level > 0 or (node.module or "").startswith("planardyn"))]
    imported += [alias.name for node in ast.walk(tree) if isinstance(node, ast.Import)
                 for alias in node.names if alias.name.startswith("planardyn")]
    assert imported == []


def test_demo_runs_shipped_models():
    """`planardyn demo` finds its models in the package, not relative to a source tree."""
    assert {demo.ROBOT_MODEL, demo.PASSIVE_MODEL} <= set(models.names())


def test_resolve_takes_a_file_first_then_a_shipped_name(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    assert models.resolve("five-bar") == models.path("five-bar")
    assert models.resolve("library/four-bar") == models.path("library/four-bar")
    (tmp_path / "five-bar").write_text("name: mine\n")  # a file of that name wins
    assert models.resolve("five-bar") == Path("five-bar")
    assert models.resolve("missing.json") == Path("missing.json")  # for the loader to report
    with pytest.raises(models.UnknownModelError, match=r"^fivebar: no such model file, and no shipped model"):
        models.resolve("fivebar")


def test_cli_takes_shipped_names(tmp_path):
    p = subprocess.run([sys.executable, "-m", "planardyn", "check", "five-bar"], capture_output=True, text=True,
                       cwd=tmp_path)
    assert p.returncode == 0 and p.stdout.startswith("model: five-bar 5R robot"), p.stderr
    p = subprocess.run([sys.executable, "-m", "planardyn", "check", "fivebar"], capture_output=True, text=True,
                       cwd=tmp_path)
    assert p.returncode == 2 and "no shipped model is named 'fivebar'" in p.stderr and "five-bar-free-fall" in p.stderr
