"""planardyn.guard: a long run's guards. Ctrl-C keeps the trajectory as a cancelled run, a run
whose output rows cannot fit is refused up front (the command line and ``Mechanism.simulate``),
and a run that outputs every step is stopped when the process outgrows its memory.

Each test states the failure it reproduces (what happened before) and checks the fix.
"""

from __future__ import annotations

import os
import signal

import numpy as np
import planardyn as pd
import pytest
from conftest import MODELS, cli_run
from planardyn import cli, guard
from planardyn.results_io import read_results

FIVE_BAR = MODELS / "five-bar.yaml"


def test_ctrl_c_keeps_the_run_as_a_cancelled_file(tmp_path, monkeypatch):
    """Before: Ctrl-C during simulate lost the whole trajectory (exit 130, no file)."""
    out = tmp_path / "run.csv"
    drawn = cli.ProgressBar.__call__

    def press_ctrl_c(self, t):  # the user presses Ctrl-C once the run is past t = 50 s
        drawn(self, t)
        if t > 50:
            os.kill(os.getpid(), signal.SIGINT)

    monkeypatch.setattr(cli.ProgressBar, "__call__", press_ctrl_c)
    code, err = cli_run("simulate", FIVE_BAR, "--t-end", "5000", "--output-dt", "0.5", "--progress", "-o", out)
    assert code == 1 and "interrupted (Ctrl-C)" in err, err
    back = read_results(out)
    assert back.status == "cancelled" and not back.success and "Ctrl-C" in back.message
    # Stopped at the first progress call (t = 1% of 5000 s, just past 50 s), far before
    # 5000 s, with every output row up to there (one every 0.5 s from 0), then the last
    # accepted state (the step that passed 50 s).
    assert back.t[-2] == 50.0 and 50.0 < back.t[-1] < 50.5
    assert np.allclose(back.t[:-1], 0.5 * np.arange(len(back.t) - 1), rtol=0, atol=1e-9)
    assert signal.getsignal(signal.SIGINT) is signal.default_int_handler


def test_run_that_cannot_fit_is_refused_up_front(monkeypatch):
    """Before: 1e8 output rows were allowed, ~33 GB on a 24 GB machine."""
    monkeypatch.setattr(cli, "available_memory", lambda: 10 * 2**20)
    # 10001 rows of the five-bar (m = 2, 4 bodies): 8 * (1 + 8 + 5 + 24) + 1 = 305 B a row,
    # times PEAK_FACTOR 4: 12.2 MB > 10 MiB.
    assert guard.row_bytes(2, 4) == 305
    code, err = cli_run("simulate", FIVE_BAR, "--t-end", "10", "--output-dt", "0.001")
    assert code == 2 and "--output-dt" in err and "--t-end" in err and "five-bar.yaml" in err, err


def test_memory_guard_stops_an_every_step_run():
    """A run that outputs every step has no row count up front: the guard stops it when the
    process outgrows its share of memory, keeping the trajectory."""
    mech = pd.load(FIVE_BAR)
    g = guard.RunGuard()
    g.limit = 0  # as if memory were already exhausted
    res = mech.simulate(5.0, progress=g)
    assert res.status == "cancelled" and g.reason is not None and "memory" in g.reason
    assert 0 < res.t[-1] <= 0.06  # stopped at the first progress call, after 1% of the run


def test_api_run_that_cannot_fit_is_refused_up_front(monkeypatch):
    """The same rule in Mechanism.simulate: 10001 rows of 305 B, 4 times over, exceed 10 MiB;
    10000 t_eval rows (12.2 MB) too; 1001 rows (1.2 MB) run."""
    mech = pd.load(FIVE_BAR)
    monkeypatch.setattr(pd.mechanism, "available_memory", lambda: 10 * 2**20)
    with pytest.raises(ValueError, match="output rows need about 0.0114 GiB.*larger output_dt"):
        mech.simulate(t_end=10.0, output_dt=0.001)
    with pytest.raises(ValueError, match="fewer t_eval"):
        mech.simulate(t_end=1.0, t_eval=np.linspace(0.0, 1.0, 10_000))
    assert mech.simulate(t_end=0.01, output_dt=1e-5).success


def test_api_small_run_does_not_read_the_memory(monkeypatch):
    """A run whose rows always fit (11 rows of 305 B, 4 times over: 13 kB, under
    guard.ALWAYS_FITS = 1 MiB) runs without reading /proc/meminfo; 1001 rows (1.2 MB) do read it."""
    mech = pd.load(FIVE_BAR)
    reads = []
    monkeypatch.setattr(pd.mechanism, "available_memory", lambda: reads.append(1) or 10 * 2**20)
    assert mech.simulate(t_end=0.01, output_dt=1e-3).success
    assert reads == []
    assert mech.simulate(t_end=0.01, output_dt=1e-5).success
    assert reads == [1]
