"""The command line's manners: warnings as one line, a closed pipe ends quietly, messages name
options, `size` documented, progress for GIF writing, a missing optional package refused
before the computation, the inverse plot's energy panel says what it shows.

Expected values: the dissipation of the five-bar's two motor dampers (c = 1 N m s/rad each,
examples/models/five-bar.yaml) along q_k(t) = q_k0 +- 0.2 sin^2(pi t), t in [0, 1] s, is
c * sum_k int qd_k^2 dt = 2 * c * (0.2 pi)^2 / 2 = 0.394784 J (closed form); the drives' work
is integrated by the trapezoidal rule on 201 rows, an O(h^2) error of about 1e-5 J.
"""

from __future__ import annotations

import io
import re
import subprocess
import sys

import numpy as np
import planardyn as pd
import pytest
from conftest import MODELS, ROOT
from planardyn import cli, models
from planardyn.mechanism import Mechanism
from planardyn.results_io import inverse_result, write_results
from wheel_smoke import BLOCK

FIVE_BAR = MODELS / "five-bar.yaml"


def run(*args: str) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-m", "planardyn", *map(str, args)], capture_output=True, text=True,
                          timeout=120)


def test_a_warning_is_one_clean_line():
    p = run("check", models.path("library/double-parallelogram"))
    assert p.returncode == 0, p.stderr
    lines = p.stderr.splitlines()
    assert len(lines) == 1
    assert lines[0].startswith("planardyn: warning: ") and "redundant constraints" in lines[0]
    assert "PlanardynWarning" not in p.stderr and ".py:" not in p.stderr


def test_main_restores_the_warning_display():
    before = __import__("warnings").showwarning
    assert cli.main(["check", str(FIVE_BAR)]) == 0
    assert __import__("warnings").showwarning is before


@pytest.mark.parametrize("args", [("check", FIVE_BAR), ("demo", "--out", "{tmp}"), ("--help",)])
def test_a_closed_pipe_ends_quietly(args, tmp_path):
    args = [str(a).format(tmp=tmp_path / "demo") for a in args]
    proc = subprocess.Popen([sys.executable, "-m", "planardyn", *args], stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE, text=True)
    proc.stdout.readline()  # the reader takes one line and goes (... | head -1)
    proc.stdout.close()
    err = proc.stderr.read()
    assert proc.wait(timeout=120) == 0
    assert err == ""


def test_rk4_without_step_names_the_option():
    p = run("simulate", FIVE_BAR, "--method", "rk4", "--t-end", "0.1")
    assert p.returncode == 2
    assert "--dt" in p.stderr and "--method rk4" in p.stderr and "Options::" not in p.stderr
    assert run("simulate", FIVE_BAR, "--method", "rk4", "--dt", "1e-3", "--t-end", "0.01").returncode == 0


@pytest.mark.parametrize("page", ["README.md", "docs/cli.md"])
def test_size_is_documented_with_a_command_that_runs(page):
    commands = [line for lang, body in BLOCK.findall((ROOT / page).read_text()) if lang == "bash"
                for line in body.splitlines() if line.startswith("planardyn size ")]
    assert commands  # tests/test_docs.py runs each one
    assert "planardyn size" in cli._parser().format_help()


class Terminal(io.StringIO):
    """A stderr that says it is a terminal, as an interactive shell's is."""

    def isatty(self):
        return True


def test_a_simulation_in_a_terminal_shows_progress(tmp_path, monkeypatch):
    stderr = Terminal()
    monkeypatch.setattr(sys, "stderr", stderr)
    assert cli.main(["simulate", str(FIVE_BAR), "--t-end", "0.5", "-o", str(tmp_path / "run.npz")]) == 0
    updates = [u for u in stderr.getvalue().split("\r") if u]
    # tqdm redraws at most every 0.1 s: at least the start and the end, the end once, full,
    # with the elapsed time and the time left.
    assert len(updates) >= 2 and "|" in updates[0]
    assert [u for u in updates if "100%" in u] == [updates[-1]]
    assert re.search(r"100%\|[#█]+\| 0\.5/0\.5 s \[\d\d:\d\d<00:00\]\n$", updates[-1]), updates[-1]


