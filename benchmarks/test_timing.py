"""The interleaved timing of timing.py: the order of the calls and the statistics, on stand-in calls
(no speed is asserted). Run with ``.venv/bin/python -m pytest -q benchmarks``."""

from __future__ import annotations

import sys
import time
from pathlib import Path

import pytest

sys.path.insert(0, str(Path(__file__).resolve().parent))

import timing  # noqa: E402


def test_rounds_alternate_the_order():
    # Calls longer than MIN_SAMPLE are not batched: one warm-up call each, then A B C, C B A, A B C.
    order = []

    def call(name):
        def f():
            order.append(name)
            time.sleep(1.1 * timing.MIN_SAMPLE)
        return f

    out = timing.measure({k: call(k) for k in "ABC"}, rounds=3, say=lambda _: None)
    assert "".join(order) == "ABC" + "ABC" + "CBA" + "ABC"
    assert all(out["entries"][k]["batch"] == 1 and len(out["entries"][k]["wall"]) == 3 for k in "ABC")
    assert len(out["load_1min_per_round"]) == 3


def test_batches_and_returned_values():
    # A call far shorter than MIN_SAMPLE is repeated; what it returns (a clocked share) is averaged per call.
    calls = []

    def f():
        calls.append(1)
        return 0.25

    out = timing.measure({"f": f}, rounds=2, say=lambda _: None)
    e = out["entries"]["f"]
    assert e["batch"] > 1 and len(calls) == 1 + 2 * e["batch"]
    assert e["value"] == [0.25, 0.25]


def test_quartiles_and_per_round_ratios():
    q = timing.quartiles([5.0, 1.0, 3.0, 2.0, 4.0])
    assert (q["median"], q["q1"], q["q3"], q["min"], q["max"]) == (3.0, 2.0, 4.0, 1.0, 5.0)
    # Per-round ratios: a slow round slows both, and the ratio stays 2.
    r = timing.paired([2.0, 20.0, 4.0], [1.0, 10.0, 2.0])
    assert r["median"] == r["q1"] == r["q3"] == pytest.approx(2.0, rel=1e-15)
