"""Every missing optional extra says how to install it (issue 26, first hour 3): `planardyn plan`
without toppra printed `planardyn: No module named 'toppra'`. The missing package is simulated by
a None in sys.modules (Python's import then raises ImportError naming it), with planardyn's
modules that imported it dropped so that they import again."""

from __future__ import annotations

import contextlib
import io
import re
import sys

import numpy as np
import planardyn as pd
import pytest
from conftest import ROOT
from planardyn import extras

tomllib = pytest.importorskip("tomllib")  # Python 3.11+


def without(monkeypatch, *modules: str, dropping: str = "") -> None:
    """``modules`` made unimportable; planardyn's modules under ``dropping`` forgotten."""
    for name in list(sys.modules):
        if dropping and (name == dropping or name.startswith(dropping + ".")):
            monkeypatch.delitem(sys.modules, name)
    for name in modules:  # its submodules too: `from toppra.constants import` would find them
        for loaded in [m for m in sys.modules if m.startswith(name + ".")]:
            monkeypatch.setitem(sys.modules, loaded, None)
        monkeypatch.setitem(sys.modules, name, None)


def run(*argv: str) -> tuple[int, str, str]:
    from planardyn.cli import main

    out, err = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
        code = main(list(argv))
    return code, out.getvalue(), err.getvalue()


def test_the_extras_are_pyprojects():
    declared = tomllib.loads((ROOT / "pyproject.toml").read_text())["project"]["optional-dependencies"]
    packages = {k: tuple(re.split(r"[<>=]", v)[0] for v in vs) for k, vs in declared.items() if k != "all"}
    assert packages == extras.EXTRAS
    assert set(extras.MODULES) == set(extras.EXTRAS)
    assert declared["all"] == [f"planardyn[{','.join(extras.EXTRAS)}]"]
    # The shell needs the brackets quoted; and no 'planardyn[...]' from an index, which has no planardyn.
    assert str(extras.missing("dask", "a Dask batch")) == (
        "a Dask batch needs the 'dask' extra: pip install 'dask[distributed]' (or the wheel with it, "
        "'planardyn-<version>.whl[dask]')")


LINE = ["plan", "library/five-bar-5r", "--line", "-0.08", "0.28", "0.08", "0.36", "--effort", "3", "3"]


@pytest.mark.parametrize(("missing", "commands"), [
    ("toppra", [LINE, ["plan", "--help"], ["plan"]]),
    ("casadi", [[*LINE, "--collocate", "time"]]),  # only collocation needs casadi
])
def test_plan_without_its_extra_says_how_to_install_it(monkeypatch, missing, commands):
    without(monkeypatch, missing, dropping="planardyn.plan")
    for argv in commands:
        code, out, err = run(*argv)
        assert code == 2 and out == ""
        assert err.startswith("planardyn: planardyn plan needs the 'plan' extra: pip install toppra casadi "
                              "(or the wheel with it, 'planardyn-<version>.whl[plan]'; "), err
        assert missing in err and err.count("\n") == 1
    # The listing still has the command.
    from planardyn.cli import _parser

    assert re.search(r"\n    plan +time-optimal timing", _parser().format_help())


def test_another_import_error_is_not_taken_for_the_extra(monkeypatch):
    # A module of planardyn itself failing is a bug to show, not an install hint.
    without(monkeypatch, "planardyn.plan.topp", dropping="planardyn.plan")
    code, _, err = run("plan", "five-bar", "--line", "0", "0.4", "0.05", "0.45", "--effort", "3", "3")
    assert code == 2 and "extra" not in err and "planardyn.plan.topp" in err


def test_parquet_and_mp4_without_their_extras(monkeypatch, tmp_path):
    res = pd.load_example("five-bar").simulate(t_end=0.02, output_dt=0.01)
    npz = res.save(tmp_path / "run.npz")
    without(monkeypatch, "pyarrow", "pyarrow.parquet")
    with pytest.raises(ImportError, match=r"a Parquet results file needs the 'parquet' extra: pip install pyarrow \(or the wheel"):
        res.save(tmp_path / "run.parquet")
    code, _, err = run("simulate", "five-bar", "--t-end", "0.01", "-o", str(tmp_path / "run.parquet"))
    assert code == 2 and "needs the 'parquet' extra: pip install pyarrow (or the wheel with it, 'planardyn-<version>.whl[parquet]'" in err
    without(monkeypatch, "imageio_ffmpeg")
    code, _, err = run("animate", str(npz), "-o", str(tmp_path / "run.mp4"))
    assert code == 2 and "needs the 'mp4' extra: pip install imageio-ffmpeg (or" in err
    from planardyn.animate import write_mp4

    with pytest.raises(ImportError, match=r"an MP4 animation needs the 'mp4' extra"):
        write_mp4(iter([np.zeros((16, 16, 3), np.uint8)]), tmp_path / "x.mp4", 10.0, (16, 16))


def test_to_dataframe_without_pandas(monkeypatch):
    res = pd.load_example("five-bar").simulate(t_end=0.02, output_dt=0.01)
    without(monkeypatch, "pandas")
    with pytest.raises(ImportError, match=r"to_dataframe\(\) needs the 'pandas' extra: pip install pandas \(or the wheel with it"):
        res.to_dataframe()