def test_gif_writing_shows_progress(tmp_path, monkeypatch):
    res = pd.load(FIVE_BAR).simulate(t_end=0.3, output_dt=0.01)
    write_results(res, tmp_path / "run.npz")

    stderr = Terminal()
    monkeypatch.setattr(sys, "stderr", stderr)
    assert cli.main(["animate", str(FIVE_BAR), str(tmp_path / "run.npz"), "-o", str(tmp_path / "run.gif")]) == 0
    updates = [u for u in stderr.getvalue().split("\r") if u]
    # 0.3 s at 20 frames/s in 3 s of playback: 61 frames, the bar full once at the end.
    assert len(updates) >= 2 and [u for u in updates if "100%" in u] == [updates[-1]]
    assert re.search(r"100%\|[#█]+\| 61/61 frames \[\d\d:\d\d<00:00\]\n$", updates[-1]), updates[-1]


@pytest.mark.parametrize(("module", "args", "stopped"), [
    ("pyarrow", ["simulate", str(FIVE_BAR), "-o", "run.parquet"], (Mechanism, "simulate")),
    ("pyarrow", ["inverse", str(FIVE_BAR), "--motion", "motion.csv", "-o", "tau.parquet"], (cli, "load")),
    ("imageio_ffmpeg", ["animate", str(FIVE_BAR), "run.npz", "-o", "run.mp4"], (cli, "load")),
])
def test_missing_optional_package_is_reported_before_the_computation(module, args, stopped, monkeypatch, capsys,
                                                                      tmp_path):
    monkeypatch.chdir(tmp_path)
    monkeypatch.setitem(sys.modules, module, None)  # as if not installed

    def never(*_a, **_k):
        raise AssertionError("the computation started")

    monkeypatch.setattr(*stopped, never)  # what would start the work: the simulation, or reading the inputs
    assert cli.main(args) == 2
    err = capsys.readouterr().err
    package, extra = {"pyarrow": ("pyarrow", "parquet"), "imageio_ffmpeg": ("imageio-ffmpeg", "mp4")}[module]
    assert f"needs the '{extra}' extra: pip install {package} (or the wheel with it" in err and "computation" not in err


def test_inverse_plot_energy_panel_shows_what_the_dampers_take():
    from matplotlib.figure import Figure
    from planardyn.plot import plot_results

    mech = pd.load(FIVE_BAR)
    t = np.linspace(0.0, 1.0, 201)
    swing = 0.2 * np.sin(np.pi * t) ** 2
    rate = 0.2 * np.pi * np.sin(2 * np.pi * t)
    accel = 0.4 * np.pi**2 * np.cos(2 * np.pi * t)
    q0 = mech.q0
    res = inverse_result(mech, t, np.column_stack([q0[0] + swing, q0[1] - swing]),
                         np.column_stack([rate, -rate]), np.column_stack([accel, -accel]))
    fig = Figure()
    plot_results(res, fig=fig)
    energy_ax = [ax for ax in fig.axes if ax.get_ylabel() == "energy dissipated (J)"]
    assert len(energy_ax) == 1
    (line,) = energy_ax[0].get_lines()
    assert line.get_label() == "taken by dampers, friction, loads: W - (T + V - E0)"
    dissipated = line.get_ydata()
    assert dissipated[-1] == pytest.approx(2 * 1.0 * (0.2 * np.pi) ** 2 / 2, abs=1e-4)
    assert np.all(np.diff(dissipated) > -1e-9)  # dampers only take energy
    titles = [ax.get_title() for ax in fig.axes]
    assert "energy: the drives' work W, and what the loads dissipate" in titles
